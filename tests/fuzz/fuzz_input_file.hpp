#pragma once
// A file that holds the current fuzz input, for readers that take a path: one file per process,
// created once and rewritten for every input, in /dev/shm when there is one (no disk writes at
// tens of thousands of inputs per second), removed when the process ends normally.

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace keyplace::fuzz {

class FuzzInputFile {
 public:
  // `stem` goes into the file's name, so that a left-over file says which harness made it.
  explicit FuzzInputFile(const std::string& stem) {
    struct stat status {};
    const char* tmpdir = std::getenv("TMPDIR");
    std::string folder = stat("/dev/shm", &status) == 0 && S_ISDIR(status.st_mode)
                             ? "/dev/shm"
                             : (tmpdir != nullptr && *tmpdir != '\0' ? tmpdir : "/tmp");
    std::string pattern = folder + "/keyplace-fuzz-" + stem + "-XXXXXX";
    const int fd = mkstemp(pattern.data());
    if (fd < 0) Die("cannot create a file like " + pattern);
    close(fd);
    path_ = pattern;
  }
  ~FuzzInputFile() { unlink(path_.c_str()); }
  FuzzInputFile(const FuzzInputFile&) = delete;
  FuzzInputFile& operator=(const FuzzInputFile&) = delete;

  // Replaces the file's content with `data`; returns its path.
  const std::string& Write(const std::uint8_t* data, std::size_t size) const {
    const int fd = open(path_.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
    if (fd < 0) Die("cannot open " + path_);
    std::size_t written = 0;
    while (written < size) {
      const ssize_t count = write(fd, data + written, size - written);
      if (count < 0 && errno == EINTR) continue;
      if (count <= 0) Die("cannot write " + path_);
      written += static_cast<std::size_t>(count);
    }
    close(fd);
    return path_;
  }

  const std::string& path() const { return path_; }

 private:
  // A broken harness must not look like a finding in the library, nor like a pass.
  [[noreturn]] static void Die(const std::string& what) {
    std::fprintf(stderr, "fuzz harness: %s (%s)\n", what.c_str(), std::strerror(errno));
    std::exit(2);
  }

  std::string path_;
};

// Stops the run with the unexpected error: libFuzzer and the replay driver report it as a crash
// and keep the input.
[[noreturn]] inline void Finding(const std::string& what) {
  std::fprintf(stderr, "fuzz finding: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

// A documented rejection: an error of the documented type whose message names `name` (the file
// or source), as every error of keyplace does.
inline void ExpectNamedError(const char* type, const std::string& message,
                             const std::string& name) {
  if (message.find(name) == std::string::npos) {
    Finding(std::string(type) + " without the file name '" + name + "': " + message);
  }
}

}  // namespace keyplace::fuzz
