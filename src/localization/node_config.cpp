#include "keyplace/localization/node_config.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "localization/localization_fields.hpp"

namespace keyplace {
namespace {

// What InitialPoseYaml takes as a frame id: letters, digits, '_', '/', '.', '-'; not empty.
bool IsFrameName(const std::string& name) {
  if (name.empty()) return false;
  for (const char c : name) {
    const bool allowed = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                         (c >= '0' && c <= '9') || c == '_' || c == '/' || c == '.' || c == '-';
    if (!allowed) return false;
  }
  return true;
}

}  // namespace

void Validate(const NodeConfig& config) {
  const auto fail = [](const std::string& message) {
    throw std::invalid_argument("NodeConfig." + message);
  };
  if (!IsFrameName(config.map_frame)) {
    fail("map_frame '" + config.map_frame + "' is not a frame name (letters, digits, _ / . -)");
  }
  if (!(config.odometry_wait_s > 0.0 && config.odometry_wait_s <= 60.0)) {
    fail("odometry_wait_s must be in (0, 60] s");
  }
  if (!(config.status_period_s > 0.0 && config.status_period_s <= 3600.0)) {
    fail("status_period_s must be in (0, 3600] s");
  }
  if (config.status_path.empty()) fail("status_path must not be empty");
  if (!(config.map_period_s > 0.0 && config.map_period_s <= 3600.0)) {
    fail("map_period_s must be in (0, 3600] s");
  }
  if (config.map_path.empty()) fail("map_path must not be empty");
  // The grid goes beside the map as .yaml and .pgm: a map of that name would be overwritten.
  for (const char* grid_extension : {".yaml", ".pgm"}) {
    const std::string extension(grid_extension);
    if (config.map_path.size() >= extension.size() &&
        config.map_path.compare(config.map_path.size() - extension.size(), extension.size(),
                                extension) == 0) {
      fail("map_path '" + config.map_path + "' ends in " + extension +
           ": that is where the map_server grid goes (use .kpm)");
    }
  }
}

const ConfigFields<NodeConfig>& NodeConfigFields() {
  using C = NodeConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("NodeConfig");
    table
        .Enum("publish", &C::publish,
              {{NodePublish::kInitialPose, "initialpose"},
               {NodePublish::kMapToOdom, "map_to_odom"},
               {NodePublish::kBoth, "both"}},
              "relocalization node: /initialpose on each new fix, map -> odom while fixed, or both")
        .Enum("odometry", &C::odometry,
              {{NodeOdometry::kTopic, "topic"}, {NodeOdometry::kTf, "tf"}},
              "odometry from input.odom_topic or from tf (input.odom_frame -> input.base_frame)")
        .Text("map_frame", &C::map_frame, "", "frame of the map, the fixes and map -> odom")
        .Double("odometry_wait_s", &C::odometry_wait_s, "s",
                "a scan waits for odometry at its stamp until a scan this much newer comes")
        .Double("status_period_s", &C::status_period_s, "s",
                "the status (and map -> odom when fixed) goes out at least this often")
        .Text("status_path", &C::status_path, "", "file ~save_status writes (YAML)")
        .Double("map_period_s", &C::map_period_s, "s",
                "SLAM node: /map goes out at most this often while scans come")
        .Text("map_path", &C::map_path, "",
              "SLAM node: map ~save_map writes (.kpm; the map_server grid beside it, .yaml/.pgm)");
    return table;
  }();
  return fields;
}

}  // namespace keyplace
