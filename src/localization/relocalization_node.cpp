#include "keyplace/localization/relocalization_node.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <iomanip>
#include <limits>
#include <sstream>
#include <utility>

#include "common/quantile.hpp"
#include "io/atomic_file.hpp"
#include "keyplace/io/bag_input_config.hpp"

namespace keyplace {
namespace {

// An odometry position beyond this is a corrupt message, not a place (the log and bag readers'
// limit, CarmenReadOptions::max_coordinate_m).
constexpr double kMaxCoordinateM = 1e7;

std::string Number(double value, int decimals = 3) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(decimals) << value;
  return text.str();
}

std::string Stamp(double stamp_s) { return Number(stamp_s, 6); }

std::string PoseText(const Pose2& pose) {
  return Number(pose.x) + " m, " + Number(pose.y) + " m, " + Number(pose.theta * 180.0 / M_PI, 1) +
         " deg";
}

// x and y linearly, the heading along the shorter turn (as the bag readers interpolate).
Pose2 Interpolate(const OdometryInput& a, const OdometryInput& b, double stamp_s) {
  const double span_s = b.stamp_s - a.stamp_s;
  const double f = span_s > 0.0 ? (stamp_s - a.stamp_s) / span_s : 0.0;
  const Pose2& p = a.T_odom_robot;
  const Pose2& q = b.T_odom_robot;
  return {p.x + f * (q.x - p.x), p.y + f * (q.y - p.y), p.theta + f * WrapAngle(q.theta - p.theta)};
}

// A scan's geometry as NoteGeometry keeps it: stamp_s holds the beam count.
std::string GeometryText(const ScanInput& geometry) {
  return "frame '" + geometry.frame_id + "', " +
         std::to_string(static_cast<std::size_t>(geometry.stamp_s)) + " beams from " +
         Number(geometry.angle_min_rad, 6) + " rad by " + Number(geometry.angle_increment_rad, 6) +
         " rad, ranges " + Number(geometry.range_min_m) + " to " + Number(geometry.range_max_m) +
         " m, laser at " + PoseText(*geometry.T_robot_laser);
}

// Equal up to what a float32 message or a logged mounting rounds (0.1 mm, 0.1 mrad).
bool SameGeometry(const ScanInput& a, const ScanInput& b) {
  constexpr double kTolerance = 1e-4;
  const auto near = [](double x, double y) { return std::abs(x - y) <= kTolerance; };
  const Pose2& p = *a.T_robot_laser;
  const Pose2& q = *b.T_robot_laser;
  return a.frame_id == b.frame_id && a.stamp_s == b.stamp_s &&
         near(a.angle_min_rad, b.angle_min_rad) &&
         near(a.angle_increment_rad, b.angle_increment_rad) && near(a.range_min_m, b.range_min_m) &&
         near(a.range_max_m, b.range_max_m) && near(p.x, q.x) && near(p.y, q.y) &&
         near(WrapAngle(p.theta - q.theta), 0.0);
}

}  // namespace

RelocalizationNode::RelocalizationNode(const GlobalMap& map, const Config& config)
    : config_([&] {
        Validate(config);
        return config;
      }()),
      relocalizer_(map, ToLocalizerConfig(config_), config_.features),
      laser_pose_override_(ParseLaserPose(config_.input.laser_pose)) {}

