// keyplace_ros_relocalize: the RelocalizationNode on ROS 1. Scans and odometry (a topic or the
// tf chain) in; /initialpose, map -> odom on tf and the status on /diagnostics out; services
// ~relocalize and ~save_status. Everything it decides comes from the library's node core; this
// file only converts messages (docs/ROS.md, "On a robot").

#include <algorithm>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include "keyplace/localization/relocalization_node.hpp"
#include "keyplace/store/map_file.hpp"
#include "node_messages.hpp"
#include "ros_support.hpp"
#include "sensor_inputs.hpp"

namespace keyplace::ros1 {
namespace {

class RelocalizeNode {
 public:
  RelocalizeNode(ros::NodeHandle& node, ros::NodeHandle& private_node, const GlobalMap& map,
                 const Config& config)
      : core_(map, config),
        inputs_(node, core_.config(),
                {[this](const OdometryInput& odometry) { Publish(core_.AddOdometry(odometry)); },
                 [this](const ScanInput& scan) { Publish(core_.AddScan(scan)); },
                 [this](double now_s) { Publish(core_.Tick(now_s)); }}) {
    initial_pose_publisher_ =
        node.advertise<geometry_msgs::PoseWithCovarianceStamped>("initialpose", 5);
    diagnostics_publisher_ = node.advertise<diagnostic_msgs::DiagnosticArray>("diagnostics", 10);
    relocalize_service_ =
        private_node.advertiseService("relocalize", &RelocalizeNode::OnRelocalize, this);
    save_status_service_ =
        private_node.advertiseService("save_status", &RelocalizeNode::OnSaveStatus, this);
    ROS_INFO("keyplace: relocalizing on %s; publishing %s", inputs_.Description().c_str(),
             PublishText(config.node.publish));
  }

  ~RelocalizeNode() {
    const NodeStatus status = core_.status();
    ROS_INFO(
        "keyplace: %zu scans received, %zu processed, %zu dropped, %zu waiting; per scan %.1f ms "
        "mean, %.1f ms p99, %.1f ms max; %lld searches of the whole map in the background, %.1f "
        "ms each",
        status.scans_received, status.scans_processed, status.scans_dropped, status.scans_waiting,
        1e3 * status.latency_mean_s, 1e3 * status.latency_p99_s, 1e3 * status.latency_max_s,
        status.map_searches, 1e3 * status.map_search_mean_s);
  }

 private:
  static const char* PublishText(NodePublish publish) {
    switch (publish) {
      case NodePublish::kInitialPose:
        return "/initialpose on each new fix";
      case NodePublish::kMapToOdom:
        return "map -> odom while fixed";
      case NodePublish::kBoth:
        return "/initialpose on each new fix and map -> odom while fixed";
    }
    return "?";
  }

  bool OnRelocalize(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
    Publish(core_.Relocalize());
    response.success = true;
    response.message = "searching";
    return true;
  }

  bool OnSaveStatus(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
    const std::string& path = core_.config().node.status_path;
    try {
      core_.SaveStatus(path);
      response.success = true;
      response.message = path;
    } catch (const std::exception& error) {
      response.success = false;
      response.message = error.what();
      ROS_ERROR("keyplace: ~save_status: %s", error.what());
    }
    return true;
  }

  void Publish(const NodeOutput& output) {
    LogEvents(output.events);
    for (const StampedInitialPose& fix : output.initial_poses) PublishInitialPose(fix);
    for (const StampedTransform& transform : output.transforms) inputs_.Broadcast(transform);
    if (output.status_due) PublishStatus();
  }

  void PublishInitialPose(const StampedInitialPose& fix) {
    geometry_msgs::PoseWithCovarianceStamped message;
    message.header.stamp.fromSec(fix.stamp_s);
    message.header.frame_id = fix.pose.frame_id;
    message.pose.pose.position.x = fix.pose.T_map_robot.x;
    message.pose.pose.position.y = fix.pose.T_map_robot.y;
    message.pose.pose.orientation = QuaternionOf(fix.pose.T_map_robot.theta);
    const std::array<double, 36> covariance = InitialPoseCovariance(fix.pose);
    std::copy(covariance.begin(), covariance.end(), message.pose.covariance.begin());
    initial_pose_publisher_.publish(message);
  }

