#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/types.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace keyplace {

namespace {

// fsync of a file or directory by name (a read-only descriptor may be synced on Linux).
void SyncPath(const std::string& name, const std::string& path) {
  const int descriptor = ::open(name.c_str(), O_RDONLY | O_CLOEXEC);
  if (descriptor < 0) throw std::runtime_error(path + ": cannot open " + name + " to sync it");
  const int status = ::fsync(descriptor);
  ::close(descriptor);
  if (status != 0) throw std::runtime_error(path + ": cannot sync " + name);
}

// PID of a temporary file name ".NAME.tmpPID", or 0.
pid_t TemporaryOwner(const std::string& file_name, const std::string& prefix) {
  if (file_name.size() <= prefix.size() || file_name.compare(0, prefix.size(), prefix) != 0) {
    return 0;
  }
  const std::string digits = file_name.substr(prefix.size());
  if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) return 0;
  return static_cast<pid_t>(std::stol(digits));
}

}  // namespace

std::string TemporaryPathFor(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path directory = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  const std::string prefix = "." + target.filename().string() + ".tmp";
  std::error_code error;
  for (fs::directory_iterator it(directory, error), end; !error && it != end; it.increment(error)) {
    const pid_t owner = TemporaryOwner(it->path().filename().string(), prefix);
    // kill(pid, 0) fails with ESRCH only when no such process exists: its write was cut short.
    if (owner > 0 && owner != getpid() && ::kill(owner, 0) != 0 && errno == ESRCH) {
      std::error_code ignored;
      fs::remove(it->path(), ignored);
    }
  }
  std::string name = prefix;
  name += std::to_string(getpid());
  return (target.parent_path() / name).string();
}

void CommitTemporary(const std::string& temporary, const std::string& path) {
  namespace fs = std::filesystem;
  SyncPath(temporary, path);
  std::error_code error;
  fs::rename(temporary, path, error);
  if (error) throw std::runtime_error(path + ": cannot rename temporary file: " + error.message());
  const fs::path directory = fs::path(path).parent_path();
  SyncPath(directory.empty() ? std::string(".") : directory.string(), path);
}

void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  const std::string temporary = TemporaryPathFor(path);
  try {
    std::ofstream stream(temporary, std::ios::binary | std::ios::trunc);
    if (!stream) throw std::runtime_error(path + ": cannot create temporary file " + temporary);
    write(stream);
    stream.flush();
    if (!stream) throw std::runtime_error(path + ": write failed");
    stream.close();
    CommitTemporary(temporary, path);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
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
  CheckNotAnInput(path, inputs);
}

void CheckNotAnInput(const std::string& path, const std::vector<std::string>& inputs) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path directory = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  std::error_code error;
  if (!fs::exists(target, error)) return;
  for (const std::string& input : inputs) {
    if (input.empty()) continue;
    const fs::path source(input);
    if (fs::equivalent(target, source, error)) {
      std::string message = path;
      message += ": is the input " + input;
      message += "; writing it would destroy the input";
      throw std::invalid_argument(message);
    }
    // A rosbag2 directory is read through the files in it (metadata.yaml, its storage files).
    if (fs::is_directory(source, error) && fs::exists(source / "metadata.yaml", error) &&
        fs::equivalent(directory, source, error)) {
      std::string message = path;
      message += ": is a file of the input bag directory " + input;
      message += "; writing it would damage the input";
      throw std::invalid_argument(message);
    }
  }
}

}  // namespace keyplace
