#include "io/atomic_file.hpp"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

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

}  // namespace keyplace
