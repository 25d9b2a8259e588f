#pragma once
// Internal: decoders of the CDR-serialized ROS 2 messages keyplace reads (sensor_msgs/msg/
// LaserScan, nav_msgs/msg/Odometry, tf2_msgs/msg/TFMessage), as rosbag2 stores them: a 4-byte
// encapsulation header (CDR big- or little-endian) then the fields with XCDR1 alignment (each
// primitive aligned to its size, at most 8, counted from the end of the header). Every length is
// checked against the bytes left before anything is allocated.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "io/bag_messages.hpp"

namespace keyplace {

/// A message that does not decode; what() says where and why (without the bag's name).
struct CdrError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

ScanFields DecodeRos2LaserScan(const std::uint8_t* data, std::size_t size);
OdometryFields DecodeRos2Odometry(const std::uint8_t* data, std::size_t size);
std::vector<TransformFields> DecodeRos2TfMessage(const std::uint8_t* data, std::size_t size);

}  // namespace keyplace