NodeOutput RelocalizationNode::AddOdometry(const OdometryInput& odometry) {
  NodeOutput output;
  const Pose2& pose = odometry.T_odom_robot;
  std::string problem;
  if (!std::isfinite(odometry.stamp_s) || !std::isfinite(pose.theta)) {
    problem = "its stamp or heading is not finite";
  } else if (!(std::abs(pose.x) <= kMaxCoordinateM && std::abs(pose.y) <= kMaxCoordinateM)) {
    problem = "its position lies beyond +-1e7 m";
  } else if (!odometry_.empty() && odometry.stamp_s <= odometry_.back().stamp_s) {
    problem = "it is not after the previous one (" + Stamp(odometry_.back().stamp_s) +
              "): out of order or repeated";
  }
  if (!problem.empty()) {
    ++status_.odometry_dropped;
    output.events.push_back({NodeEventLevel::kWarning,
                             "odometry at " + Stamp(odometry.stamp_s) + " dropped: " + problem});
    return output;
  }
  odometry_.push_back(odometry);
  Drain(output);
  // Samples older than the last scan serve no later scan (scans come in stamp order); the last
  // one before it is kept for the interpolation there. Scans may lag the odometry by any time
  // (a busy node, a slow driver), so nothing newer is dropped, up to kMaxOdometrySamples
  // (odometry flowing while no scan comes).
  while (odometry_.size() >= 2 &&
         ((last_scan_stamp_s_ && odometry_[1].stamp_s <= *last_scan_stamp_s_) ||
          odometry_.size() > kMaxOdometrySamples)) {
    odometry_.pop_front();
  }
  RepublishIfDue(odometry.stamp_s, output);
  return output;
}

NodeOutput RelocalizationNode::AddScan(const ScanInput& input) {
  NodeOutput output;
  ++status_.scans_received;
  if (!std::isfinite(input.stamp_s)) {
    Drop("a scan with a stamp that is not finite dropped", output);
    return output;
  }
  const std::string at = "scan at " + Stamp(input.stamp_s);
  if (last_scan_stamp_s_ && input.stamp_s <= *last_scan_stamp_s_) {
    Drop(at + " dropped: not after the previous scan (" + Stamp(*last_scan_stamp_s_) +
             "): out of order or repeated",
         output);
    return output;
  }
  std::optional<LaserScan> scan = Convert(input, output);
  if (!scan) return output;
  last_scan_stamp_s_ = input.stamp_s;
  pending_.push_back({std::move(*scan), input.frame_id});
  Drain(output);
  RepublishIfDue(input.stamp_s, output);
  return output;
}

NodeOutput RelocalizationNode::Tick(double now_s) {
  // No scan is dropped by the clock: a busy wrapper's clock runs ahead of the messages still
  // queued for it, and a scan's odometry may be among them. Waiting scans are dropped by the
  // stamps of later scans (Drain).
  NodeOutput output;
  if (std::isfinite(now_s)) RepublishIfDue(now_s, output);
  return output;
}

NodeOutput RelocalizationNode::Relocalize() {
  NodeOutput output;
  relocalizer_.Reset();
  last_T_odom_robot_.reset();
  status_.status = FixStatus::kSearching;
  status_.confidence = 0.0;
  status_.unconfirmed_m = 0.0;
  status_.pose.reset();
  output.events.push_back({NodeEventLevel::kInfo, "relocalize: fix forgotten, searching again"});
  output.status_due = true;
  return output;
}

std::optional<LaserScan> RelocalizationNode::Convert(const ScanInput& input, NodeOutput& output) {
  const std::string at = "scan at " + Stamp(input.stamp_s) + " dropped: ";
  const std::size_t n = input.ranges_m.size();
  std::string problem;
  if (n == 0) {
    problem = "it has no beams";
  } else if (n > kMaxScanBeams) {
    problem = std::to_string(n) + " beams, more than the " + std::to_string(kMaxScanBeams) +
              " keyplace takes (downsample the scan)";
  } else if (!(input.range_max_m > 0.0 && std::isfinite(input.range_max_m))) {
    problem = "range_max must be positive and finite";
  } else if (config_.input.scan_fov_rad <= 0.0 &&
             !(std::isfinite(input.angle_min_rad) && std::isfinite(input.angle_increment_rad))) {
    problem = "angle_min and angle_increment must be finite";
  }
  const std::optional<Pose2> T_robot_laser =
      laser_pose_override_ ? laser_pose_override_ : input.T_robot_laser;
  if (problem.empty() && !T_robot_laser) {
    problem = "no laser pose for frame '" + input.frame_id + "' (tf " + config_.input.base_frame +
              " -> " + input.frame_id + ", or input.laser_pose)";
  }
  if (!problem.empty()) {
    Drop(at + problem, output);
    return std::nullopt;
  }
  LaserScan scan;
  scan.timestamp_s = input.stamp_s;
  scan.max_range_m = input.range_max_m;
  scan.T_robot_laser = *T_robot_laser;
  const double fov_rad = config_.input.scan_fov_rad;
  const double start_rad = fov_rad > 0.0 ? -0.5 * fov_rad : input.angle_min_rad;
  const double step_rad =
      fov_rad > 0.0 ? fov_rad / static_cast<double>(n) : input.angle_increment_rad;
  scan.ranges_m.resize(n);
  scan.angles_rad.resize(n);
  scan.valid.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const double range_m = input.ranges_m[i];
    scan.ranges_m[i] = range_m;
    scan.angles_rad[i] = start_rad + static_cast<double>(i) * step_rad;
    // The bag readers' rule: NaN, <= 0 or below range_min is invalid; at or beyond range_max
    // (+inf included, REP 117) is no return.
    scan.valid[i] = !std::isnan(range_m) && range_m > 0.0 && range_m >= input.range_min_m &&
                    range_m < scan.max_range_m;
  }
  NoteGeometry(input, scan.T_robot_laser, output);
  return scan;
}

