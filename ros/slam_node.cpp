// keyplace_ros_slam: the SlamNode on ROS 1. Scans and odometry (a topic or the tf chain) in;
// map -> odom on tf, the occupancy grid on /map (latched) and the status on /diagnostics out;
// service ~save_map writes the .kpm and the map_server grid. Everything it decides comes from the
// library's node core; this file only converts messages (docs/ROS.md, "On a robot").

#include <exception>
#include <memory>
#include <string>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include "keyplace/slam/slam_node.hpp"
#include "node_messages.hpp"
#include "ros_support.hpp"
#include "sensor_inputs.hpp"

namespace keyplace::ros1 {
namespace {

// nav_msgs/OccupancyGrid's cell values: occupancy in percent, -1 unknown.
constexpr std::int8_t kGridOccupied = 100;
constexpr std::int8_t kGridFree = 0;
constexpr std::int8_t kGridUnknown = -1;

nav_msgs::OccupancyGrid GridMessageOf(const StampedGrid& stamped,
                                      const OccupancyGridConfig& config) {
  const OccupancyGrid& grid = stamped.grid;
  nav_msgs::OccupancyGrid message;
  message.header.stamp.fromSec(stamped.stamp_s);
  message.header.frame_id = stamped.frame_id;
  message.info.map_load_time = message.header.stamp;
  message.info.resolution = static_cast<float>(grid.resolution_m);
  message.info.width = static_cast<std::uint32_t>(grid.width);
  message.info.height = static_cast<std::uint32_t>(grid.height);
  message.info.origin.position.x = grid.origin_m.x();
  message.info.origin.position.y = grid.origin_m.y();
  message.info.origin.orientation.w = 1.0;
  // Both row-major from the row at origin.y up, as map_server publishes a map.
  message.data.resize(static_cast<std::size_t>(grid.width) * static_cast<std::size_t>(grid.height));
  for (int row = 0; row < grid.height; ++row) {
    for (int column = 0; column < grid.width; ++column) {
      const CellState state = grid.State(column, row, config);
      message.data[grid.Index(column, row)] = state == CellState::kOccupied ? kGridOccupied
                                              : state == CellState::kFree   ? kGridFree
                                                                            : kGridUnknown;
    }
  }
  return message;
}

class SlamRosNode {
 public:
  SlamRosNode(ros::NodeHandle& node, ros::NodeHandle& private_node, const Config& config)
      : core_(config),
        inputs_(node, core_.config(),
                {[this](const OdometryInput& odometry) { Publish(core_.AddOdometry(odometry)); },
                 [this](const ScanInput& scan) { Publish(core_.AddScan(scan)); },
                 [this](double now_s) { Publish(core_.Tick(now_s)); }}) {
    map_publisher_ = node.advertise<nav_msgs::OccupancyGrid>("map", 1, /*latch=*/true);
    diagnostics_publisher_ = node.advertise<diagnostic_msgs::DiagnosticArray>("diagnostics", 10);
    save_map_service_ = private_node.advertiseService("save_map", &SlamRosNode::OnSaveMap, this);
    ROS_INFO("keyplace: SLAM on %s; /map every %.1f s, ~save_map to %s",
             inputs_.Description().c_str(), config.node.map_period_s, config.node.map_path.c_str());
  }

  ~SlamRosNode() {
    const SlamNodeStatus status = core_.status();
    ROS_INFO(
        "keyplace: %zu scans received, %zu processed, %zu dropped, %zu waiting; %zu submaps, %zu "
        "loops used; per scan %.1f ms mean, %.1f ms p99, %.1f ms max",
        status.scans_received, status.scans_processed, status.scans_dropped, status.scans_waiting,
        status.submaps, status.loops_used, 1e3 * status.latency_mean_s, 1e3 * status.latency_p99_s,
        1e3 * status.latency_max_s);
  }

 private:
  bool OnSaveMap(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
    try {
      const SavedSlamMap saved = core_.SaveMap(core_.config().node.map_path);
      response.success = true;
      response.message = saved.map_path + " " + saved.grid_path;
      ROS_INFO("keyplace: ~save_map: %s (%zu submaps, %zu scans) and %s", saved.map_path.c_str(),
               saved.submaps, saved.scans, saved.grid_path.c_str());
    } catch (const std::exception& error) {
      response.success = false;
      response.message = error.what();
      ROS_ERROR("keyplace: ~save_map: %s", error.what());
    }
    return true;
  }

  void Publish(const SlamNodeOutput& output) {
    LogEvents(output.events);
    for (const StampedTransform& transform : output.transforms) inputs_.Broadcast(transform);
    if (output.map) map_publisher_.publish(GridMessageOf(*output.map, core_.config().grid));
    if (output.status_due) PublishStatus();
  }

  void PublishStatus() {
    const SlamNodeStatus status = core_.status();
    diagnostic_msgs::DiagnosticStatus diagnostic;
    diagnostic.name = ros::this_node::getName() + ": slam";
    diagnostic.hardware_id = "keyplace";
    const bool mapping = status.scans_processed > 0;
    diagnostic.level =
        mapping ? diagnostic_msgs::DiagnosticStatus::OK : diagnostic_msgs::DiagnosticStatus::WARN;
    diagnostic.message = mapping ? "mapping" : "waiting for scans and odometry";
    const auto value = [&](const std::string& key, const std::string& text) {
      AddDiagnosticValue(key, text, diagnostic);
    };
    value("x", DiagnosticNumber(status.T_map_robot.x));
    value("y", DiagnosticNumber(status.T_map_robot.y));
    value("theta", DiagnosticNumber(status.T_map_robot.theta));
    value("submaps", std::to_string(status.submaps));
    value("loops_used", std::to_string(status.loops_used));
    value("maps_published", std::to_string(status.maps_published));
    value("scans_received", std::to_string(status.scans_received));
    value("scans_processed", std::to_string(status.scans_processed));
    value("scans_dropped", std::to_string(status.scans_dropped));
    value("scans_waiting", std::to_string(status.scans_waiting));
    value("odometry_dropped", std::to_string(status.odometry_dropped));
    value("odometry_jumps", std::to_string(status.odometry_jumps));
    value("last_scan_stamp", DiagnosticNumber(status.last_scan_stamp_s));
    value("latency_mean_s", DiagnosticNumber(status.latency_mean_s));
    value("latency_p99_s", DiagnosticNumber(status.latency_p99_s));
    value("latency_max_s", DiagnosticNumber(status.latency_max_s));
    value("last_map_seconds", DiagnosticNumber(status.last_map_seconds));
    diagnostic_msgs::DiagnosticArray array;
    array.header.stamp = ros::Time::now();
    array.status.push_back(diagnostic);
    diagnostics_publisher_.publish(array);
  }

  SlamNode core_;
  SensorInputs inputs_;
  ros::Publisher map_publisher_;
  ros::Publisher diagnostics_publisher_;
  ros::ServiceServer save_map_service_;
};

}  // namespace
}  // namespace keyplace::ros1

int main(int argc, char** argv) {
  ros::init(argc, argv, "keyplace_slam");
  ros::NodeHandle node;
  ros::NodeHandle private_node("~");
  std::unique_ptr<keyplace::ros1::SlamRosNode> slam;
  try {
    const keyplace::Config config = keyplace::ros1::ConfigFromParameters(private_node, "default");
    slam = std::make_unique<keyplace::ros1::SlamRosNode>(node, private_node, config);
  } catch (const std::exception& error) {
    ROS_FATAL("keyplace: %s", error.what());
    return 2;
  }
  ros::spin();
  slam.reset();
  return 0;
}
