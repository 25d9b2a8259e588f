#pragma once
// ROS 1 messages to and from what keyplace's node cores speak (io/sensor_input.hpp): scans,
// odometry (a topic or tf), transforms, events to log, diagnostics entries. Shared by
// keyplace_ros_relocalize and keyplace_ros_slam.

#include <optional>
#include <string>
#include <vector>

#include <diagnostic_msgs/DiagnosticStatus.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_ros/buffer.h>

#include "keyplace/config/config.hpp"
#include "keyplace/io/sensor_input.hpp"

namespace keyplace::ros1 {

/// The scan with the laser's pose from tf (base_frame -> the scan's frame) unless input.laser_pose
/// gives it; without either, the scan has no laser pose and the core drops it, saying why.
ScanInput ScanInputOf(const sensor_msgs::LaserScan& message, const Config& config,
                      const tf2_ros::Buffer& buffer);

OdometryInput OdometryInputOf(const nav_msgs::Odometry& message);

/// The odometry at `stamp` from the tf chain odom_frame -> base_frame (node.odometry = tf),
/// waiting up to node.odometry_wait_s for it; nothing (logged, throttled) when tf has none.
std::optional<OdometryInput> TfOdometryAt(const ros::Time& stamp, const Config& config,
                                          const tf2_ros::Buffer& buffer);

geometry_msgs::TransformStamped TransformMessageOf(const StampedTransform& transform);

/// Logs each event at its level, prefixed "keyplace: ".
void LogEvents(const std::vector<NodeEvent>& events);

/// Appends key = value to a diagnostic status.
void AddDiagnosticValue(const std::string& key, const std::string& value,
                        diagnostic_msgs::DiagnosticStatus& status);

/// A number as diagnostics show it (6 significant digits).
std::string DiagnosticNumber(double value);

}  // namespace keyplace::ros1
