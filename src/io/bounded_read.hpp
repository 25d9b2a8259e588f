#pragma once
// Internal: reading a file whole with a limit, for every input keyplace holds in memory at once
// (configurations, map_server YAML and images, rosbag2 metadata.yaml): /dev/zero, a FIFO or a
// huge file ends in an error naming the file and the limit, not in a bare std::bad_alloc.

#include <cstddef>
#include <string>

namespace keyplace {

/// Limits of the files read whole (docs/RELIABILITY.md, "Files read whole"). A configuration
/// written by dump-config is about 9 KiB, a rosbag2 metadata.yaml a few KiB per storage file.
inline constexpr std::size_t kMaxConfigFileBytes = std::size_t{1} << 20;     // 1 MiB
inline constexpr std::size_t kMaxMapServerYamlBytes = std::size_t{1} << 20;  // 1 MiB
inline constexpr std::size_t kMaxBagMetadataBytes = std::size_t{16} << 20;   // 16 MiB
/// A map_server image (PGM): its header within the first 4 KiB, then at most 2^28 pixels
/// (16384 x 16384, 819 m square at 5 cm cells) of one byte.
inline constexpr std::size_t kMaxPgmHeaderBytes = 4096;
inline constexpr std::size_t kMaxMapServerPixels = std::size_t{1} << 28;

/// The content of `path`, reading at most `max_bytes` + 1 bytes: more is std::runtime_error
/// "PATH: more than N bytes (the limit of a WHAT); ...". A file that cannot be opened is
/// std::runtime_error "PATH: cannot open the WHAT".
std::string ReadWholeFile(const std::string& path, std::size_t max_bytes, const std::string& what);

}  // namespace keyplace
