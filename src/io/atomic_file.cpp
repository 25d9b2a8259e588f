#include "io/atomic_file.hpp"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace keyplace {

void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path temporary =
      target.parent_path() / ("." + target.filename().string() + ".tmp" + std::to_string(getpid()));
  try {
    std::ofstream stream(temporary, std::ios::binary | std::ios::trunc);
    if (!stream)
      throw std::runtime_error(path + ": cannot create temporary file " + temporary.string());
    write(stream);
    stream.flush();
    if (!stream) throw std::runtime_error(path + ": write failed");
    stream.close();
    std::error_code error;
    fs::rename(temporary, target, error);
    if (error)
      throw std::runtime_error(path + ": cannot rename temporary file: " + error.message());
  } catch (...) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw;
  }
}

void CheckOutputPath(const std::string& path, const std::vector<std::string>& inputs) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path directory = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  std::error_code error;
  if (!fs::is_directory(directory, error)) {
    throw std::invalid_argument(path + ": the directory " + directory.string() + " does not exist");
  }
  if (access(directory.c_str(), W_OK) != 0) {
    throw std::invalid_argument(path + ": the directory " + directory.string() +
                                " is not writable");
  }
  if (fs::is_directory(target, error)) throw std::invalid_argument(path + ": is a directory");
  if (!fs::exists(target, error)) return;
  for (const std::string& input : inputs) {
    if (!input.empty() && fs::equivalent(target, fs::path(input), error)) {
      throw std::invalid_argument(path + ": is the input " + input +
                                  "; writing it would destroy the input");
    }
  }
}

}  // namespace keyplace
