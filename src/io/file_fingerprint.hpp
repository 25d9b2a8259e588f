#pragma once

#include <string>

namespace keyplace {

/// "crc32:<8 hex digits>:<size in bytes>" of a file's bytes: identifies the log a map was built
/// from. Throws std::runtime_error naming the path when it cannot be read.
std::string FileFingerprint(const std::string& path);

}  // namespace keyplace