  void PublishStatus() {
    const NodeStatus status = core_.status();
    diagnostic_msgs::DiagnosticStatus diagnostic;
    diagnostic.name = ros::this_node::getName() + ": relocalization";
    diagnostic.hardware_id = "keyplace";
    diagnostic.level = status.status == FixStatus::kFixed ? diagnostic_msgs::DiagnosticStatus::OK
                                                          : diagnostic_msgs::DiagnosticStatus::WARN;
    diagnostic.message = ToString(status.status);
    const auto value = [&](const std::string& key, const std::string& text) {
      AddDiagnosticValue(key, text, diagnostic);
    };
    value("status", ToString(status.status));
    value("confidence", DiagnosticNumber(status.confidence));
    if (status.pose) {
      value("x", DiagnosticNumber(status.pose->T_map_robot.x));
      value("y", DiagnosticNumber(status.pose->T_map_robot.y));
      value("theta", DiagnosticNumber(status.pose->T_map_robot.theta));
    }
    if (status.last_answer) {
      const NodeAnswer& answer = *status.last_answer;
      value("last_answer_stamp", DiagnosticNumber(answer.stamp_s));
      value("last_answer", answer.found ? "found" : answer.ambiguous ? "ambiguous" : "not found");
      value("last_answer_confidence", DiagnosticNumber(answer.confidence));
      value("last_answer_source", answer.map_search ? "map search" : "keypoints");
    }
    value("scans_received", std::to_string(status.scans_received));
    value("scans_processed", std::to_string(status.scans_processed));
    value("scans_dropped", std::to_string(status.scans_dropped));
    value("scans_waiting", std::to_string(status.scans_waiting));
    value("odometry_dropped", std::to_string(status.odometry_dropped));
    value("answers", std::to_string(status.answers));
    value("fixes", std::to_string(status.fixes));
    value("losses", std::to_string(status.losses));
    value("last_scan_stamp", DiagnosticNumber(status.last_scan_stamp_s));
    value("latency_mean_s", DiagnosticNumber(status.latency_mean_s));
    value("latency_p99_s", DiagnosticNumber(status.latency_p99_s));
    value("latency_max_s", DiagnosticNumber(status.latency_max_s));
    value("map_searches", std::to_string(status.map_searches));
    value("map_search_mean_s", DiagnosticNumber(status.map_search_mean_s));
    diagnostic_msgs::DiagnosticArray array;
    array.header.stamp = ros::Time::now();
    array.status.push_back(diagnostic);
    diagnostics_publisher_.publish(array);
  }

  RelocalizationNode core_;
  SensorInputs inputs_;
  ros::Publisher initial_pose_publisher_;
  ros::Publisher diagnostics_publisher_;
  ros::ServiceServer relocalize_service_;
  ros::ServiceServer save_status_service_;
};

}  // namespace
}  // namespace keyplace::ros1

int main(int argc, char** argv) {
  ros::init(argc, argv, "keyplace_relocalize");
  ros::NodeHandle node;
  ros::NodeHandle private_node("~");
  std::unique_ptr<keyplace::ros1::RelocalizeNode> relocalize;
  try {
    // A robot program relocalizes with the strict preset (docs/LOCALIZATION.md).
    const keyplace::Config config = keyplace::ros1::ConfigFromParameters(private_node, "strict");
    const std::string map_path = keyplace::ros1::RequiredParameter(private_node, "map");
    const keyplace::GlobalMap map = keyplace::LoadMap(map_path);
    ROS_INFO("keyplace: map %s: %zu submaps", map_path.c_str(), map.submaps.size());
    relocalize = std::make_unique<keyplace::ros1::RelocalizeNode>(node, private_node, map, config);
  } catch (const std::exception& error) {
    ROS_FATAL("keyplace: %s", error.what());
    return 2;
  }
  ros::spin();
  relocalize.reset();
  return 0;
}
