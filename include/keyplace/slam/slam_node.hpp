#pragma once
// Online SLAM as a robot node runs it, without a middleware: laser scans and odometry come in as
// plain structs (io/sensor_input.hpp), OnlineSlam maps, and what a ROS 1 or ROS 2 wrapper sends
// out comes back as data: the map -> odom transform with every scan, the occupancy grid for /map
// every node.map_period_s, the status, events to log. ~save_map is SaveMap. Nothing a sensor or a
// bag sends throws (SensorSync); an odometry jump no robot can make is absorbed, not mapped
// (docs/ROS.md, "On a robot").
//
//   keyplace::SlamNode node(config);
//   on odometry:  Publish(node.AddOdometry({stamp_s, T_odom_robot}));
//   on a scan:    Publish(node.AddScan(scan));
//   on a timer:   Publish(node.Tick(now_s));
//   ~save_map:    node.SaveMap(config.node.map_path);

#include <cmath>
#include <cstddef>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/config/config.hpp"
#include "keyplace/io/laser_scan.hpp"
#include "keyplace/io/sensor_input.hpp"
#include "keyplace/io/sensor_sync.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/mapping/occupancy_grid.hpp"
#include "keyplace/slam/online_slam.hpp"

namespace keyplace {

/// The occupancy grid to publish on /map.
struct StampedGrid {
  double stamp_s = 0.0;  // when it went out (the clock or the message that made it due)
  std::string frame_id;  // node.map_frame
  OccupancyGrid grid;
};

/// What the SLAM node reports as its status (a ROS DiagnosticArray).
struct SlamNodeStatus {
  std::size_t scans_received = 0;
  std::size_t scans_processed = 0;
  // Refused by SensorSync, or a scan SLAM could not take.
  std::size_t scans_dropped = 0;
  std::size_t scans_waiting = 0;  // accepted, waiting for odometry at their stamp
  std::size_t odometry_dropped = 0;
  std::size_t odometry_jumps = 0;  // steps no robot makes between two scans, absorbed
  std::size_t submaps = 0;
  std::size_t loops_used = 0;  // accepted loops whose edges are enabled in the graph now
  std::size_t maps_published = 0;
  double last_scan_stamp_s = 0.0;  // 0: none yet
  Pose2 T_map_robot;               // at the last processed scan
  Pose2 T_map_odom;
  // CPU time of processing one scan (keypoints, odometry, mapping, loop search, optimisation):
  // mean, 99th percentile and maximum over the last kLatencyWindow processed scans.
  double latency_mean_s = 0.0;
  double latency_p99_s = 0.0;
  double latency_max_s = 0.0;
  double last_map_seconds = 0.0;  // CPU time of the last /map grid
};

/// What to publish after one call, in this order.
struct SlamNodeOutput {
  std::vector<StampedTransform> transforms;  // map -> odom on tf
  std::optional<StampedGrid> map;            // on /map
  bool status_due = false;                   // publish status() now
  std::vector<NodeEvent> events;
};

/// What SaveMap wrote.
struct SavedSlamMap {
  std::string map_path;   // the .kpm
  std::string grid_path;  // the map_server YAML (its image beside it)
  std::size_t submaps = 0;
  std::size_t scans = 0;
};

class SlamNode {
 public:
  static constexpr std::size_t kLatencyWindow = 10000;
  // A step of the odometry between two scans longer than kMaxStepM + kMaxSpeedMps * dt, or a turn
  // larger than kMaxTurnRad + kMaxTurnRateRadps * dt, is a reset or a glitch of the odometry
  // frame, not motion: no ground robot keyplace maps with moves 10 m/s indoors or spins a turn a
  // second (a TurtleBot's limit is 2.84 rad/s), and the constant terms cover a scan that waits
  // long for its odometry.
  static constexpr double kMaxSpeedMps = 10.0;
  static constexpr double kMaxStepM = 1.0;
  static constexpr double kMaxTurnRateRadps = 2.0 * M_PI;
  static constexpr double kMaxTurnRad = 0.5;

  /// SLAM with `config` (odometry, mapping, place, slam, features; input says where the laser
  /// sits, node what is published and grid how /map is drawn). Throws std::invalid_argument
  /// naming the field for an invalid config.
  explicit SlamNode(const Config& config);

  SlamNodeOutput AddOdometry(const OdometryInput& odometry);
  SlamNodeOutput AddScan(const ScanInput& scan);
  /// The clock (stamps' time base): map -> odom and the status every node.status_period_s, /map
  /// when due.
  SlamNodeOutput Tick(double now_s);

  /// The grid of the keyframe scans at their current poses (the scans the front end added to its
  /// local map: enough for the map, a fraction of the cost). Throws std::invalid_argument before
  /// the first scan or when the grid would exceed grid.max_cells.
  OccupancyGrid Grid() const;
  /// The map so far (loops optimised), with the configuration that made it.
  GlobalMap Map() const;
  /// Optimises the loops not optimised yet, then writes Map() to `map_path` (.kpm) and Grid() as a
  /// map_server map beside it (.yaml, .pgm), each atomically. Throws std::invalid_argument before
  /// the first submap completes, std::runtime_error naming a file that cannot be written.
  SavedSlamMap SaveMap(const std::string& map_path);

  SlamNodeStatus status() const;
  const Config& config() const { return config_; }

 private:
  void Release(SyncOutput&& synced, SlamNodeOutput& output);
  void Process(SyncedScan& synced, SlamNodeOutput& output);
  // The odometry pose SLAM is given: `T_odom_robot` with the jumps absorbed so far.
  Pose2 ContinuousOdometry(const SyncedScan& synced, SlamNodeOutput& output);
  // The status every node.status_period_s; map -> odom when the wrapper's clock finds none sent
  // for as long (scans send theirs; not at a message's stamp: tf refuses a second transform at a
  // stamp it has, and a scan's odometry comes at the scan's stamp, just before it).
  void PublishIfDue(double now_s, bool clock, SlamNodeOutput& output);

  Config config_;
  OnlineSlam slam_;
  SensorSync sync_;
  SlamNodeStatus status_;
  std::vector<LaserScan> keyframes_;   // the scans the grid is drawn from
  std::vector<int> keyframe_indices_;  // their scan_index in OnlineSlam
  int next_scan_index_ = 0;
  std::optional<Pose2> last_T_odom_robot_;  // as received, at the last scan given to SLAM
  double last_odometry_stamp_s_ = 0.0;      // that scan's stamp
  Pose2 T_continuous_odom_;                 // absorbs the odometry jumps
  std::optional<double> last_status_s_;     // when the status was last due
  std::optional<double> last_map_s_;        // when /map last went out
  std::optional<double> last_transform_s_;  // stamp of the last map -> odom sent
  std::size_t scans_at_last_map_ = 0;
  std::deque<double> latencies_s_;
};

/// The map_server YAML SaveMap writes beside a map: the path with its extension (.kpm) replaced
/// by .yaml.
std::string GridPathOf(const std::string& map_path);

}  // namespace keyplace
