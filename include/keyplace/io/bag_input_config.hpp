#pragma once
// How a ROS bag becomes a log: which topics hold the scans and the odometry, which tf frames are
// the odometry frame and the robot, where the laser sits. Config section `input`.

#include <optional>
#include <string>

#include "keyplace/common/pose2.hpp"

namespace keyplace {

struct BagInputConfig {
  // sensor_msgs/LaserScan messages: the scans.
  std::string scan_topic = "/scan";
  // nav_msgs/Odometry messages: the robot pose in the odometry frame. When the bag has no such
  // topic, the odometry comes from /tf (odom_frame -> base_frame).
  std::string odom_topic = "/odom";
  // tf frames of the odometry chain (REP 105 names) and of the robot whose pose the map uses.
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";
  // "x,y,theta" (m, m, rad): the laser on the robot (T_base_laser). Empty: from /tf_static or
  // /tf (base_frame -> the scans' frame_id). When given, it overrides tf.
  std::string laser_pose;
  // > 0: spread the beams as a CARMEN FLASER line (start -fov/2, step fov/n) over this field of
  // view (rad) instead of the messages' angle_min and angle_increment. For bags converted from
  // CARMEN logs whose converter wrote another spacing than the log's (fr079.orig.bag:
  // increment pi/359 where the log has pi/360).
  double scan_fov_rad = 0.0;
};

/// Throws std::invalid_argument naming the field for an empty topic or frame, a laser_pose that
/// is not three finite numbers, or a field of view outside [0, 2 pi].
void Validate(const BagInputConfig& config);

/// BagInputConfig::laser_pose as a pose; nothing when empty. Throws std::invalid_argument for
/// text that is not "x,y,theta".
std::optional<Pose2> ParseLaserPose(const std::string& text);

}  // namespace keyplace
