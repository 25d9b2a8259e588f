#pragma once
// Internal: how large a compressed chunk of a bag (ROS 1 bz2/lz4, MCAP lz4/zstd) may claim to be
// once decompressed, checked before its buffer is allocated: a hostile size field must not make
// the reader allocate gigabytes from a few bytes.

#include <cstdint>

namespace keyplace {

// Laser data do not compress 1000-fold; up to 16 MiB is allowed whatever the ratio (rosbag and
// rosbag2 write chunks of 768 KiB).
inline constexpr std::uint64_t kMaxChunkCompressionRatio = 1024;
inline constexpr std::uint64_t kMinChunkLimitBytes = 16ULL << 20U;
inline constexpr std::uint64_t kMaxChunkBytes = 256ULL << 20U;

inline bool PlausibleChunkBytes(std::uint64_t uncompressed_bytes, std::uint64_t compressed_bytes) {
  const std::uint64_t by_ratio = kMaxChunkCompressionRatio * compressed_bytes;
  const std::uint64_t limit = by_ratio > kMinChunkLimitBytes ? by_ratio : kMinChunkLimitBytes;
  return uncompressed_bytes <= limit && uncompressed_bytes <= kMaxChunkBytes;
}

}  // namespace keyplace
