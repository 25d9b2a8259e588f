#pragma once
// One 2D laser scan as read from a log, in the laser frame.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"

namespace keyplace {

struct LaserScan {
  std::vector<double> ranges_m;    // one per beam, as written in the log
  std::vector<double> angles_rad;  // beam bearing in the laser frame, same length as ranges_m
  // 1 when the beam returned a usable range (finite, >= 0, < max_range_m), 0 otherwise.
  std::vector<std::uint8_t> valid;
  double max_range_m = 0.0;  // readings at or beyond this are "no return"

  double timestamp_s = 0.0;         // ipc_timestamp as written in the log
  double logger_timestamp_s = 0.0;  // logger_timestamp (the monotonic one for Intel raw)

  // Robot pose in the odometry frame (raw logs), when the log carries one.
  std::optional<Pose2> odometry_pose;
  // SLAM-corrected robot pose (corrected logs), when the log carries one.
  std::optional<Pose2> corrected_pose;
  // Mounting of the laser on the robot: laser pose = robot pose * T_robot_laser.
  Pose2 T_robot_laser;
  // The laser pose exactly as the log writes it, in the log's frame (corrected or odometry).
  // Recomposing robot pose * T_robot_laser differs from it by a few ulps, which is enough to
  // flip near-equal edge lengths in FLIRT's spanning trees.
  Pose2 logged_laser_pose;

  std::size_t line = 0;  // 1-based line number of the laser line in its file

  std::size_t size() const { return ranges_m.size(); }
  std::size_t CountValid() const;

  /// Endpoint of beam i in the laser frame (uses the raw range even for invalid beams).
  Eigen::Vector2d Endpoint(std::size_t i) const;
  /// Endpoints of the valid beams only, in the laser frame.
  std::vector<Eigen::Vector2d> ValidEndpoints() const;
};

}  // namespace keyplace
