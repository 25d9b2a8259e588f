#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "io/atomic_file.hpp"

namespace keyplace {
namespace {

namespace fs = std::filesystem;

class OutputPath : public ::testing::Test {
 protected:
  void SetUp() override {
    directory_ = fs::temp_directory_path() / ("keyplace-output-" + std::to_string(getpid()));
    fs::create_directories(directory_);
    std::ofstream(directory_ / "input.log") << "FLASER\n";
  }
  void TearDown() override { fs::remove_all(directory_); }
  std::string Path(const std::string& name) const { return (directory_ / name).string(); }

  fs::path directory_;
};

TEST_F(OutputPath, ANewFileInAnExistingDirectoryIsFine) {
  EXPECT_NO_THROW(CheckOutputPath(Path("out.json"), {Path("input.log")}));
}

TEST_F(OutputPath, TheInputUnderAnyNameIsRefused) {
  EXPECT_THROW(CheckOutputPath(Path("input.log"), {Path("input.log")}), std::invalid_argument);
  fs::create_hard_link(directory_ / "input.log", directory_ / "alias.log");
  try {
    CheckOutputPath(Path("alias.log"), {"", Path("input.log")});
    FAIL() << "a hard link to the input was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("is the input"), std::string::npos) << error.what();
  }
  // Another existing file is only replaced.
  std::ofstream(directory_ / "old.json") << "{}";
  EXPECT_NO_THROW(CheckOutputPath(Path("old.json"), {Path("input.log")}));
}

TEST_F(OutputPath, MissingDirectoriesAndDirectoriesAreRefused) {
  EXPECT_THROW(CheckOutputPath(Path("nowhere/out.json"), {}), std::invalid_argument);
  fs::create_directories(directory_ / "folder");
  EXPECT_THROW(CheckOutputPath(Path("folder"), {}), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
