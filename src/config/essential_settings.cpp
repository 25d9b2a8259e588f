// The essential settings (docs/README.md, "Configuration": why these).

#include "keyplace/config/essential_settings.hpp"

#include <algorithm>
#include <string>
#include <vector>

namespace keyplace {

const std::vector<std::string>& EssentialConfigKeys() {
  // What a user must match to a robot and a building; the rest has defaults measured on the
  // development logs and rarely needs a change.
  static const std::vector<std::string> keys = {
      // A ROS bag's topics and frames, and where the laser sits when tf does not say.
      "input.scan_topic", "input.odom_topic", "input.base_frame", "input.laser_pose",
      // The laser's usable range (a 5.6 m Hokuyo URG against a 30 m SICK).
      "odometry.min_range_m", "odometry.max_range_m",
      // How large a submap may grow, and how stable a keypoint must be to stay in it.
      "mapping.min_stability", "mapping.max_path_m",
      // How sure an answer and a fix must be.
      "place.min_reference_coverage", "place.min_confidence", "localization.fix.confirmations",
      "localization.fix.lost_after_m",
      // The occupancy grid's cell.
      "grid.resolution_m",
      // What the robot node publishes, where its odometry comes from, the map's frame.
      "node.publish", "node.odometry", "node.map_frame"};
  return keys;
}

bool IsEssentialConfigKey(const std::string& key) {
  const std::vector<std::string>& keys = EssentialConfigKeys();
  return std::find(keys.begin(), keys.end(), key) != keys.end();
}

}  // namespace keyplace
