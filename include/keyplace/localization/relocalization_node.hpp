#pragma once
// The Relocalizer as a robot node runs it, without a middleware: laser scans and odometry come in
// as plain structs (the fields of sensor_msgs/LaserScan and nav_msgs/Odometry), the node decides
// what to publish and when, and everything a ROS 1 or ROS 2 wrapper sends out comes back as data
// (the /initialpose message, the map -> odom transform, the status, events to log). Nothing here
// throws on what a sensor or a bag sends: an empty scan, NaN ranges, too many beams, a stamp that
// goes back, an odometry jump, a scan geometry that changes, a scan without odometry all become
// events, and the node goes on (docs/ROS.md, "On a robot").
//
//   keyplace::RelocalizationNode node(keyplace::LoadMap("site.kpm"), config);
//   on odometry:  Publish(node.AddOdometry({stamp_s, T_odom_robot}));
//   on a scan:    Publish(node.AddScan(scan));
//   on a timer:   Publish(node.Tick(now_s));
//   ~relocalize:  Publish(node.Relocalize());

#include <cstddef>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/config/config.hpp"
#include "keyplace/io/sensor_input.hpp"
#include "keyplace/io/sensor_sync.hpp"
#include "keyplace/localization/initial_pose.hpp"
#include "keyplace/localization/relocalizer.hpp"
#include "keyplace/mapping/global_map.hpp"

namespace keyplace {

/// /initialpose: the fix with the stamp of the scan it was declared at.
struct StampedInitialPose {
  double stamp_s = 0.0;
  InitialPose pose;
};

/// The localizer's latest answer (a query submap completed).
struct NodeAnswer {
  double stamp_s = 0.0;  // of the scan that completed the query
  bool found = false;
  bool ambiguous = false;
  double confidence = 0.0;
  int submap_id = -1;       // -1 for an answer of a search of the whole map
  bool map_search = false;  // the answer came from a search of the whole map
  Pose2 T_world_robot;      // valid when a candidate was verified
};

/// What the node reports as its status (a ROS DiagnosticArray, ~save_status).
struct NodeStatus {
  FixStatus status = FixStatus::kSearching;
  double confidence = 0.0;  // of the fix; 0 without one
  Pose2 T_world_odom;       // valid when fixed: map <- odom
  // When fixed: the robot's pose at the last processed scan with its covariance (what
  // /initialpose would carry now).
  std::optional<InitialPose> pose;
  double unconfirmed_m = 0.0;
  std::optional<NodeAnswer> last_answer;
  double last_scan_stamp_s = 0.0;  // of the last processed scan (0: none yet)
  std::size_t scans_received = 0;
  std::size_t scans_processed = 0;
  std::size_t scans_dropped = 0;
  // Accepted and waiting for odometry at their stamp: received = processed + dropped + waiting.
  std::size_t scans_waiting = 0;
  std::size_t odometry_dropped = 0;
  std::size_t answers = 0;
  std::size_t fixes = 0;   // fixes declared (first ones and new ones after a loss)
  std::size_t losses = 0;  // fixes given up
  // Searches of the whole map that ran to their end (on a thread of their own while there is no
  // fix; one stopped by a fix or ~relocalize is not counted) and their mean time.
  long long map_searches = 0;
  double map_search_mean_s = 0.0;
  // CPU time of processing one scan (keypoints, query, recognition): mean, 99th percentile and
  // maximum over the last kLatencyWindow processed scans.
  double latency_mean_s = 0.0;
  double latency_p99_s = 0.0;
  double latency_max_s = 0.0;
};

/// One processed scan.
struct ProcessedScan {
  double stamp_s = 0.0;
  double latency_s = 0.0;  // CPU time the node spent on it
  FixStatus status = FixStatus::kSearching;
  bool answered = false;  // an answer came with it (a query's or a search's)
};

/// What to publish after one call, in this order.
struct NodeOutput {
  std::vector<ProcessedScan> scans;
  std::vector<StampedInitialPose> initial_poses;  // on /initialpose
  std::vector<StampedTransform> transforms;       // map -> odom on tf
  bool status_due = false;                        // publish status() now
  std::vector<NodeEvent> events;
};

class RelocalizationNode {
 public:
  /// Scans processed scans the latency figures of NodeStatus cover.
  static constexpr std::size_t kLatencyWindow = 10000;

  /// The localizer of `config` (localization, place, features; its input section says where
  /// the laser sits and how beams are spread, its node section what is published). Throws
  /// std::invalid_argument naming the field for an invalid config.
  RelocalizationNode(const GlobalMap& map, const Config& config);

  /// The next odometry pose; a scan waiting for odometry at its stamp may be processed now.
  NodeOutput AddOdometry(const OdometryInput& odometry);
  /// The next scan: processed as soon as odometry covers its stamp; dropped when a later scan
  /// comes node.odometry_wait_s after it and its odometry has not.
  NodeOutput AddScan(const ScanInput& scan);
  /// The clock (the wrapper's time, in the stamps' time base): republishes map -> odom and the
  /// status every node.status_period_s.
  NodeOutput Tick(double now_s);
  /// Forgets the fix and the query being built and searches again (the ~relocalize service).
  NodeOutput Relocalize();

  /// The status now (the latency figures are computed here).
  NodeStatus status() const;
  const Config& config() const { return config_; }

  /// The status as YAML (what ~save_status writes).
  std::string StatusYaml() const;
  /// Writes StatusYaml() to `path` atomically; throws std::runtime_error naming the path.
  void SaveStatus(const std::string& path) const;

 private:
  void Release(const SyncOutput& synced, NodeOutput& output);
  void Process(const LaserScan& scan, const Pose2& T_odom_robot, NodeOutput& output);
  void Publish(const RelocalizationUpdate& update, double stamp_s, NodeOutput& output);
  // The status every node.status_period_s; map -> odom when the wrapper's clock finds none sent
  // for as long (scans send theirs; not at a message's stamp: tf refuses a second transform at a
  // stamp it has, and a scan's odometry comes at the scan's stamp, just before it).
  void RepublishIfDue(double now_s, bool clock, NodeOutput& output);
  void Drop(const std::string& why, NodeOutput& output);

  Config config_;
  Relocalizer relocalizer_;
  SensorSync sync_;
  NodeStatus status_;
  std::size_t scans_failed_ = 0;            // released scans the localizer could not take
  std::optional<Pose2> last_T_odom_robot_;  // of the last processed scan
  std::optional<double> last_status_s_;     // when the status was last due
  std::optional<double> last_transform_s_;  // stamp of the last map -> odom sent
  std::deque<double> latencies_s_;
};

}  // namespace keyplace
