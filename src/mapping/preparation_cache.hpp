#pragma once
// The preparation cache of PrepareLogInputs (LogInputOptions::cache_dir): the ICP poses and the
// FLIRT keypoints of a log kept in files, so that several runs over one log compute them once.
//
// An entry is one file, named by its kind and a hash of its key. The key spells out everything
// the result depends on (CacheKey in scan_sources.cpp): the code, the log's content, the kept scan
// range, the reading options and the settings (features, odometry, bag input). A file whose key
// differs is another entry (a hash collision) and is replaced; a damaged file (not a regular
// file, bad header, short, checksum mismatch, counts that do not fit the log) is reported and
// recomputed.
//
// File layout, native byte order (an entry written with another byte order is reported and
// replaced):
//   "KPPREP1\n" | u32 0x01020304 | u64 key bytes | key | u64 payload bytes | payload
//   | u64 FNV-1a 64 of every byte before it.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/features/keypoint.hpp"

namespace keyplace::mapping_internal {

/// dir/<kind>-<16 hex digits of the key's hash>.bin
std::string CacheEntryPath(const std::string& dir, const std::string& kind, const std::string& key);

/// What reading an entry found: its payload, or why there is none (`problem` is empty for a
/// missing file or another key's entry, which are plain misses).
struct CacheRead {
  std::optional<std::string> payload;
  std::string problem;
};

/// The largest entry read (it is read whole): 80 times the largest keypoint entry of the shared
/// logs (26 MB). A larger file is a damaged or foreign one, named and computed again, not a
/// reason to run out of memory.
constexpr std::uint64_t kMaxCacheEntryBytes = std::uint64_t{2} << 30;

CacheRead ReadCacheEntry(const std::string& path, const std::string& key,
                         std::uint64_t max_bytes = kMaxCacheEntryBytes);

/// Writes the entry atomically (temporary file, then rename). Throws std::runtime_error naming
/// the path when it cannot be written.
void WriteCacheEntry(const std::string& path, const std::string& key, const std::string& payload);

std::string EncodePoses(const std::vector<Pose2>& poses);
/// Throws std::runtime_error saying what does not fit when the payload is not `scans` poses.
std::vector<Pose2> DecodePoses(const std::string& payload, std::size_t scans);

std::string EncodeKeypoints(const std::vector<std::vector<Keypoint>>& keypoints);
/// Throws std::runtime_error saying what does not fit when the payload is not keypoints of
/// `scans` scans.
std::vector<std::vector<Keypoint>> DecodeKeypoints(const std::string& payload, std::size_t scans);

}  // namespace keyplace::mapping_internal
