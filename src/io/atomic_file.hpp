#pragma once
// Writing output files so that a failure never leaves a half-written or corrupted file behind.

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace keyplace {

/// Calls `write` on a stream to a temporary file next to `path`, then renames it over `path`.
/// On any failure (exception in `write`, I/O error) the temporary file is removed, `path` is left
/// untouched and std::runtime_error names the path.
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

/// The temporary file a write of `path` goes to first: `.NAME.tmpPID` beside it. Temporary files
/// of `path` left by writers that no longer run (killed before their rename) are removed here.
std::string TemporaryPathFor(const std::string& path);

/// Makes `temporary` durable (fsync), renames it onto `path` and syncs the directory, so that after
/// a power loss `path` holds either its old or its new content. Throws std::runtime_error naming
/// `path`.
void CommitTemporary(const std::string& temporary, const std::string& path);

/// Checks, before any work, that `path` can be written: its directory exists and is writable, it
/// is not a directory, and it is none of `inputs` (the same file under any name: hard link,
/// symbolic link, ./name, as an output would replace the input it is computed from) nor an
/// existing file of an input that is a rosbag2 directory. Every writer of the CLI and of the
/// Python module checks here. Throws std::invalid_argument naming the path and the input.
void CheckOutputPath(const std::string& path, const std::vector<std::string>& inputs);

/// The part of CheckOutputPath that protects the inputs: `path`, when it exists, is none of
/// `inputs` under any name, nor a file of an input rosbag2 directory. std::invalid_argument.
void CheckNotAnInput(const std::string& path, const std::vector<std::string>& inputs);

}  // namespace keyplace
