// libFuzzer harness of the ROS 2 MCAP reader (ReadRos2Bag on one .mcap file): records, chunks
// (uncompressed, lz4, zstd, CRC), schemas and channels, CDR messages and the poses' assembly.
// Correct rejection is std::invalid_argument naming the file; anything else, and a log that
// breaks the reader's guarantees, is a finding. Seeds: cut copies of the fixtures of
// tests/data/ros2 (one per chunk compression, a few chunks each).

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz_input_file.hpp"
#include "keyplace/io/ros2_bag.hpp"
#include "log_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const keyplace::fuzz::FuzzInputFile file("mcap");
  const std::string& path = file.Write(data, size);
  try {
    keyplace::fuzz::CheckLog(keyplace::ReadRos2Bag(path));
  } catch (const std::invalid_argument& error) {
    keyplace::fuzz::ExpectNamedError("std::invalid_argument", error.what(), path);
  }
  return 0;
}
