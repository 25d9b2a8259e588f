#pragma once
// What a robot node takes in and sends out, without a middleware: the fields of
// sensor_msgs/LaserScan and nav_msgs/Odometry as plain structs, transforms for tf, and events for
// the wrapper to log. The node cores (RelocalizationNode, SlamNode) speak only these, so a ROS 1
// or ROS 2 wrapper is a file of message conversions (docs/ROS.md, "On a robot").

#include <optional>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"

namespace keyplace {

/// One laser scan as a driver sends it (sensor_msgs/LaserScan).
struct ScanInput {
  double stamp_s = 0.0;
  std::string frame_id;
  double angle_min_rad = 0.0;
  double angle_increment_rad = 0.0;
  double range_min_m = 0.0;
  double range_max_m = 0.0;
  std::vector<float> ranges_m;
  // The laser on the robot (base_frame -> frame_id, from tf), when the wrapper has it;
  // input.laser_pose overrides it.
  std::optional<Pose2> T_robot_laser;
};

/// One odometry pose (nav_msgs/Odometry, or the tf chain odom_frame -> base_frame).
struct OdometryInput {
  double stamp_s = 0.0;
  Pose2 T_odom_robot;
};

enum class NodeEventLevel { kInfo, kWarning, kError };

/// Something the wrapper should log.
struct NodeEvent {
  NodeEventLevel level = NodeEventLevel::kInfo;
  std::string what;
};

/// A transform to broadcast on tf.
struct StampedTransform {
  double stamp_s = 0.0;
  std::string parent_frame;
  std::string child_frame;
  Pose2 T_parent_child;
};

}  // namespace keyplace
