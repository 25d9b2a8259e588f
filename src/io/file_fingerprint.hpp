#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace keyplace {

/// "crc32:<8 hex digits>:<size in bytes>": identifies the log a map was built from.
std::string FormatFingerprint(std::uint32_t crc32, std::uint64_t bytes);

/// FormatFingerprint of a regular file's bytes (ReadCarmenLog computes the same while reading,
/// CarmenLog::fingerprint; this is for logs built in memory with a path). Throws
/// std::runtime_error naming the path when it cannot be read or is not a regular file: a pipe
/// read a second time would give other bytes or block.
std::string FileFingerprint(const std::string& path);

/// The fingerprint of the files' bytes one after the other (a ROS 2 bag's storage files).
std::string FilesFingerprint(const std::vector<std::string>& paths);

}  // namespace keyplace