void RelocalizationNode::NoteGeometry(const ScanInput& input, const Pose2& T_robot_laser,
                                      NodeOutput& output) {
  ScanInput geometry;
  geometry.frame_id = input.frame_id;
  geometry.angle_min_rad = input.angle_min_rad;
  geometry.angle_increment_rad = input.angle_increment_rad;
  geometry.range_min_m = input.range_min_m;
  geometry.range_max_m = input.range_max_m;
  geometry.T_robot_laser = T_robot_laser;
  geometry.stamp_s = static_cast<double>(input.ranges_m.size());  // the beam count
  if (geometry_ && SameGeometry(*geometry_, geometry)) return;
  if (geometry_) {
    output.events.push_back({NodeEventLevel::kWarning, "scan at " + Stamp(input.stamp_s) +
                                                           ": the scan geometry changed from " +
                                                           GeometryText(*geometry_) + " to " +
                                                           GeometryText(geometry)});
  } else {
    output.events.push_back({NodeEventLevel::kInfo, "first scan: " + GeometryText(geometry)});
  }
  geometry_ = geometry;
}

void RelocalizationNode::Drain(NodeOutput& output) {
  while (!pending_.empty() && !odometry_.empty() &&
         odometry_.back().stamp_s >= pending_.front().scan.timestamp_s) {
    const PendingScan& next = pending_.front();
    if (const std::optional<Pose2> T_odom_robot = OdometryAt(next.scan.timestamp_s)) {
      Process(next.scan, *T_odom_robot, output);
    } else {
      Drop("scan at " + Stamp(next.scan.timestamp_s) + " dropped: it precedes the first " +
               "odometry pose",
           output);
    }
    pending_.pop_front();
  }
  // A scan still waiting while a later one is odometry_wait_s newer: the odometry stopped.
  while (!pending_.empty() && last_scan_stamp_s_ &&
         pending_.front().scan.timestamp_s < *last_scan_stamp_s_ - config_.node.odometry_wait_s) {
    Drop("scan at " + Stamp(pending_.front().scan.timestamp_s) + " dropped: no odometry at its " +
             "stamp within node.odometry_wait_s (" + Number(config_.node.odometry_wait_s) + " s)",
         output);
    pending_.pop_front();
  }
}

std::optional<Pose2> RelocalizationNode::OdometryAt(double stamp_s) const {
  const auto after =
      std::lower_bound(odometry_.begin(), odometry_.end(), stamp_s,
                       [](const OdometryInput& sample, double t) { return sample.stamp_s < t; });
  if (after == odometry_.end()) return std::nullopt;
  // Before the first pose the robot's pose would be a guess (the bag readers hold the first one
  // for a log's first scan; a live node drops the few scans before odometry starts).
  if (after == odometry_.begin()) {
    if (after->stamp_s == stamp_s) return after->T_odom_robot;
    return std::nullopt;
  }
  return Interpolate(*std::prev(after), *after, stamp_s);
}

