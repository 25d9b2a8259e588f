// libFuzzer harness of the ROS 2 sqlite3 storage reader (ReadRos2Bag on one .db3 file): the
// database's schema and integrity checks, the topics and messages tables, message blobs, CDR
// messages and the poses' assembly. Correct rejection is std::invalid_argument naming the file;
// anything else, and a log that breaks the reader's guarantees, is a finding. Seeds: the first
// 4 scans of the ROS 2 fixtures' slice cut to 24 beams, written by sql.js
// (tests/io/ros2/generate_fixtures.mjs --seeds), odometry on /odom or only on /tf.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz_input_file.hpp"
#include "keyplace/io/ros2_bag.hpp"
#include "log_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const keyplace::fuzz::FuzzInputFile file("ros2-sqlite");
  const std::string& path = file.Write(data, size);
  try {
    keyplace::fuzz::CheckLog(keyplace::ReadRos2Bag(path));
  } catch (const std::invalid_argument& error) {
    keyplace::fuzz::ExpectNamedError("std::invalid_argument", error.what(), path);
  }
  return 0;
}
