#pragma once
// A fix as a ROS geometry_msgs/PoseWithCovarianceStamped, ready to publish on /initialpose for
// AMCL or nav2 (docs/NAVIGATION.md): `rostopic pub -f fix.yaml /initialpose
// geometry_msgs/PoseWithCovarianceStamped`, or the same fields in JSON.

#include <array>
#include <string>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"
#include "keyplace/localization/relocalizer.hpp"

namespace keyplace {

struct InitialPose {
  std::string frame_id = "map";  // the map's frame: the grid keyplace exports is in it
  Pose2 T_map_robot;
  // Over (x, y, yaw) of T_map_robot (m^2, m rad, rad^2): RelocalizationUpdate::covariance,
  // derived from the matches (docs/NAVIGATION.md).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

/// Throws std::invalid_argument unless `frame_id` is a ROS frame name (letters, digits, _ / . -):
/// the message writes it as is in YAML and JSON. Every InitialPose made by keyplace is checked.
void CheckInitialPoseFrameId(const std::string& frame_id);

/// The fix of an update whose status is kFixed (std::invalid_argument otherwise): its pose and
/// covariance. The one way to make the message from the localizer (the evaluation's FixEvent
/// keeps what this gives at the fix).
InitialPose InitialPoseOf(const RelocalizationUpdate& update, const std::string& frame_id = "map");

/// The message's 6x6 covariance, row-major over x, y, z, roll, pitch, yaw: the (x, y, yaw) terms
/// of InitialPose::covariance in their places (indices 0, 1, 5 of each row), 0 elsewhere.
std::array<double, 36> InitialPoseCovariance(const InitialPose& pose);

/// The message as YAML (header without stamp: a zero stamp means "now" to AMCL, and leaving it
/// out keeps the text valid for ROS 1's secs/nsecs and ROS 2's sec/nanosec alike). The 6x6
/// covariance is row-major over x, y, z, roll, pitch, yaw; z, roll and pitch are 0.
std::string InitialPoseYaml(const InitialPose& pose);
/// The same fields as JSON.
std::string InitialPoseJson(const InitialPose& pose);

/// Writes YAML, or JSON when the path ends in ".json", atomically. Throws std::runtime_error
/// naming the path when it cannot be written.
void WriteInitialPose(const InitialPose& pose, const std::string& path);

}  // namespace keyplace