void RelocalizationNode::Process(const LaserScan& scan, const Pose2& T_odom_robot,
                                 NodeOutput& output) {
  const std::string at = "scan at " + Stamp(scan.timestamp_s);
  if (last_T_odom_robot_) {
    // A step longer than lost_after_m would lose any fix unconfirmed: the odometry frame jumped
    // (a reset, a glitch), and neither the fix nor the query built so far hold across it.
    const double step_m = TranslationNorm(Between(*last_T_odom_robot_, T_odom_robot));
    if (step_m > config_.localization.fix.lost_after_m) {
      output.events.push_back(
          {NodeEventLevel::kWarning,
           at + ": the odometry moved " + Number(step_m) + " m since the previous scan (more " +
               "than localization.fix.lost_after_m): fix and query forgotten, searching again"});
      if (status_.status == FixStatus::kFixed) ++status_.losses;
      relocalizer_.Reset();
      status_.status = FixStatus::kSearching;
      status_.confidence = 0.0;
      status_.pose.reset();
      output.status_due = true;
    }
  }
  last_T_odom_robot_ = T_odom_robot;

  const auto start = std::chrono::steady_clock::now();
  RelocalizationUpdate update;
  try {
    update = relocalizer_.AddScan(scan, T_odom_robot);
  } catch (const std::exception& error) {
    // A scan the localizer cannot take leaves its query in an unknown state: start a new one.
    relocalizer_.Reset();
    Drop(at + " dropped: " + error.what() + "; searching again", output);
    status_.status = FixStatus::kSearching;
    status_.pose.reset();
    output.status_due = true;
    return;
  }
  const double latency_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  RecordLatency(latency_s);
  ++status_.scans_processed;
  status_.last_scan_stamp_s = scan.timestamp_s;
  output.scans.push_back({scan.timestamp_s, latency_s, update.status, update.answer.has_value()});
  Publish(update, scan.timestamp_s, output);
}

void RelocalizationNode::Publish(const RelocalizationUpdate& update, double stamp_s,
                                 NodeOutput& output) {
  const std::string at = "scan at " + Stamp(stamp_s);
  if (update.status != status_.status) output.status_due = true;
  status_.status = update.status;
  status_.confidence = update.status == FixStatus::kFixed ? update.confidence : 0.0;
  status_.unconfirmed_m = update.unconfirmed_m;
  if (update.answer) {
    const LocalizationResult& answer = *update.answer;
    ++status_.answers;
    status_.last_answer = NodeAnswer{stamp_s,           answer.found,     answer.ambiguous,
                                     answer.confidence, answer.submap_id, answer.T_world_robot};
    output.status_due = true;
  }
  if (update.lost) {
    ++status_.losses;
    output.events.push_back({NodeEventLevel::kWarning, at + ": fix lost"});
  }
  if (update.status != FixStatus::kFixed) {
    status_.pose.reset();
    return;
  }
  status_.T_world_odom = update.T_world_odom;
  status_.pose = InitialPoseOf(update, config_.node.map_frame);
  const NodePublish publish = config_.node.publish;
  if (update.new_fix) {
    ++status_.fixes;
    output.events.push_back(
        {NodeEventLevel::kInfo, at + ": fixed at " + PoseText(update.T_world_robot) +
                                    ", confidence " + Number(update.confidence)});
    if (publish != NodePublish::kMapToOdom)
      output.initial_poses.push_back({stamp_s, *status_.pose});
  }
  if (publish != NodePublish::kInitialPose) {
    output.transforms.push_back(
        {stamp_s, config_.node.map_frame, config_.input.odom_frame, update.T_world_odom});
  }
}

