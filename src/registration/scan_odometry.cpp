#include "keyplace/registration/scan_odometry.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

#include "common/quantile.hpp"
#include "correlative_search.hpp"
#include "probability_grid.hpp"

namespace keyplace {
namespace {

constexpr double kMaxRecoveryPoses = 1e6;
// Cartographer's 2D submap resolution; 1024 cells of it span 51 m, so points up to 12.8 m from
// the laser always lie in the grid (it is centred again when the laser leaves its middle half),
// and farther ones of the 30 m of ScanOdometryConfig::max_range_m often do.
constexpr double kGridCellM = 0.05;
constexpr int kGridWidthCells = 1024;
// Key scans in the grid: as many as a Cartographer 2D submap holds (num_range_data 90). Measured
// against the ICP local map's 10 on FR079_r and Intel_r, every scan refined: the front end's drift
// (relations over more than 5 s) 0.34 → 0.20 m and 0.77 → 0.50 m (docs/REGISTRATION.md).
constexpr std::size_t kGridKeyScans = 90;
// Scans over which the odometry's total judges a catch-up: longer than its stalls (Intel raw:
// 13 scans with no motion, then 0.77 m at once), short enough that its drift over them stays far
// below the correction bound it decides (25 scans of 5 cm: 1.25 m, a few cm of drift).
constexpr std::size_t kOdometryWindowScans = 25;
// Registered scans over which the odometry's agreement with ICP is measured, and the fewest that
// judge a weak match.
constexpr std::size_t kAgreementWindowScans = 25;
constexpr std::size_t kAgreementMinScans = 10;
// A weak match: inlier ratio below this fraction of the recent matches' median. On the
// development logs (FR079_r, Intel_r) 99.9 % of the registered scans are above 0.71 of it; the
// lowest are FR079_r raw 4175 (0.52: a person next to the laser), then one at 0.66.
constexpr double kWeakMatchInlierFraction = 0.6;
// How far ICP's step parts from the odometry's is judged against the motion: wheel odometry errs
// in proportion to how far it moved and turned, plus this much for the scan's own noise (m, and
// rad counted as m at 1 m).
constexpr double kDisagreementFloor = 0.05;
// A step the odometry contradicts: its disagreement per motion exceeds this many times the recent
// median. On the development logs the 99.9th percentile of that multiple is 14.8 (FR079_r) and
// 19.1 (Intel_r); FR079_r raw 4175 is at 44.
constexpr double kContradictionMedians = 20.0;

void RequireOdometryField(bool condition, const char* field, const char* what) {
  if (!condition) {
    throw std::invalid_argument(std::string("ScanOdometryConfig.") + field + " " + what);
  }
}

// ICP's step against the odometry's (`correction`, ICP's pose in the predicted frame) per unit of
// the odometry's motion (`odometry_step`).
double DisagreementPerMotion(const Pose2& correction, const Pose2& odometry_step) {
  const double motion = TranslationNorm(odometry_step) + std::abs(odometry_step.theta);
  return (TranslationNorm(correction) + std::abs(correction.theta)) / (motion + kDisagreementFloor);
}

void RecordIcp(const IcpResult& icp, ScanOdometryResult* result) {
  result->icp_status = icp.status;
  result->iterations = icp.iterations;
  result->inlier_ratio = icp.inlier_ratio;
  result->residual_rms_m = icp.residual_rms_m;
  result->degenerate = icp.degenerate;
}

}  // namespace

std::string ToString(ScanOdometryStatus status) {
  switch (status) {
    case ScanOdometryStatus::kFirstScan:
      return "first_scan";
    case ScanOdometryStatus::kRegistered:
      return "registered";
    case ScanOdometryStatus::kRecovered:
      return "recovered";
    case ScanOdometryStatus::kFallbackNotConverged:
      return "fallback_not_converged";
    case ScanOdometryStatus::kFallbackCorrectionTooLarge:
      return "fallback_correction_too_large";
    case ScanOdometryStatus::kFallbackTooFewPoints:
      return "fallback_too_few_points";
    case ScanOdometryStatus::kFallbackWeakMatch:
      return "fallback_weak_match";
  }
  return "unknown";
}

bool IsIcpPose(ScanOdometryStatus status) {
  return status == ScanOdometryStatus::kRegistered || status == ScanOdometryStatus::kRecovered;
}

void ValidateScanOdometryConfig(const ScanOdometryConfig& c) {
  try {
    ValidateIcpConfig(c.icp);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(std::string("ScanOdometryConfig.icp: ") + error.what());
  }
  RequireOdometryField(c.min_range_m >= 0.0, "min_range_m", "must be >= 0");
  RequireOdometryField(c.max_range_m > c.min_range_m, "max_range_m", "must be > min_range_m");
  RequireOdometryField(c.source_min_spacing_m >= 0.0, "source_min_spacing_m", "must be >= 0");
  RequireOdometryField(c.local_map_scans >= 1, "local_map_scans", "must be >= 1");
  RequireOdometryField(c.keyframe_translation_m >= 0.0, "keyframe_translation_m", "must be >= 0");
  RequireOdometryField(c.keyframe_rotation_rad >= 0.0, "keyframe_rotation_rad", "must be >= 0");
  RequireOdometryField(c.max_correction_translation_m > 0.0, "max_correction_translation_m",
                       "must be > 0");
  RequireOdometryField(c.max_correction_rotation_rad > 0.0, "max_correction_rotation_rad",
                       "must be > 0");
  RequireOdometryField(
      c.recovery_window_translation_m >= 0.0 && c.recovery_window_translation_m <= 10.0,
      "recovery_window_translation_m", "must be in [0, 10]");
  RequireOdometryField(
      c.recovery_window_rotation_rad >= 0.0 && c.recovery_window_rotation_rad <= M_PI,
      "recovery_window_rotation_rad", "must be in [0, pi]");
  RequireOdometryField(
      std::isfinite(c.recovery_step_translation_m) && c.recovery_step_translation_m >= 0.01,
      "recovery_step_translation_m", "must be finite and >= 0.01");
  RequireOdometryField(
      std::isfinite(c.recovery_step_rotation_rad) && c.recovery_step_rotation_rad >= 0.001,
      "recovery_step_rotation_rad", "must be finite and >= 0.001");
  // Each searched pose costs one lookup per scan point: the default window has 11 x 11 x 181 =
  // 21 901 poses (4-12 ms); this bound keeps a search under about a second.
  const double translations =
      2.0 * std::floor(c.recovery_window_translation_m / c.recovery_step_translation_m) + 1.0;
  const double rotations =
      2.0 * std::floor(c.recovery_window_rotation_rad / c.recovery_step_rotation_rad) + 1.0;
  RequireOdometryField(
      translations * translations * rotations <= kMaxRecoveryPoses, "recovery_window_translation_m",
      "and the other recovery_window_* / recovery_step_* fields give more than 1 000 000 "
      "searched poses");
}

ScanOdometry::ScanOdometry(const ScanOdometryConfig& config) : config_(config) {
  ValidateScanOdometryConfig(config_);
}

ScanOdometry::~ScanOdometry() = default;

std::vector<Eigen::Vector2d> ScanOdometry::FilteredEndpoints(const LaserScan& scan,
                                                             const ScanOdometryConfig& config) {
  std::vector<Eigen::Vector2d> points;
  const std::size_t n = std::min(scan.ranges_m.size(), scan.angles_rad.size());
  points.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (i < scan.valid.size() && scan.valid[i] == 0) continue;
    const double r = scan.ranges_m[i];
    if (!std::isfinite(r) || r < config.min_range_m || r >= config.max_range_m) continue;
    const double a = scan.angles_rad[i];
    points.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  return points;
}

std::vector<Eigen::Vector2d> ScanOdometry::SubsampleBySpacing(
    const std::vector<Eigen::Vector2d>& points, double spacing_m) {
  if (spacing_m <= 0.0 || points.empty()) return points;
  std::vector<Eigen::Vector2d> kept;
  kept.reserve(points.size());
  const double spacing2 = spacing_m * spacing_m;
  for (const Eigen::Vector2d& p : points) {
    if (kept.empty() || (p - kept.back()).squaredNorm() >= spacing2) kept.push_back(p);
  }
  return kept;
}

void ScanOdometry::AddKeyframe(const std::vector<Eigen::Vector2d>& points_laser,
                               const Pose2& T_world_laser) {
  target_.reset();  // it refers to map_points_, which changes now
  Keyframe keyframe;
  // Normals are fitted within the one scan (no cross-scan noise), then rotated with it.
  keyframe.normals_world = EstimateNormals(points_laser, config_.icp);
  const Eigen::Matrix2d R = Eigen::Rotation2Dd(T_world_laser.theta).toRotationMatrix();
  for (Eigen::Vector2d& n : keyframe.normals_world.normals) n = R * n;
  keyframe.points_world.reserve(points_laser.size());
  const PointMapper to_world(T_world_laser);
  for (const Eigen::Vector2d& p : points_laser) keyframe.points_world.push_back(to_world(p));
  keyframes_.push_back(std::move(keyframe));
  while (static_cast<int>(keyframes_.size()) > config_.local_map_scans) keyframes_.pop_front();

  map_points_.clear();
  PointNormals map_normals;
  for (const Keyframe& k : keyframes_) {
    map_points_.insert(map_points_.end(), k.points_world.begin(), k.points_world.end());
    map_normals.normals.insert(map_normals.normals.end(), k.normals_world.normals.begin(),
                               k.normals_world.normals.end());
    map_normals.valid.insert(map_normals.valid.end(), k.normals_world.valid.begin(),
                             k.normals_world.valid.end());
  }
  target_ = std::make_unique<IcpTarget>(map_points_, std::move(map_normals), config_.icp);
  last_keyframe_T_world_laser_ = T_world_laser;
  if (config_.grid_refinement) {
    if (!grid_) grid_ = std::make_unique<ProbabilityGrid>(kGridCellM, kGridWidthCells);
    grid_->Push({T_world_laser.translation(), keyframes_.back().points_world});
    while (grid_->num_scans() > kGridKeyScans) grid_->Pop();
  }
}

std::optional<IcpResult> ScanOdometry::Recover(const std::vector<Eigen::Vector2d>& source_laser,
                                               const Pose2& predicted_T_world_laser) const {
  CorrelativeWindow window;
  window.translation_m = config_.recovery_window_translation_m;
  window.rotation_rad = config_.recovery_window_rotation_rad;
  window.translation_step_m = config_.recovery_step_translation_m;
  window.rotation_step_rad = config_.recovery_step_rotation_rad;
  // Closeness falls to exp(-1/8) = 0.88 half a step off a target point, so the true pose scores
  // well on the search grid; the field covers every point the scan can reach in the window.
  const double sigma_m = window.translation_step_m;
  double reach_m = 0.0;
  for (const Eigen::Vector2d& p : source_laser) reach_m = std::max(reach_m, p.norm());
  const ProximityField field(map_points_, predicted_T_world_laser.translation(),
                             reach_m + window.translation_m + 3.0 * sigma_m,
                             window.translation_step_m / 2.0, sigma_m);
  const CorrelativeMatch match =
      SearchCorrelative(field, source_laser, predicted_T_world_laser, window);
  if (!match.moved) return std::nullopt;  // ICP from the same start would fail the same way
  IcpResult icp = AlignPointToLine(*target_, source_laser, match.T_target_source, config_.icp);
  if (!icp.converged) return std::nullopt;
  if (!WithinCorrectionBounds(Between(match.T_target_source, icp.T_target_source))) {
    return std::nullopt;
  }
  return icp;
}

bool ScanOdometry::WithinCorrectionBounds(const Pose2& correction) const {
  return TranslationNorm(correction) <= config_.max_correction_translation_m &&
         std::abs(correction.theta) <= config_.max_correction_rotation_rad;
}

bool ScanOdometry::WeakMatchContradictsOdometry(double inlier_ratio, const Pose2& correction,
                                                const Pose2& odometry_step) const {
  if (agreement_window_.size() < kAgreementMinScans) return false;
  // Most matches are not weak: the disagreements' median only for those that are.
  std::vector<double> values;
  values.reserve(agreement_window_.size());
  for (const Agreement& a : agreement_window_) values.push_back(a.inlier_ratio);
  if (inlier_ratio >= kWeakMatchInlierFraction * Quantile(values, 0.5)) return false;
  values.clear();
  for (const Agreement& a : agreement_window_) values.push_back(a.disagreement_per_motion);
  return DisagreementPerMotion(correction, odometry_step) >
         kContradictionMedians * Quantile(values, 0.5);
}

void ScanOdometry::RecordAgreement(double inlier_ratio, const Pose2& correction,
                                   const Pose2& odometry_step) {
  agreement_window_.push_back({inlier_ratio, DisagreementPerMotion(correction, odometry_step)});
  while (agreement_window_.size() > kAgreementWindowScans) agreement_window_.pop_front();
}

// A scan joins the local map when it moved or turned far enough from the last key scan, or
// while the map is too small for ICP; never one whose view the map just found mostly foreign
// (a weak match: it would bring the occluder into the map).
bool ScanOdometry::WantsKeyframe(const Pose2& T_world_laser, ScanOdometryStatus status) const {
  const bool map_too_small = static_cast<int>(map_points_.size()) < config_.icp.min_points;
  if (status == ScanOdometryStatus::kFallbackWeakMatch && !map_too_small) return false;
  const Pose2 since_keyframe = Between(last_keyframe_T_world_laser_, T_world_laser);
  return TranslationNorm(since_keyframe) >= config_.keyframe_translation_m ||
         std::abs(since_keyframe.theta) >= config_.keyframe_rotation_rad || map_too_small;
}

// Two independent predictions of this scan's pose: the odometry's, and the previous step as ICP
// estimated it, repeated. When they part by more than the correction bound, one of them is wrong,
// and ICP says which (docs/REGISTRATION.md, "Odometry glitches" and "Odometry that stalls, then
// catches up"). Only with recovery on, odometry at this scan and the one before, and a previous
// step ICP estimated.
std::optional<Pose2> ScanOdometry::DisputingMotion(const Pose2& predicted_T_world_laser,
                                                   bool increment_measured) const {
  if (!config_.recovery_search || !increment_measured || !have_previous_icp_step_) {
    return std::nullopt;
  }
  const Pose2 motion_T_world_laser = previous_T_world_laser_ * previous_step_laser_;
  if (WithinCorrectionBounds(Between(motion_T_world_laser, predicted_T_world_laser))) {
    return std::nullopt;
  }
  return motion_T_world_laser;
}

std::optional<IcpResult> ScanOdometry::MotionBetterByOdometryTotal(
    const std::vector<Eigen::Vector2d>& source, const Pose2& motion_T_world_laser,
    const IcpResult& from_odometry, const Pose2& odometry_laser) const {
  if (odometry_window_.size() < kOdometryWindowScans) return std::nullopt;
  const IcpResult from_motion =
      AlignPointToLine(*target_, source, motion_T_world_laser, config_.icp);
  // Two minima, each near its start: anything less is one pose found twice.
  if (!from_motion.converged ||
      !WithinCorrectionBounds(Between(motion_T_world_laser, from_motion.T_target_source)) ||
      WithinCorrectionBounds(Between(from_odometry.T_target_source, from_motion.T_target_source))) {
    return std::nullopt;
  }
  const Pose2 total_T_world_laser = OdometryTotal(odometry_laser);
  const auto off_m = [&](const Pose2& T_world_laser) {
    return TranslationNorm(Between(total_T_world_laser, T_world_laser));
  };
  if (off_m(from_motion.T_target_source) < off_m(from_odometry.T_target_source)) {
    return from_motion;
  }
  return std::nullopt;
}

// ICP from the prediction, the checks of its result and the recovery: the scan's pose, and its
// status and ICP figures in `result` (the prediction itself when the scan falls back).
Pose2 ScanOdometry::Register(const std::vector<Eigen::Vector2d>& source,
                             const Pose2& predicted_T_world_laser, const Pose2& odometry_step,
                             const std::optional<Pose2>& disputing_motion,
                             const Pose2& odometry_laser, ScanOdometryResult& result) const {
  Pose2 T_world_laser = predicted_T_world_laser;
  const IcpResult icp = AlignPointToLine(*target_, source, predicted_T_world_laser, config_.icp);
  RecordIcp(icp, &result);
  const Pose2 correction = Between(predicted_T_world_laser, icp.T_target_source);
  if (!icp.converged) {
    result.status = icp.status == IcpStatus::kTooFewPoints
                        ? ScanOdometryStatus::kFallbackTooFewPoints
                        : ScanOdometryStatus::kFallbackNotConverged;
  } else if (!disputing_motion && WithinCorrectionBounds(correction) &&
             WeakMatchContradictsOdometry(icp.inlier_ratio, correction, odometry_step)) {
    // The odometry is not disputed by the previous motion either: trust it over a match on far
    // fewer points than the recent ones had.
    result.status = ScanOdometryStatus::kFallbackWeakMatch;
  } else if (WithinCorrectionBounds(correction)) {
    result.status = ScanOdometryStatus::kRegistered;
    T_world_laser = icp.T_target_source;
    const std::optional<IcpResult> better =
        disputing_motion
            ? MotionBetterByOdometryTotal(source, *disputing_motion, icp, odometry_laser)
            : std::nullopt;
    if (better && MapSupportsBetter(source, better->T_target_source, icp.T_target_source)) {
      RecordIcp(*better, &result);
      result.status = ScanOdometryStatus::kRecovered;
      T_world_laser = better->T_target_source;
    }
  } else if (disputing_motion &&
             WithinCorrectionBounds(Between(*disputing_motion, icp.T_target_source)) &&
             MapSupportsBetter(source, icp.T_target_source, predicted_T_world_laser)) {
    // ICP converged beyond the bound of the odometry's prediction, within that of the
    // motion's: the odometry glitched.
    result.status = ScanOdometryStatus::kRecovered;
    T_world_laser = icp.T_target_source;
  } else {
    result.status = ScanOdometryStatus::kFallbackCorrectionTooLarge;
  }
  if (config_.recovery_search &&
      (result.status == ScanOdometryStatus::kFallbackNotConverged ||
       result.status == ScanOdometryStatus::kFallbackCorrectionTooLarge)) {
    // The total only when the odometry's last step also parts from the previous motion: a late
    // step, not ICP having corrected the odometry over the window (drift, slip).
    const std::optional<Pose2> total =
        disputing_motion ? OdometryTotalDisputing(predicted_T_world_laser, odometry_laser)
                         : std::nullopt;
    const std::optional<IcpResult> recovered = RecoverFrom(source, predicted_T_world_laser, total);
    if (recovered &&
        MapSupportsBetter(source, recovered->T_target_source, predicted_T_world_laser)) {
      RecordIcp(*recovered, &result);
      result.status = ScanOdometryStatus::kRecovered;
      T_world_laser = recovered->T_target_source;
    }
  }
  return T_world_laser;
}

bool ScanOdometry::MapSupportsBetter(const std::vector<Eigen::Vector2d>& source,
                                     const Pose2& candidate_T_world_laser,
                                     const Pose2& alternative_T_world_laser) const {
  if (!grid_) return true;
  return MeanGridCost(*grid_, source, candidate_T_world_laser) <
         MeanGridCost(*grid_, source, alternative_T_world_laser);
}

// Where the odometry's total since the oldest scan of the window puts this scan.
Pose2 ScanOdometry::OdometryTotal(const Pose2& odometry_laser) const {
  const Past& oldest = odometry_window_.front();
  return oldest.T_world_laser * Between(oldest.T_odom_laser, odometry_laser);
}

// Where the odometry's total over the last scans puts this scan (from the oldest of them), when
// it parts from the odometry's last step beyond the correction bounds: the motion the scans
// measured while the odometry stood still, reported again in one late step (docs/REGISTRATION.md,
// "Odometry that stalls, then catches up"). Only with a full window of scans with odometry.
std::optional<Pose2> ScanOdometry::OdometryTotalDisputing(const Pose2& predicted_T_world_laser,
                                                          const Pose2& odometry_laser) const {
  if (odometry_window_.size() < kOdometryWindowScans) return std::nullopt;
  const Pose2 total_T_world_laser = OdometryTotal(odometry_laser);
  if (WithinCorrectionBounds(Between(predicted_T_world_laser, total_T_world_laser))) {
    return std::nullopt;
  }
  return total_T_world_laser;
}

// ICP failed from the odometry's prediction: ICP from the odometry's total when it disputes the
// prediction (cheap, and right when the last step was a late one), then the search around the
// prediction, then around the total.
std::optional<IcpResult> ScanOdometry::RecoverFrom(const std::vector<Eigen::Vector2d>& source,
                                                   const Pose2& predicted_T_world_laser,
                                                   const std::optional<Pose2>& total) const {
  if (total) {
    const IcpResult from_total = AlignPointToLine(*target_, source, *total, config_.icp);
    if (from_total.converged &&
        WithinCorrectionBounds(Between(*total, from_total.T_target_source))) {
      return from_total;
    }
  }
  if (std::optional<IcpResult> recovered = Recover(source, predicted_T_world_laser)) {
    return recovered;
  }
  return total ? Recover(source, *total) : std::nullopt;
}

ScanOdometryResult ScanOdometry::Add(const LaserScan& scan,
                                     const std::optional<Pose2>& T_odom_robot) {
  const auto start = std::chrono::steady_clock::now();
  ScanOdometryResult result;
  result.sequence = num_scans_;
  result.timestamp_s = scan.timestamp_s;
  const Pose2& T_robot_laser = scan.T_robot_laser;
  const std::vector<Eigen::Vector2d> points = FilteredEndpoints(scan, config_);

  // Odometry increment of the laser since the previous scan.
  Pose2 odometry_increment;  // identity without odometry
  Pose2 odometry_laser;
  const bool increment_measured = T_odom_robot.has_value() && previous_scan_had_odometry_;
  previous_scan_had_odometry_ = T_odom_robot.has_value();
  if (!increment_measured) {  // no odometry total or agreement across a scan without it
    odometry_window_.clear();
    agreement_window_.clear();
  }
  if (T_odom_robot) {
    odometry_laser = *T_odom_robot * T_robot_laser;
    if (have_previous_odometry_)
      odometry_increment = Between(previous_odometry_laser_, odometry_laser);
    previous_odometry_laser_ = odometry_laser;
    have_previous_odometry_ = true;
  }

  if (num_scans_ == 0) {
    const Pose2 T_world_robot = T_odom_robot ? *T_odom_robot : Pose2();
    result.T_world_robot = T_world_robot;
    result.T_world_laser = T_world_robot * T_robot_laser;
    result.T_world_robot_odometry_prediction = T_world_robot;
    result.status = ScanOdometryStatus::kFirstScan;
    result.converged = true;
    result.icp_status = IcpStatus::kConverged;
    result.keyframe = true;
    AddKeyframe(points, result.T_world_laser);
  } else {
    const Pose2 predicted_T_world_laser = previous_T_world_laser_ * odometry_increment;
    result.T_world_robot_odometry_prediction = predicted_T_world_laser * T_robot_laser.inverse();
    Pose2 T_world_laser = predicted_T_world_laser;
    // The points registered (ICP, the recovery) and refined on the grid.
    std::vector<Eigen::Vector2d> source;
    if (target_ == nullptr || static_cast<int>(points.size()) < config_.icp.min_points ||
        static_cast<int>(map_points_.size()) < config_.icp.min_points) {
      result.status = ScanOdometryStatus::kFallbackTooFewPoints;
      result.icp_status = IcpStatus::kTooFewPoints;
    } else {
      source = SubsampleBySpacing(points, config_.source_min_spacing_m);
      T_world_laser = Register(source, predicted_T_world_laser, odometry_increment,
                               DisputingMotion(predicted_T_world_laser, increment_measured),
                               odometry_laser, result);
    }
    result.converged = IsIcpPose(result.status);
    result.fell_back = !result.converged;
    const bool key_scan = !points.empty() && WantsKeyframe(T_world_laser, result.status);
    if (key_scan && grid_ && result.converged) {
      // Only key scans: they make the maps every later scan is registered against.
      const GridMatch refined = MatchOnGrid(*grid_, source, T_world_laser);
      if (refined.converged) T_world_laser = refined.T_world_laser;
    }
    result.T_world_laser = T_world_laser;
    if (result.status == ScanOdometryStatus::kRegistered && increment_measured) {
      RecordAgreement(result.inlier_ratio, Between(predicted_T_world_laser, T_world_laser),
                      odometry_increment);
    }
    result.T_world_robot = T_world_laser * T_robot_laser.inverse();
    if (key_scan) {
      result.keyframe = true;
      AddKeyframe(points, T_world_laser);
    }
  }
  // A fallback's step is the odometry's own, no second opinion on the next one.
  have_previous_icp_step_ = num_scans_ > 0 && result.converged;
  if (have_previous_icp_step_) {
    previous_step_laser_ = Between(previous_T_world_laser_, result.T_world_laser);
  }
  previous_T_world_laser_ = result.T_world_laser;
  if (T_odom_robot) {
    odometry_window_.push_back({result.T_world_laser, odometry_laser});
    while (odometry_window_.size() > kOdometryWindowScans) odometry_window_.pop_front();
  }
  ++num_scans_;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace keyplace
