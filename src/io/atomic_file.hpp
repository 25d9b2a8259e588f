#pragma once
// Writing output files so that a failure never leaves a half-written or corrupted file behind.

#include <functional>
#include <ostream>
#include <string>

namespace keyplace {

/// Calls `write` on a stream to a temporary file next to `path`, then renames it over `path`.
/// On any failure (exception in `write`, I/O error) the temporary file is removed, `path` is left
/// untouched and std::runtime_error names the path.
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace keyplace
