// libFuzzer harness of the CDR decoders of ROS 2 messages (io/ros2_cdr.hpp): the input is one
// serialized message, given to each of the three decoders. Correct rejection is CdrError; a
// decoded message must not hold more elements than its bytes can encode (lengths are checked
// before anything is allocated). Seeds: LaserScan, Odometry and TFMessage messages of the
// fixtures in tests/data/ros2, little endian, and a big-endian LaserScan.

#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_input_file.hpp"
#include "io/ros2_cdr.hpp"

namespace {

template <class Decode>
void Decodes(const Decode& decode) {
  try {
    decode();
  } catch (const keyplace::CdrError& error) {
    if (std::string(error.what()).find("byte ") != 0) {
      keyplace::fuzz::Finding(std::string("CdrError without its byte: ") + error.what());
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Decodes([&] {
    const keyplace::ScanFields scan = keyplace::DecodeRos2LaserScan(data, size);
    if (scan.ranges.size() * 4 > size || scan.frame_id.size() > size) {
      keyplace::fuzz::Finding("a LaserScan with more ranges or frame bytes than its bytes hold");
    }
  });
  Decodes([&] { keyplace::DecodeRos2Odometry(data, size); });
  Decodes([&] {
    if (keyplace::DecodeRos2TfMessage(data, size).size() * 72 > size) {
      keyplace::fuzz::Finding("a TFMessage with more transforms than its bytes hold");
    }
  });
  return 0;
}
