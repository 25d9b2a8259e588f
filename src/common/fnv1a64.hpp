#pragma once
// Internal: FNV-1a (64 bit), the checksum of map files' content (store/map_checksum.cpp) and of
// preparation cache entries (mapping/preparation_cache.cpp): catches damage, not tampering.

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace keyplace {

class Fnv1a64 {
 public:
  void Bytes(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < size; ++k) {
      state_ ^= bytes[k];
      state_ *= kPrime;
    }
  }
  // Fixed width and byte order, so that the checksum does not depend on the machine.
  void Uint64(std::uint64_t value) {
    std::array<unsigned char, 8> little_endian{};
    for (std::size_t k = 0; k < little_endian.size(); ++k) {
      little_endian[k] = static_cast<unsigned char>(value >> (8 * k));
    }
    Bytes(little_endian.data(), little_endian.size());
  }
  std::uint64_t value() const { return state_; }

 private:
  static constexpr std::uint64_t kOffsetBasis = 14695981039346656037ULL;
  static constexpr std::uint64_t kPrime = 1099511628211ULL;
  std::uint64_t state_ = kOffsetBasis;
};

/// The FNV-1a 64 of `size` bytes.
inline std::uint64_t Fnv1a64Of(const void* data, std::size_t size) {
  Fnv1a64 hash;
  hash.Bytes(data, size);
  return hash.value();
}

/// 16 lower-case hex digits.
inline std::string Hex64(std::uint64_t value) {
  std::array<char, 17> text{};
  std::snprintf(text.data(), text.size(), "%016llx", static_cast<unsigned long long>(value));
  return text.data();
}

}  // namespace keyplace
