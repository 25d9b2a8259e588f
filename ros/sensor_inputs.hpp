#pragma once
// The inputs both keyplace ROS 1 nodes take: the laser scans, the odometry (a topic, or the tf
// chain odom_frame -> base_frame at each scan's stamp) and a 10 Hz clock, converted to what the
// node cores take and handed to the node's callbacks. A callback that throws is logged, never
// fatal. Also the tf broadcaster the nodes publish map -> odom with.

#include <functional>
#include <string>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include "keyplace/config/config.hpp"
#include "keyplace/io/sensor_input.hpp"

namespace keyplace::ros1 {

struct SensorCallbacks {
  std::function<void(const OdometryInput&)> odometry;
  std::function<void(const ScanInput&)> scan;
  std::function<void(double now_s)> clock;
};

class SensorInputs {
 public:
  /// Subscribes to input.scan_topic (and input.odom_topic when node.odometry is topic) and starts
  /// the clock. `config` must outlive this object.
  SensorInputs(ros::NodeHandle& node, const Config& config, SensorCallbacks callbacks);

  /// "/scan with odometry from /odom" (or "from tf odom -> base_link"), for the start message.
  std::string Description() const;

  void Broadcast(const StampedTransform& transform);

 private:
  void OnScan(const sensor_msgs::LaserScan::ConstPtr& message);
  void OnOdometry(const nav_msgs::Odometry::ConstPtr& message);
  void OnTimer(const ros::TimerEvent& event);

  const Config& config_;
  SensorCallbacks callbacks_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  ros::Subscriber scan_subscriber_;
  ros::Subscriber odom_subscriber_;
  ros::Timer timer_;
};

}  // namespace keyplace::ros1
