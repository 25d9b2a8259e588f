#pragma once
// Locating test data: the project's own data/ and the shared data sets (../shared).

#include <string>

namespace keyplace::testing {

/// Root of the source tree.
std::string SourceDir();

/// The shared folder: $KEYPLACE_SHARED, else <source>/../shared. Throws std::runtime_error with
/// a clear message when it does not exist (tests that need it then fail, never skip silently).
std::string SharedDir();

/// <shared>/<relative>; throws std::runtime_error naming the path when it is missing.
std::string SharedFile(const std::string& relative);

/// A fresh empty temporary directory for one test, removed with its contents when the test
/// program exits.
std::string MakeTempDir(const std::string& prefix);

}  // namespace keyplace::testing
