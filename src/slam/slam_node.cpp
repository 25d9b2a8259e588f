#include "keyplace/slam/slam_node.hpp"

#include <chrono>
#include <cmath>
#include <exception>
#include <stdexcept>
#include <utility>

#include "common/fixed_text.hpp"
#include "common/latency_window.hpp"
#include "common/period.hpp"
#include "keyplace/mapping/map_server.hpp"
#include "keyplace/store/map_file.hpp"

namespace keyplace {
namespace {

double CpuSecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

std::string GridPathOf(const std::string& map_path) {
  const std::size_t slash = map_path.find_last_of('/');
  const std::size_t dot = map_path.find_last_of('.');
  const bool has_extension =
      dot != std::string::npos && (slash == std::string::npos || dot > slash);
  return (has_extension ? map_path.substr(0, dot) : map_path) + ".yaml";
}

SlamNode::SlamNode(const Config& config)
    : config_([&] {
        Validate(config);
        return config;
      }()),
      slam_(ToSlamConfig(config_), config_.features),
      sync_(config_.input, config_.node.odometry_wait_s) {}

SlamNodeOutput SlamNode::AddOdometry(const OdometryInput& odometry) {
  SlamNodeOutput output;
  Release(sync_.AddOdometry(odometry), output);
  if (std::isfinite(odometry.stamp_s)) PublishIfDue(odometry.stamp_s, false, output);
  return output;
}

SlamNodeOutput SlamNode::AddScan(const ScanInput& scan) {
  SlamNodeOutput output;
  Release(sync_.AddScan(scan), output);
  if (std::isfinite(scan.stamp_s)) PublishIfDue(scan.stamp_s, false, output);
  return output;
}

SlamNodeOutput SlamNode::Tick(double now_s) {
  SlamNodeOutput output;
  if (std::isfinite(now_s)) PublishIfDue(now_s, true, output);
  return output;
}

void SlamNode::Release(SyncOutput&& synced, SlamNodeOutput& output) {
  output.events.insert(output.events.end(), synced.events.begin(), synced.events.end());
  for (SyncedScan& next : synced.scans) Process(next, output);
}

Pose2 SlamNode::ContinuousOdometry(const SyncedScan& synced, SlamNodeOutput& output) {
  const Pose2& T_odom_robot = synced.T_odom_robot;
  const double stamp_s = synced.scan.timestamp_s;
  if (last_T_odom_robot_) {
    const double dt_s = stamp_s - last_odometry_stamp_s_;
    const Pose2 step = Between(*last_T_odom_robot_, T_odom_robot);
    const double allowed_m = kMaxStepM + kMaxSpeedMps * dt_s;
    const double allowed_rad = kMaxTurnRad + kMaxTurnRateRadps * dt_s;
    if (TranslationNorm(step) > allowed_m || std::abs(step.theta) > allowed_rad) {
      // The robot is taken not to have moved across the jump: SLAM's odometry stays continuous
      // (ICP still measures the true motion), map -> odom follows the new odometry frame.
      ++status_.odometry_jumps;
      output.events.push_back(
          {NodeEventLevel::kWarning,
           "scan at " + StampText(stamp_s) + ": the odometry moved " +
               FixedText(TranslationNorm(step), 3) + " m and turned " +
               FixedText(step.theta * 180.0 / M_PI, 1) + " deg in " + FixedText(dt_s, 3) +
               " s (more than " + FixedText(allowed_m, 3) + " m or " +
               FixedText(allowed_rad * 180.0 / M_PI, 1) +
               " deg): a reset or a glitch of the odometry, not motion; absorbed"});
      T_continuous_odom_ = T_continuous_odom_ * *last_T_odom_robot_ * T_odom_robot.inverse();
    }
  }
  last_T_odom_robot_ = T_odom_robot;
  last_odometry_stamp_s_ = stamp_s;
  return T_continuous_odom_ * T_odom_robot;
}

void SlamNode::Process(SyncedScan& synced, SlamNodeOutput& output) {
  const double stamp_s = synced.scan.timestamp_s;
  const Pose2 T_odom_robot = ContinuousOdometry(synced, output);
  const auto start = std::chrono::steady_clock::now();
  // Unique per call, even for a scan OnlineSlam throws on after recording it.
  const int scan_index = next_scan_index_++;
  SlamStep step;
  try {
    step = slam_.AddScan(scan_index, synced.scan, T_odom_robot);
  } catch (const std::exception& error) {
    ++status_.scans_dropped;
    output.events.push_back(
        {NodeEventLevel::kWarning, "scan at " + StampText(stamp_s) + " dropped: " + error.what()});
    return;
  }
  AddLatency(CpuSecondsSince(start), kLatencyWindow, latencies_s_);
  ++status_.scans_processed;
  status_.last_scan_stamp_s = stamp_s;
  if (step.odometry.keyframe || keyframes_.empty()) {
    keyframes_.push_back(std::move(synced.scan));
    keyframe_indices_.push_back(scan_index);
  }
  if (step.submap_completed) {
    status_.submaps = slam_.map().submaps.size();
    output.status_due = true;
  }
  if (step.loop >= 0 && slam_.loops()[static_cast<std::size_t>(step.loop)].accepted) {
    const LoopClosure& loop = slam_.loops()[static_cast<std::size_t>(step.loop)];
    output.events.push_back(
        {NodeEventLevel::kInfo, "scan at " + StampText(stamp_s) + ": loop closed between submaps " +
                                    std::to_string(loop.query_submap) + " and " +
                                    std::to_string(loop.reference_submap)});
  }
  status_.T_map_robot = slam_.LatestPose().T_world_robot;
  // map -> odom with the odometry as received, so that tf's odom -> base_link composes to the
  // SLAM pose.
  status_.T_map_odom = status_.T_map_robot * synced.T_odom_robot.inverse();
  output.transforms.push_back(
      {stamp_s, config_.node.map_frame, config_.input.odom_frame, status_.T_map_odom});
  last_transform_s_ = stamp_s;
}

void SlamNode::PublishIfDue(double now_s, bool clock, SlamNodeOutput& output) {
  if (PeriodElapsed(last_status_s_, now_s, config_.node.status_period_s)) {
    last_status_s_ = now_s;
    output.status_due = true;
  }
  if (clock && status_.scans_processed > 0 &&
      PeriodElapsed(last_transform_s_, now_s, config_.node.status_period_s)) {
    output.transforms.push_back(
        {now_s, config_.node.map_frame, config_.input.odom_frame, status_.T_map_odom});
    last_transform_s_ = now_s;
  }
  const bool map_due = PeriodElapsed(last_map_s_, now_s, config_.node.map_period_s);
  if (!map_due || status_.scans_processed == scans_at_last_map_) return;
  last_map_s_ = now_s;
  scans_at_last_map_ = status_.scans_processed;
  const auto start = std::chrono::steady_clock::now();
  try {
    output.map = StampedGrid{now_s, config_.node.map_frame, Grid()};
    ++status_.maps_published;
  } catch (const std::exception& error) {
    output.events.push_back({NodeEventLevel::kError, std::string("/map: ") + error.what()});
  }
  status_.last_map_seconds = CpuSecondsSince(start);
}

OccupancyGrid SlamNode::Grid() const {
  if (keyframes_.empty()) throw std::invalid_argument("no scan processed yet: no grid");
  const std::vector<OnlineSlam::ScanPose> trajectory = slam_.Trajectory();
  std::vector<const LaserScan*> scans;
  std::vector<Pose2> T_world_robot;
  scans.reserve(keyframes_.size());
  T_world_robot.reserve(keyframes_.size());
  // Both in processing order: the keyframes are found by their scan_index in one pass.
  std::size_t k = 0;
  for (const OnlineSlam::ScanPose& pose : trajectory) {
    if (k < keyframes_.size() && pose.scan_index == keyframe_indices_[k]) {
      scans.push_back(&keyframes_[k]);
      T_world_robot.push_back(pose.T_world_robot);
      ++k;
    }
  }
  return BuildOccupancyGrid(scans, T_world_robot, config_.grid);
}

GlobalMap SlamNode::Map() const {
  GlobalMap map = slam_.map();
  map.source_log = "live:" + config_.input.scan_topic;
  map.pose_source = "slam";
  map.configuration = ConfigToYaml(config_);
  return map;
}

SavedSlamMap SlamNode::SaveMap(const std::string& map_path) {
  slam_.Finish();  // loops not optimised yet (deferred, or slam.optimize_every_loops > 1)
  const GlobalMap map = Map();
  if (map.submaps.empty()) {
    throw std::invalid_argument("no submap completed yet (" +
                                std::to_string(status_.scans_processed) +
                                " scans processed): nothing to save");
  }
  // The grid first: one that cannot be made (grid.max_cells) leaves no map file behind either.
  const OccupancyGrid grid = Grid();
  SavedSlamMap saved{map_path, GridPathOf(map_path), map.submaps.size(), status_.scans_processed};
  keyplace::SaveMap(map, map_path);
  WriteMapServerMap(grid, config_.grid, saved.grid_path);
  return saved;
}

SlamNodeStatus SlamNode::status() const {
  SlamNodeStatus status = status_;
  status.scans_received = sync_.scans_received();
  status.scans_dropped = sync_.scans_dropped() + status_.scans_dropped;
  status.scans_waiting = sync_.scans_waiting();
  status.odometry_dropped = sync_.odometry_dropped();
  status.loops_used = 0;
  for (const LoopClosure& loop : slam_.loops()) status.loops_used += slam_.LoopUsed(loop) ? 1 : 0;
  const LatencySummary latency = SummarizeLatencies(latencies_s_);
  status.latency_mean_s = latency.mean_s;
  status.latency_p99_s = latency.p99_s;
  status.latency_max_s = latency.max_s;
  return status;
}

}  // namespace keyplace