void RelocalizationNode::RepublishIfDue(double now_s, NodeOutput& output) {
  if (last_status_s_ && now_s - *last_status_s_ < config_.node.status_period_s &&
      now_s >= *last_status_s_) {
    return;
  }
  last_status_s_ = now_s;
  output.status_due = true;
  if (status_.status == FixStatus::kFixed && config_.node.publish != NodePublish::kInitialPose &&
      output.transforms.empty()) {
    output.transforms.push_back(
        {now_s, config_.node.map_frame, config_.input.odom_frame, status_.T_world_odom});
  }
}

void RelocalizationNode::RecordLatency(double latency_s) {
  latencies_s_.push_back(latency_s);
  if (latencies_s_.size() > kLatencyWindow) latencies_s_.pop_front();
}

void RelocalizationNode::Drop(const std::string& why, NodeOutput& output) {
  ++status_.scans_dropped;
  output.events.push_back({NodeEventLevel::kWarning, why});
}

NodeStatus RelocalizationNode::status() const {
  NodeStatus status = status_;
  status.scans_waiting = pending_.size();
  if (!latencies_s_.empty()) {
    const std::vector<double> latencies(latencies_s_.begin(), latencies_s_.end());
    double sum_s = 0.0;
    for (const double latency_s : latencies) sum_s += latency_s;
    status.latency_mean_s = sum_s / static_cast<double>(latencies.size());
    status.latency_p99_s = Quantile(latencies, 0.99);
    status.latency_max_s = *std::max_element(latencies.begin(), latencies.end());
  }
  return status;
}

std::string RelocalizationNode::StatusYaml() const {
  const NodeStatus s = status();
  std::ostringstream yaml;
  yaml << std::setprecision(std::numeric_limits<double>::max_digits10);
  yaml << "status: " << ToString(s.status) << "\n";
  yaml << "confidence: " << s.confidence << "\n";
  if (s.pose) {
    yaml << "pose: {frame_id: " << s.pose->frame_id << ", x: " << s.pose->T_map_robot.x
         << ", y: " << s.pose->T_map_robot.y << ", theta: " << s.pose->T_map_robot.theta << "}\n";
    yaml << "covariance_xytheta: [";
    for (int i = 0; i < 9; ++i) yaml << (i ? ", " : "") << s.pose->covariance(i / 3, i % 3);
    yaml << "]\n";
    yaml << "T_map_odom: {x: " << s.T_world_odom.x << ", y: " << s.T_world_odom.y
         << ", theta: " << s.T_world_odom.theta << "}\n";
    yaml << "unconfirmed_m: " << s.unconfirmed_m << "\n";
  }
  if (s.last_answer) {
    const NodeAnswer& a = *s.last_answer;
    yaml << "last_answer: {stamp_s: " << a.stamp_s << ", found: " << (a.found ? "true" : "false")
         << ", ambiguous: " << (a.ambiguous ? "true" : "false") << ", confidence: " << a.confidence
         << ", submap: " << a.submap_id << ", x: " << a.T_world_robot.x
         << ", y: " << a.T_world_robot.y << ", theta: " << a.T_world_robot.theta << "}\n";
  }
  yaml << "last_scan_stamp_s: " << s.last_scan_stamp_s << "\n";
  yaml << "scans_received: " << s.scans_received << "\n";
  yaml << "scans_processed: " << s.scans_processed << "\n";
  yaml << "scans_dropped: " << s.scans_dropped << "\n";
  yaml << "scans_waiting: " << s.scans_waiting << "\n";
  yaml << "odometry_dropped: " << s.odometry_dropped << "\n";
  yaml << "answers: " << s.answers << "\n";
  yaml << "fixes: " << s.fixes << "\n";
  yaml << "losses: " << s.losses << "\n";
  yaml << "latency_mean_s: " << s.latency_mean_s << "\n";
  yaml << "latency_p99_s: " << s.latency_p99_s << "\n";
  yaml << "latency_max_s: " << s.latency_max_s << "\n";
  return yaml.str();
}

void RelocalizationNode::SaveStatus(const std::string& path) const {
  const std::string text = StatusYaml();
  WriteFileAtomically(path, [&](std::ostream& out) { out << text; });
}

}  // namespace keyplace
