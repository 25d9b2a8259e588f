#pragma once
// What keyplace's robot nodes publish and how long they wait: config section `node`
// (RelocalizationNode and SlamNode, the ROS nodes keyplace_ros_relocalize and keyplace_ros_slam;
// docs/ROS.md, "On a robot").

#include <string>

namespace keyplace {

/// What goes out when the node has a fix.
enum class NodePublish {
  kInitialPose,  // /initialpose on every new fix (the first one, each one after a loss)
  kMapToOdom,    // the map -> odom transform with every scan while fixed
  kBoth,
};

/// Where the robot's odometry pose comes from.
enum class NodeOdometry {
  kTopic,  // nav_msgs/Odometry messages on input.odom_topic
  kTf,     // the tf chain input.odom_frame -> input.base_frame at each scan's stamp
};

struct NodeConfig {
  NodePublish publish = NodePublish::kInitialPose;
  NodeOdometry odometry = NodeOdometry::kTopic;
  // The map's frame: the frame of the fixes and the parent of map -> odom. The odometry and
  // robot frames are input.odom_frame and input.base_frame.
  std::string map_frame = "map";
  // A scan waits for an odometry pose at or after its stamp until a scan this much newer (stamps'
  // time) comes, and is dropped then (a scan before the first odometry pose is dropped at once). 1
  // s is where the bag readers call an odometry gap a guess (docs/ROS.md); drivers publish odometry
  // at 10-100 Hz. A bag played at N times real time needs N times more: the messages of two topics
  // reach the node in any order within the same wall time.
  double odometry_wait_s = 1.0;
  // The status (and, when fixed, map -> odom) goes out at least this often (stamps' time), so a
  // monitor sees a node that gets no scans.
  double status_period_s = 1.0;
  // Where ~save_status writes the status (YAML); relative paths are the node's working directory.
  std::string status_path = "keyplace_status.yaml";
  // SLAM node: the occupancy grid of the scans at their current poses goes out on /map at most
  // this often (stamps' time), when scans came since the last one. It is rebuilt from all
  // keyframes each time, as a loop closure moves them all.
  double map_period_s = 5.0;
  // SLAM node: where ~save_map writes the map (.kpm); the map_server grid goes beside it, the
  // same path with .yaml and .pgm. Relative paths are the node's working directory.
  std::string map_path = "keyplace_map.kpm";
};

/// Throws std::invalid_argument naming the first invalid field (NodeConfig.<field>).
void Validate(const NodeConfig& config);

}  // namespace keyplace
