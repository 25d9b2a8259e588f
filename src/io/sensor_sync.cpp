#include "keyplace/io/sensor_sync.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <utility>

#include "common/fixed_text.hpp"
#include "keyplace/io/carmen_log.hpp"

namespace keyplace {
namespace {

// An odometry position beyond this is a corrupt message, not a place (the log and bag readers'
// limit, CarmenReadOptions::max_coordinate_m).
constexpr double kMaxCoordinateM = 1e7;

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
         FixedText(geometry.angle_min_rad, 6) + " rad by " +
         FixedText(geometry.angle_increment_rad, 6) + " rad, ranges " +
         FixedText(geometry.range_min_m) + " to " + FixedText(geometry.range_max_m) +
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

// Why the beams' bearings are not a scan (the bag readers' bounds), or "".
std::string BearingProblem(double start_rad, double step_rad, std::size_t beams) {
  if (!std::isfinite(start_rad) || !std::isfinite(step_rad)) {
    return "angle_min and angle_increment must be finite";
  }
  if (!(std::abs(start_rad) <= 2.0 * M_PI)) {
    return "angle_min = " + FixedText(start_rad, 6) + " rad is not an angle in [-2 pi, 2 pi]";
  }
  const double span_rad = std::abs(step_rad) * static_cast<double>(beams - 1);
  if ((beams > 1 && step_rad == 0.0) || !(span_rad <= 2.0 * M_PI * (1.0 + 1e-9))) {
    return "angle_increment = " + FixedText(step_rad, 6) + " rad over " + std::to_string(beams) +
           " beams does not spread them over at most one turn";
  }
  return "";
}

}  // namespace

std::string StampText(double stamp_s) { return FixedText(stamp_s, 6); }

SensorSync::SensorSync(const BagInputConfig& input, double odometry_wait_s)
    : input_([&] {
        Validate(input);
        return input;
      }()),
      odometry_wait_s_(odometry_wait_s),
      laser_pose_override_(ParseLaserPose(input.laser_pose)) {
  if (!(odometry_wait_s > 0.0)) {
    throw std::invalid_argument("odometry_wait_s must be positive");
  }
}

SyncOutput SensorSync::AddOdometry(const OdometryInput& odometry) {
  SyncOutput output;
  const Pose2& pose = odometry.T_odom_robot;
  std::string problem;
  if (!std::isfinite(odometry.stamp_s) || !std::isfinite(pose.theta)) {
    problem = "its stamp or heading is not finite";
  } else if (!(std::abs(pose.x) <= kMaxCoordinateM && std::abs(pose.y) <= kMaxCoordinateM)) {
    problem = "its position lies beyond +-1e7 m";
  } else if (!odometry_.empty() && odometry.stamp_s <= odometry_.back().stamp_s) {
    problem = "it is not after the previous one (" + StampText(odometry_.back().stamp_s) +
              "): out of order or repeated";
  }
  if (!problem.empty()) {
    ++odometry_dropped_;
    output.events.push_back(
        {NodeEventLevel::kWarning,
         "odometry at " + StampText(odometry.stamp_s) + " dropped: " + problem});
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
  return output;
}

SyncOutput SensorSync::AddScan(const ScanInput& input) {
  SyncOutput output;
  ++scans_received_;
  if (!std::isfinite(input.stamp_s)) {
    Drop("a scan with a stamp that is not finite dropped", output);
    return output;
  }
  if (last_scan_stamp_s_ && input.stamp_s <= *last_scan_stamp_s_) {
    Drop("scan at " + StampText(input.stamp_s) + " dropped: not after the previous scan (" +
             StampText(*last_scan_stamp_s_) + "): out of order or repeated",
         output);
    return output;
  }
  std::optional<LaserScan> scan = Convert(input, output);
  if (!scan) return output;
  last_scan_stamp_s_ = input.stamp_s;
  pending_.push_back({std::move(*scan), input.frame_id});
  Drain(output);
  return output;
}

std::optional<LaserScan> SensorSync::Convert(const ScanInput& input, SyncOutput& output) {
  const std::size_t n = input.ranges_m.size();
  const double fov_rad = input_.scan_fov_rad;
  // scan_fov_rad: spread as a FLASER line of n beams would be, as the bag readers do.
  const bool flaser = fov_rad > 0.0 && n > 0;
  const double start_rad = flaser ? FlaserBeamAngle(0, n, fov_rad) : input.angle_min_rad;
  const double step_rad = flaser ? fov_rad / FlaserSteps(n) : input.angle_increment_rad;
  std::string problem;
  if (n == 0) {
    problem = "it has no beams";
  } else if (n > kMaxScanBeams) {
    problem = std::to_string(n) + " beams, more than the " + std::to_string(kMaxScanBeams) +
              " keyplace takes (downsample the scan)";
  } else if (!(input.range_max_m > 0.0 && std::isfinite(input.range_max_m))) {
    problem = "range_max must be positive and finite";
  } else {
    problem = BearingProblem(start_rad, step_rad, n);
  }
  const std::optional<Pose2> T_robot_laser =
      laser_pose_override_ ? laser_pose_override_ : input.T_robot_laser;
  if (problem.empty() && !T_robot_laser) {
    problem = "no laser pose for frame '" + input.frame_id + "' (tf " + input_.base_frame + " -> " +
              input.frame_id + ", or input.laser_pose)";
  }
  if (!problem.empty()) {
    Drop("scan at " + StampText(input.stamp_s) + " dropped: " + problem, output);
    return std::nullopt;
  }
  LaserScan scan;
  scan.timestamp_s = input.stamp_s;
  scan.max_range_m = input.range_max_m;
  scan.T_robot_laser = *T_robot_laser;
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

void SensorSync::NoteGeometry(const ScanInput& input, const Pose2& T_robot_laser,
                              SyncOutput& output) {
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
    output.events.push_back({NodeEventLevel::kWarning, "scan at " + StampText(input.stamp_s) +
                                                           ": the scan geometry changed from " +
                                                           GeometryText(*geometry_) + " to " +
                                                           GeometryText(geometry)});
  } else {
    output.events.push_back({NodeEventLevel::kInfo, "first scan: " + GeometryText(geometry)});
  }
  geometry_ = geometry;
}

void SensorSync::Drain(SyncOutput& output) {
  while (!pending_.empty() && !odometry_.empty() &&
         odometry_.back().stamp_s >= pending_.front().scan.timestamp_s) {
    PendingScan& next = pending_.front();
    if (const std::optional<Pose2> T_odom_robot = OdometryAt(next.scan.timestamp_s)) {
      output.scans.push_back({std::move(next.scan), std::move(next.frame_id), *T_odom_robot});
    } else {
      Drop("scan at " + StampText(next.scan.timestamp_s) + " dropped: it precedes the first " +
               "odometry pose",
           output);
    }
    pending_.pop_front();
  }
  // A scan still waiting while a later one is odometry_wait_s newer: the odometry stopped.
  while (!pending_.empty() && last_scan_stamp_s_ &&
         pending_.front().scan.timestamp_s < *last_scan_stamp_s_ - odometry_wait_s_) {
    Drop("scan at " + StampText(pending_.front().scan.timestamp_s) + " dropped: no odometry at " +
             "its stamp within node.odometry_wait_s (" + FixedText(odometry_wait_s_) + " s)",
         output);
    pending_.pop_front();
  }
}

std::optional<Pose2> SensorSync::OdometryAt(double stamp_s) const {
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

void SensorSync::Drop(const std::string& why, SyncOutput& output) {
  ++scans_dropped_;
  output.events.push_back({NodeEventLevel::kWarning, why});
}

}  // namespace keyplace
