// Runs a fuzz harness (LLVMFuzzerTestOneInput) over every file of the directories it is given, in
// name order, without libFuzzer: the seed corpus and the regression inputs of each harness become
// ctest tests of the ordinary and the sanitized builds. A crash, a sanitizer report or a finding
// of the harness ends the run with the input's name on stderr.
//
// Usage: NAME_replay CORPUS_DIR [REGRESSIONS_DIR]   (a missing REGRESSIONS_DIR has no inputs yet)

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

std::vector<std::filesystem::path> FilesIn(const std::filesystem::path& folder) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<std::uint8_t> ReadBytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: %s CORPUS_DIR [REGRESSIONS_DIR]\n", argv[0]);
    return 2;
  }
  std::vector<std::filesystem::path> files;
  for (int k = 1; k < argc; ++k) {
    std::error_code error;
    if (k == 2 && !std::filesystem::exists(argv[k], error)) continue;
    if (!std::filesystem::is_directory(argv[k], error)) {
      std::fprintf(stderr, "%s: not a directory\n", argv[k]);
      return 2;
    }
    const auto found = FilesIn(argv[k]);
    files.insert(files.end(), found.begin(), found.end());
  }
  // An empty seed corpus would make this test pass without running the harness once.
  if (files.empty()) {
    std::fprintf(stderr, "%s: no inputs\n", argv[1]);
    return 2;
  }
  for (const auto& file : files) {
    std::fprintf(stderr, "input %s\n", file.c_str());
    const std::vector<std::uint8_t> bytes = ReadBytes(file);
    LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
  }
  std::fprintf(stderr, "%zu inputs, no finding\n", files.size());
  return 0;
}
