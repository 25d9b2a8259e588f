#pragma once
// What keyplace's ROS 1 nodes share: the keyplace configuration from the node's private
// parameters, planar poses from and to ROS messages, and the laser's place on the robot from tf.

#include <optional>
#include <string>

#include <geometry_msgs/Quaternion.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>

#include "keyplace/common/pose2.hpp"
#include "keyplace/config/config.hpp"

namespace keyplace::ros1 {

/// The configuration as `keyplace` commands resolve it, from the private parameters: ~preset
/// (default `default_preset`), then ~config_file (a YAML file as `keyplace dump-config` writes),
/// then every configuration key given as a parameter (`~node/publish`, `~input/scan_topic`: the
/// key with '/' for '.'), then ~set (a list of "section.key=value" strings, or one string of
/// them separated by spaces). Throws std::invalid_argument naming the parameter or key.
Config ConfigFromParameters(const ros::NodeHandle& private_node, const std::string& default_preset);

/// A required string parameter; throws std::invalid_argument naming it when missing or empty.
std::string RequiredParameter(const ros::NodeHandle& private_node, const std::string& name);

double YawOf(const geometry_msgs::Quaternion& q);
geometry_msgs::Quaternion QuaternionOf(double yaw_rad);

/// T_parent_child from tf at `stamp` (static transforms at any time); nothing when tf cannot
/// give it within `timeout`.
std::optional<Pose2> LookupPose(const tf2_ros::Buffer& buffer, const std::string& parent_frame,
                                const std::string& child_frame, const ros::Time& stamp,
                                const ros::Duration& timeout, std::string* error = nullptr);

}  // namespace keyplace::ros1
