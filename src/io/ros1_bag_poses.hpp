#pragma once
// Internal: what a bag's messages gave (scans, odometry, transforms) turned into a CarmenLog:
// the odometry pose of each scan interpolated at its stamp, the laser pose on the robot, and an
// error naming the bag, topic and problem when one of them cannot be had.

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "io/ros1_bag_source.hpp"
#include "io/tf_tree.hpp"
#include "keyplace/io/bag_input_config.hpp"
#include "keyplace/io/carmen_log.hpp"

namespace keyplace {

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
                         const BagSummary& summary, BagContents&& contents);

}  // namespace keyplace
