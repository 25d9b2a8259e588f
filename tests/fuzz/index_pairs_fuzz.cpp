// libFuzzer harness of the raw -> corrected scan index reader (ReadIndexPairs,
// `raw_index<TAB>corrected_index` rows). Correct rejection is std::invalid_argument naming the
// file; anything else is a finding.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz_input_file.hpp"
#include "keyplace/io/relations.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const keyplace::fuzz::FuzzInputFile file("index-pairs");
  const std::string& path = file.Write(data, size);
  try {
    const auto pairs = keyplace::ReadIndexPairs(path);
    // Each row is at least "0 0": more pairs than a third of the bytes cannot come from the file.
    if (pairs.size() > size / 3) keyplace::fuzz::Finding("more index pairs than rows in the file");
  } catch (const std::invalid_argument& error) {
    keyplace::fuzz::ExpectNamedError("std::invalid_argument", error.what(), path);
  }
  return 0;
}
