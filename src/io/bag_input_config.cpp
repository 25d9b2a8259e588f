#include "keyplace/io/bag_input_config.hpp"

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "io/io_fields.hpp"

namespace keyplace {

std::optional<Pose2> ParseLaserPose(const std::string& text) {
  if (text.empty()) return std::nullopt;
  std::vector<double> values;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const char* begin = text.data() + start;
    const char* end = text.data() + comma;
    if (begin != end && *begin == '+') ++begin;
    double value = 0.0;
    const auto result = std::from_chars(begin, end, value);
    if (begin == end || result.ec != std::errc() || result.ptr != end || !std::isfinite(value)) {
      throw std::invalid_argument("laser pose '" + text +
                                  "' is not x,y,theta (three finite numbers: m, m, rad)");
    }
    values.push_back(value);
    start = comma + 1;
  }
  if (values.size() != 3) {
    throw std::invalid_argument("laser pose '" + text + "' is not x,y,theta (three numbers: m, " +
                                "m, rad), it has " + std::to_string(values.size()));
  }
  return Pose2(values[0], values[1], values[2]);
}

void Validate(const BagInputConfig& config) {
  const std::pair<const char*, const std::string*> names[] = {{"scan_topic", &config.scan_topic},
                                                              {"odom_topic", &config.odom_topic},
                                                              {"odom_frame", &config.odom_frame},
                                                              {"base_frame", &config.base_frame}};
  for (const auto& [name, value] : names) {
    if (value->empty())
      throw std::invalid_argument(std::string("BagInputConfig.") + name + " is empty");
  }
  try {
    ParseLaserPose(config.laser_pose);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(std::string("BagInputConfig.laser_pose: ") + error.what());
  }
  if (!(config.scan_fov_rad >= 0.0 && config.scan_fov_rad <= 2.0 * M_PI)) {
    throw std::invalid_argument("BagInputConfig.scan_fov_rad must lie in [0, 2 pi]");
  }
}

const ConfigFields<BagInputConfig>& BagInputConfigFields() {
  using C = BagInputConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("BagInputConfig");
    table.Text("scan_topic", &C::scan_topic, "", "ROS bags: sensor_msgs/LaserScan topic")
        .Text("odom_topic", &C::odom_topic, "",
              "ROS bags: nav_msgs/Odometry topic; without it, odometry from /tf")
        .Text("odom_frame", &C::odom_frame, "", "ROS bags: odometry frame of the /tf chain")
        .Text("base_frame", &C::base_frame, "", "ROS bags: robot frame (odometry, laser pose)")
        .Text("laser_pose", &C::laser_pose, "m,m,rad",
              "ROS bags: laser on the robot x,y,theta; empty: from /tf_static or /tf")
        .Double("scan_fov_rad", &C::scan_fov_rad, "rad",
                "ROS bags: > 0 spreads beams over this as CARMEN FLASER (start -fov/2, step "
                "fov/n, or fov/(n-1) for an odd n); 0: angles from the messages");
    return table;
  }();
  return fields;
}

}  // namespace keyplace
