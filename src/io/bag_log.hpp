#pragma once
// Internal: what a bag's messages gave (scans, odometry, transforms) turned into a CarmenLog, for
// ROS 1 and ROS 2 bags alike: the odometry pose of each scan interpolated at its stamp, the laser
// pose on the robot, and an error naming the bag, topic and problem when one of them cannot be
// had.

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "io/tf_tree.hpp"
#include "keyplace/io/bag_input_config.hpp"
#include "keyplace/io/carmen_log.hpp"

namespace keyplace {

/// The message types keyplace reads, as a bag format names them.
struct BagTypeNames {
  const char* format;  // CarmenLog::format
  const char* scan;
  const char* odometry;
  const char* transforms;
};
inline constexpr BagTypeNames kRos1TypeNames{"ROS 1 bag", "sensor_msgs/LaserScan",
                                             "nav_msgs/Odometry", "tf2_msgs/TFMessage"};
inline constexpr BagTypeNames kRos2TypeNames{"ROS 2 bag", "sensor_msgs/msg/LaserScan",
                                             "nav_msgs/msg/Odometry", "tf2_msgs/msg/TFMessage"};

/// What a walk over a bag found besides the messages.
struct BagSummary {
  std::vector<LogTopic> topics;       // every topic, with its type and message count
  std::vector<std::string> warnings;  // what was dropped, naming the bag
  std::size_t messages = 0;           // in the bag (the complete chunks for a cut one)
};

struct BagContents {
  std::vector<LogScan> scans;             // ranges, angles, stamps, valid beams; no poses yet
  std::vector<std::string> scan_frames;   // header.frame_id of each scan
  std::vector<OdometryMessage> odometry;  // the odometry topic's messages, in bag order
  TfTree tf;                              // /tf and /tf_static
  std::size_t tf_messages = 0;
  std::map<std::string, std::string> wrong_types;  // topic -> the type its messages have
  std::size_t invalid_beams = 0;
  std::size_t no_return_beams = 0;
};

/// The log of a bag at `path`; throws std::invalid_argument naming the bag, the topic and the
/// problem (ReadRos1Bag lists them).
CarmenLog AssembleBagLog(const std::string& path, const BagInputConfig& config,
                         const BagTypeNames& types, const BagSummary& summary,
                         BagContents&& contents);

}  // namespace keyplace
