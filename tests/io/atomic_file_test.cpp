#include "io/atomic_file.hpp"

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
