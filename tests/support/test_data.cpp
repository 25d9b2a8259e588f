#include "support/test_data.hpp"

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <vector>

namespace keyplace::testing {
namespace fs = std::filesystem;

std::string SourceDir() { return KEYPLACE_SOURCE_DIR; }

std::string SharedDir() {
  const char* env = std::getenv("KEYPLACE_SHARED");
  const fs::path dir =
      env != nullptr && *env != '\0' ? fs::path(env) : fs::path(SourceDir()) / ".." / "shared";
  if (!fs::is_directory(dir)) {
    throw std::runtime_error("shared data folder not found at '" + dir.string() +
                             "': put the project's shared/ beside the checkout or set "
                             "KEYPLACE_SHARED to its path");
  }
  return fs::canonical(dir).string();
}

std::string SharedFile(const std::string& relative) {
  const fs::path path = fs::path(SharedDir()) / relative;
  if (!fs::exists(path)) {
    throw std::runtime_error("shared data file missing: '" + path.string() + "'");
  }
  return path.string();
}

namespace {

// Removes the test's temporary directories when the test program exits, so that repeated test
// runs do not fill /tmp.
class TempDirRegistry {
 public:
  TempDirRegistry() = default;
  TempDirRegistry(const TempDirRegistry&) = delete;
  TempDirRegistry& operator=(const TempDirRegistry&) = delete;
  ~TempDirRegistry() {
    for (const std::string& dir : dirs_) {
      std::error_code ignored;
      fs::remove_all(dir, ignored);
    }
  }
  void Add(const std::string& dir) { dirs_.push_back(dir); }

 private:
  std::vector<std::string> dirs_;
};

TempDirRegistry& Registry() {
  static TempDirRegistry registry;
  return registry;
}

}  // namespace

std::string MakeTempDir(const std::string& prefix) {
  std::string pattern = (fs::temp_directory_path() / (prefix + "-XXXXXX")).string();
  if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed: " + pattern);
  Registry().Add(pattern);
  return pattern;
}

}  // namespace keyplace::testing
