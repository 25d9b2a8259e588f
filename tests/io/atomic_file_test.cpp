#include "io/atomic_file.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>

#include "support/test_data.hpp"

namespace keyplace {
namespace {

std::string ReadAll(const std::string& path) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

// A process id that no process has now.
pid_t DeadProcessId() {
  for (pid_t pid = 4000000; pid > 1000; --pid) {
    if (kill(pid, 0) != 0 && errno == ESRCH) return pid;
  }
  return 0;
}

TEST(WriteFileAtomically, RemovesTemporariesOfKilledWritersOnly) {
  const std::string dir = testing::MakeTempDir("atomic");
  const pid_t dead = DeadProcessId();
  ASSERT_GT(dead, 0);
  const std::string stale = dir + "/.out.txt.tmp" + std::to_string(dead);
  const std::string live = dir + "/.out.txt.tmp" + std::to_string(getppid());
  const std::string other = dir + "/.other.txt.tmp" + std::to_string(dead);
  for (const std::string& path : {stale, live, other}) std::ofstream(path) << "partial";
  WriteFileAtomically(dir + "/out.txt", [](std::ostream& out) { out << "new"; });
  EXPECT_EQ(ReadAll(dir + "/out.txt"), "new");
  EXPECT_FALSE(std::filesystem::exists(stale)) << "a killed writer's temporary was left";
  EXPECT_TRUE(std::filesystem::exists(live)) << "a running writer's temporary was removed";
  EXPECT_TRUE(std::filesystem::exists(other)) << "another file's temporary was removed";
}

TEST(WriteFileAtomically, KillNineWhileWritingKeepsTheOldFile) {
  const std::string dir = testing::MakeTempDir("atomic");
  const std::string path = dir + "/out.txt";
  WriteFileAtomically(path, [](std::ostream& out) { out << "old"; });
  int started[2];
  ASSERT_EQ(pipe(started), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // Half of the new content is written when the parent kills this process.
    WriteFileAtomically(path, [&](std::ostream& out) {
      out << "new but";
      out.flush();
      const char byte = 'x';
      if (write(started[1], &byte, 1) != 1) _exit(2);
      pause();
    });
    _exit(1);
  }
  char byte = 0;
  ASSERT_EQ(read(started[0], &byte, 1), 1);
  ASSERT_EQ(kill(child, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status));
  close(started[0]);
  close(started[1]);
  EXPECT_EQ(ReadAll(path), "old");
  const std::string temporary = dir + "/.out.txt.tmp" + std::to_string(child);
  EXPECT_TRUE(std::filesystem::exists(temporary));
  // The next write cleans up after the killed one.
  WriteFileAtomically(path, [](std::ostream& out) { out << "newer"; });
  EXPECT_EQ(ReadAll(path), "newer");
  EXPECT_FALSE(std::filesystem::exists(temporary));
}

TEST(WriteFileAtomically, ReplacesContent) {
  const std::string path = testing::MakeTempDir("atomic") + "/out.txt";
  WriteFileAtomically(path, [](std::ostream& out) { out << "first"; });
  WriteFileAtomically(path, [](std::ostream& out) { out << "second"; });
  EXPECT_EQ(ReadAll(path), "second");
}

TEST(WriteFileAtomically, FailureKeepsOldFileAndLeavesNoTemporary) {
  const std::string dir = testing::MakeTempDir("atomic");
  const std::string path = dir + "/out.txt";
  WriteFileAtomically(path, [](std::ostream& out) { out << "precious"; });
  EXPECT_THROW(WriteFileAtomically(path,
                                   [](std::ostream& out) {
                                     out << "half";
                                     throw std::runtime_error("boom");
                                   }),
               std::runtime_error);
  EXPECT_EQ(ReadAll(path), "precious");
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 1);
}

TEST(WriteFileAtomically, UnwritableDirectoryNamesPath) {
  try {
    WriteFileAtomically("/nonexistent-dir/out.txt", [](std::ostream& out) { out << "x"; });
    FAIL() << "no exception";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent-dir/out.txt"), std::string::npos);
  }
}

}  // namespace
}  // namespace keyplace
