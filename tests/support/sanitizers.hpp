#pragma once
// Whether this test program runs under a sanitizer (make test-sanitize, docs/RELIABILITY.md).

namespace keyplace::testing {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif
#else
inline constexpr bool kAddressSanitizer = false;
#endif

/// Why a test that limits the address space (RLIMIT_AS) cannot run under AddressSanitizer: its
/// shadow memory alone takes terabytes of address space, so the limit says nothing about what
/// the code under test needs. Such tests run in the ordinary build (make test).
inline constexpr const char* kAddressSpaceLimitUnderAsan =
    "limits the address space, which AddressSanitizer's shadow memory (terabytes) fills; the "
    "ordinary build runs it";

}  // namespace keyplace::testing
