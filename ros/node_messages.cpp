#include "node_messages.hpp"

#include <cstdio>

#include <diagnostic_msgs/KeyValue.h>

#include "ros_support.hpp"

namespace keyplace::ros1 {

ScanInput ScanInputOf(const sensor_msgs::LaserScan& message, const Config& config,
                      const tf2_ros::Buffer& buffer) {
  ScanInput scan;
  scan.stamp_s = message.header.stamp.toSec();
  scan.frame_id = message.header.frame_id;
  scan.angle_min_rad = message.angle_min;
  scan.angle_increment_rad = message.angle_increment;
  scan.range_min_m = message.range_min;
  scan.range_max_m = message.range_max;
  scan.ranges_m = message.ranges;
  if (config.input.laser_pose.empty()) {
    std::string error;
    scan.T_robot_laser = LookupPose(buffer, config.input.base_frame, scan.frame_id,
                                    message.header.stamp, ros::Duration(0.0), &error);
    if (!scan.T_robot_laser) ROS_WARN_THROTTLE(5.0, "keyplace: laser pose: %s", error.c_str());
  }
  return scan;
}

OdometryInput OdometryInputOf(const nav_msgs::Odometry& message) {
  const geometry_msgs::Point& p = message.pose.pose.position;
  return {message.header.stamp.toSec(), Pose2(p.x, p.y, YawOf(message.pose.pose.orientation))};
}

std::optional<OdometryInput> TfOdometryAt(const ros::Time& stamp, const Config& config,
                                          const tf2_ros::Buffer& buffer) {
  std::string error;
  const std::optional<Pose2> T_odom_robot =
      LookupPose(buffer, config.input.odom_frame, config.input.base_frame, stamp,
                 ros::Duration(config.node.odometry_wait_s), &error);
  if (!T_odom_robot) {
    ROS_WARN_THROTTLE(5.0, "keyplace: odometry from tf: %s", error.c_str());
    return std::nullopt;
  }
  return OdometryInput{stamp.toSec(), *T_odom_robot};
}

geometry_msgs::TransformStamped TransformMessageOf(const StampedTransform& transform) {
  geometry_msgs::TransformStamped message;
  message.header.stamp.fromSec(transform.stamp_s);
  message.header.frame_id = transform.parent_frame;
  message.child_frame_id = transform.child_frame;
  message.transform.translation.x = transform.T_parent_child.x;
  message.transform.translation.y = transform.T_parent_child.y;
  message.transform.rotation = QuaternionOf(transform.T_parent_child.theta);
  return message;
}

void LogEvents(const std::vector<NodeEvent>& events) {
  for (const NodeEvent& event : events) {
    switch (event.level) {
      case NodeEventLevel::kInfo:
        ROS_INFO("keyplace: %s", event.what.c_str());
        break;
      case NodeEventLevel::kWarning:
        ROS_WARN("keyplace: %s", event.what.c_str());
        break;
      case NodeEventLevel::kError:
        ROS_ERROR("keyplace: %s", event.what.c_str());
        break;
    }
  }
}

void AddDiagnosticValue(const std::string& key, const std::string& value,
                        diagnostic_msgs::DiagnosticStatus& status) {
  diagnostic_msgs::KeyValue entry;
  entry.key = key;
  entry.value = value;
  status.values.push_back(entry);
}

std::string DiagnosticNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6g", value);
  return text;
}

}  // namespace keyplace::ros1
