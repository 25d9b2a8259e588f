// libFuzzer harness of the ROS 1 bag reader (ReadRos1Bag): rosbag's indexed read and, when the
// index is missing or damaged, keyplace's own walk over the chunks (uncompressed, bz2, lz4), then
// the messages' decoding and the poses' assembly. Correct rejection is std::invalid_argument
// naming the bag; anything else, and a log that breaks the reader's guarantees, is a finding.
// The seeds are the first few kB of fr079.orig.bag (cut: the index-less walk) and bags written by
// tests/io/ros1_bag_written_test.cpp's cases.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz_input_file.hpp"
#include "keyplace/io/ros1_bag.hpp"
#include "log_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const keyplace::fuzz::FuzzInputFile file("ros1-bag");
  const std::string& path = file.Write(data, size);
  try {
    keyplace::fuzz::CheckLog(keyplace::ReadRos1Bag(path));
  } catch (const std::invalid_argument& error) {
    keyplace::fuzz::ExpectNamedError("std::invalid_argument", error.what(), path);
  }
  return 0;
}
