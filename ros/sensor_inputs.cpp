#include "sensor_inputs.hpp"

#include <cstdint>
#include <exception>
#include <optional>
#include <utility>

#include "node_messages.hpp"

namespace keyplace::ros1 {

// Queue lengths: the scans a node absorbs while it spends a recognition or a /map on one (0.1-0.4
// s at 5-10 scans/s), and the odometry messages (up to 100 Hz) that come meanwhile.
constexpr std::uint32_t kScanQueue = 200;
constexpr std::uint32_t kOdometryQueue = 500;

SensorInputs::SensorInputs(ros::NodeHandle& node, const Config& config, SensorCallbacks callbacks)
    : config_(config), callbacks_(std::move(callbacks)), tf_listener_(tf_buffer_) {
  scan_subscriber_ =
      node.subscribe(config.input.scan_topic, kScanQueue, &SensorInputs::OnScan, this);
  if (config.node.odometry == NodeOdometry::kTopic) {
    odom_subscriber_ =
        node.subscribe(config.input.odom_topic, kOdometryQueue, &SensorInputs::OnOdometry, this);
  }
  timer_ = node.createTimer(ros::Duration(0.1), &SensorInputs::OnTimer, this);
}

std::string SensorInputs::Description() const {
  const std::string odometry =
      config_.node.odometry == NodeOdometry::kTopic
          ? odom_subscriber_.getTopic()
          : "tf " + config_.input.odom_frame + " -> " + config_.input.base_frame;
  return scan_subscriber_.getTopic() + " with odometry from " + odometry;
}

void SensorInputs::Broadcast(const StampedTransform& transform) {
  tf_broadcaster_.sendTransform(TransformMessageOf(transform));
}

void SensorInputs::OnScan(const sensor_msgs::LaserScan::ConstPtr& message) {
  try {
    if (config_.node.odometry == NodeOdometry::kTf) {
      const std::optional<OdometryInput> odometry =
          TfOdometryAt(message->header.stamp, config_, tf_buffer_);
      if (odometry) callbacks_.odometry(*odometry);
    }
    callbacks_.scan(ScanInputOf(*message, config_, tf_buffer_));
  } catch (const std::exception& error) {
    ROS_ERROR("keyplace: scan: %s", error.what());
  }
}

void SensorInputs::OnOdometry(const nav_msgs::Odometry::ConstPtr& message) {
  try {
    callbacks_.odometry(OdometryInputOf(*message));
  } catch (const std::exception& error) {
    ROS_ERROR("keyplace: odometry: %s", error.what());
  }
}

void SensorInputs::OnTimer(const ros::TimerEvent&) {
  try {
    callbacks_.clock(ros::Time::now().toSec());
  } catch (const std::exception& error) {
    ROS_ERROR("keyplace: %s", error.what());
  }
}

}  // namespace keyplace::ros1
