#pragma once
// Scan odometry: registers each scan against a local map of recent key scans with point-to-line
// ICP, initialised by the odometry increment, and falls back to odometry (flagged) when ICP
// fails. Scans are processed in the order they are added (for Intel raw: logger_timestamp).

#include <cstddef>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"
#include "keyplace/io/laser_scan.hpp"
#include "keyplace/registration/icp.hpp"

namespace keyplace {

class ProbabilityGrid;

struct ScanOdometryConfig {
  IcpConfig icp;

  // Beams shorter than this or at/after this range are not used (m). The far limit also drops
  // the sparse, noisy long returns that do not help local registration.
  double min_range_m = 0.1;
  double max_range_m = 30.0;

  // Source points (the scan being registered) closer than this to the previously kept point,
  // in beam order, are skipped (m). Dense short-range beams then cost less ICP time; the map
  // keeps every point. 0 keeps all.
  double source_min_spacing_m = 0.03;

  // The local map holds the last `local_map_scans` key scans (their endpoints in the world
  // frame). A scan becomes a key scan when its registered laser pose has moved at least
  // keyframe_translation_m or turned keyframe_rotation_rad since the last key scan; a stationary
  // robot therefore does not wash the map out with copies of one view.
  int local_map_scans = 10;
  // A key scan's point gets its normal from a line fitted within its own scan (no cross-scan
  // noise); where that fails (too sparse, not line-like) the point has no normal and ICP does not
  // use it (fitting those to the whole local map was measured worse and removed:
  // docs/REGISTRATION.md, "Removed options").
  double keyframe_translation_m = 0.1;
  double keyframe_rotation_rad = 0.0872664626;  // 5 deg

  // An ICP result that moves the pose further than this from the odometry-predicted pose is
  // rejected (fallback to odometry, flagged) unless recovery_search recovers the scan. Guards
  // against converging into a wrong minimum.
  double max_correction_translation_m = 0.5;
  double max_correction_rotation_rad = 0.3490658504;  // 20 deg

  // Recovery from a bad alignment. When ICP from the prediction does not converge (too few
  // inliers, no convergence) or converges beyond the max_correction_* bounds, the prediction
  // itself is suspect: a correlative search scores every pose of a window around it against the
  // local map (translations ±recovery_window_translation_m in steps of
  // recovery_step_translation_m, rotations ±recovery_window_rotation_rad in steps of
  // recovery_step_rotation_rad) and ICP runs again from the best one. Its result is used when it
  // converges within the max_correction_* bounds of that pose (status kRecovered); otherwise the
  // scan falls back to odometry as before. Before the search, an ICP result beyond the bounds is
  // taken (kRecovered) when the odometry's prediction and the previous ICP step repeated part by
  // more than the bounds and the result lies within them of the latter: the odometry glitched
  // (only with odometry at this scan and the one before). When the two predictions part so but
  // ICP converged within the bounds of the odometry's, ICP also runs from the previous step
  // repeated, and a result of it more than the bounds away is taken (kRecovered) when the
  // odometry's total over the last scans agrees better with it: a stale reading caught up. When
  // ICP from the prediction fails, the odometry's last step parts from the previous step repeated
  // and its total from the prediction, both beyond the bounds, ICP runs from the total first (a
  // late turn outside ICP's basin), and the search around the total follows the one around the
  // prediction. false: fall back at once.
  bool recovery_search = true;
  double recovery_window_translation_m = 0.5;
  double recovery_window_rotation_rad = 1.5707963268;  // 90 deg
  double recovery_step_translation_m = 0.1;
  double recovery_step_rotation_rad = 0.0174532925;  // 1 deg

  // A scan that becomes a key scan has its ICP pose (registered or recovered) refined against an
  // occupancy probability grid of the last 90 key scans (5 cm cells, hits and the free space of
  // their rays), as Cartographer's front end matches scans to submaps, and a recovered pose is
  // taken only where that grid supports it better than the pose it would replace
  // (docs/REGISTRATION.md, "Key scans refined on a probability grid").
  bool grid_refinement = true;
};

/// Throws std::invalid_argument naming the first invalid field (including icp.*).
void ValidateScanOdometryConfig(const ScanOdometryConfig& config);

enum class ScanOdometryStatus {
  kFirstScan,   // defines the world frame (= odometry frame at the first scan)
  kRegistered,  // ICP converged and was accepted
  // ICP failed from the prediction and converged from a searched pose or from the odometry's
  // total over the last scans (a late step), or converged beyond the bounds where the previous
  // step repeated says that the odometry glitched, or converged from the previous step repeated
  // where the odometry's total says its last step caught up
  kRecovered,
  kFallbackNotConverged,        // ICP did not converge: pose = odometry prediction
  kFallbackCorrectionTooLarge,  // ICP converged too far from the prediction: odometry used
  kFallbackTooFewPoints,        // scan or map too small for ICP: odometry used
  // ICP converged on far fewer of the scan's points than the recent scans' matches had (something
  // near the laser hides the map: a person) to a step the odometry contradicts beyond its recent
  // agreement with ICP: odometry used
  kFallbackWeakMatch,
};

std::string ToString(ScanOdometryStatus status);
/// True for kRegistered and kRecovered: the pose is ICP's, not the odometry's.
bool IsIcpPose(ScanOdometryStatus status);

struct ScanOdometryResult {
  std::size_t sequence = 0;  // 0-based order in which the scan was added
  double timestamp_s = 0.0;  // the scan's ipc timestamp, copied
  // Estimated robot pose in the world frame. World = the odometry frame of the first scan, so
  // T_world_robot of the first scan equals its odometry pose (identity without odometry).
  Pose2 T_world_robot;
  Pose2 T_world_laser;                      // T_world_robot * T_robot_laser
  Pose2 T_world_robot_odometry_prediction;  // the ICP initial guess, as a robot pose
  ScanOdometryStatus status = ScanOdometryStatus::kFirstScan;
  bool converged = false;   // true for kRegistered, kRecovered and kFirstScan
  bool fell_back = false;   // true for every kFallback* status
  bool degenerate = false;  // ICP's points left a direction unmeasured (IcpResult::degenerate)
  bool keyframe = false;    // the scan was added to the local map
  IcpStatus icp_status = IcpStatus::kTooFewPoints;
  int iterations = 0;
  double inlier_ratio = 0.0;
  double residual_rms_m = 0.0;
  double seconds = 0.0;  // wall time spent on this scan (filtering, ICP, map update)
};

class ScanOdometry {
 public:
  explicit ScanOdometry(const ScanOdometryConfig& config = {});
  ~ScanOdometry();
  ScanOdometry(const ScanOdometry&) = delete;
  ScanOdometry& operator=(const ScanOdometry&) = delete;

  /// Registers the next scan. The odometry increment since the previous scan initialises ICP;
  /// a scan without odometry (T_odom_robot empty) is predicted with zero motion.
  ScanOdometryResult Add(const LaserScan& scan, const std::optional<Pose2>& T_odom_robot);

  const ScanOdometryConfig& config() const { return config_; }
  std::size_t num_scans() const { return num_scans_; }
  std::size_t num_map_points() const { return map_points_.size(); }

  /// Endpoints of the scan's usable beams (range filter of the config), in the laser frame.
  static std::vector<Eigen::Vector2d> FilteredEndpoints(const LaserScan& scan,
                                                        const ScanOdometryConfig& config);
  /// Keeps a point when it is at least spacing_m from the last kept one (in order).
  static std::vector<Eigen::Vector2d> SubsampleBySpacing(const std::vector<Eigen::Vector2d>& points,
                                                         double spacing_m);

 private:
  void AddKeyframe(const std::vector<Eigen::Vector2d>& points_laser, const Pose2& T_world_laser);
  /// ICP from the best pose of the recovery search around `predicted_T_world_laser` (the
  /// odometry's prediction, or its total), when it converges close to that pose.
  std::optional<IcpResult> Recover(const std::vector<Eigen::Vector2d>& source_laser,
                                   const Pose2& predicted_T_world_laser) const;
  bool WithinCorrectionBounds(const Pose2& correction) const;
  /// ICP's result from the odometry's prediction matched few points (below a fraction of the
  /// recent matches' median inlier ratio) and parts from the prediction, per unit of the
  /// odometry's motion `odometry_step`, by many times the recent median (`agreement_window_`, the
  /// odometry's trust as measured online): a weak match that the trusted odometry contradicts.
  /// `correction`: ICP's pose in the predicted frame.
  bool WeakMatchContradictsOdometry(double inlier_ratio, const Pose2& correction,
                                    const Pose2& odometry_step) const;
  /// Adds a registered step to `agreement_window_`.
  void RecordAgreement(double inlier_ratio, const Pose2& correction, const Pose2& odometry_step);
  /// Whether a scan at `T_world_laser` with `status` joins the local map.
  bool WantsKeyframe(const Pose2& T_world_laser, ScanOdometryStatus status) const;
  /// The odometry's total over `odometry_window_` (not empty) applied to its oldest pose.
  Pose2 OdometryTotal(const Pose2& odometry_laser) const;
  /// The odometry's total over `odometry_window_` applied to its oldest pose, when the window is
  /// full and that parts from the prediction (the odometry's last step) beyond the correction
  /// bounds; nullopt otherwise.
  std::optional<Pose2> OdometryTotalDisputing(const Pose2& predicted_T_world_laser,
                                              const Pose2& odometry_laser) const;
  /// After ICP from the prediction failed: ICP from `total` (OdometryTotalDisputing), the search
  /// around the prediction, the search around `total`; the first that converges within the
  /// correction bounds of its start.
  std::optional<IcpResult> RecoverFrom(const std::vector<Eigen::Vector2d>& source,
                                       const Pose2& predicted_T_world_laser,
                                       const std::optional<Pose2>& total) const;
  /// ICP from the prediction, its checks and the recovery: the scan's pose (the prediction when
  /// it falls back), with the status and ICP figures written to `result`.
  /// `source`: the scan's points thinned by source_min_spacing_m. `odometry_step`: the
  /// odometry's increment since the previous scan (laser frame).
  Pose2 Register(const std::vector<Eigen::Vector2d>& source, const Pose2& predicted_T_world_laser,
                 const Pose2& odometry_step, const std::optional<Pose2>& disputing_motion,
                 const Pose2& odometry_laser, ScanOdometryResult& result) const;
  /// With the grid (grid_refinement): whether the scan's points at `candidate_T_world_laser` fit
  /// the grid better (lower mean correspondence cost) than at `alternative_T_world_laser`, the
  /// pose the scan would take otherwise. Without it: true.
  bool MapSupportsBetter(const std::vector<Eigen::Vector2d>& source,
                         const Pose2& candidate_T_world_laser,
                         const Pose2& alternative_T_world_laser) const;
  /// The previous ICP step repeated (constant velocity) when it parts from the odometry's
  /// prediction by more than the correction bounds (recovery on, odometry at this scan and the
  /// one before, the last scan converged); nullopt otherwise.
  std::optional<Pose2> DisputingMotion(const Pose2& predicted_T_world_laser,
                                       bool increment_measured) const;
  /// ICP converged within the correction bounds of the odometry's prediction, which parts from
  /// the constant-velocity one (`motion_T_world_laser`) beyond them. When ICP from the latter
  /// converges within its bounds too (the scan cannot tell the two apart: a corridor), returns that
  /// result if its motion over the scans in `odometry_window_` agrees better with the odometry's
  /// total over them (its translation: a stalled reading's error is where the robot is, not how it
  /// is turned), a result more than the correction bounds from the first and with a full window: a
  /// stale reading that catches up is right in total, not in its last step (docs/REGISTRATION.md,
  /// "Odometry that stalls, then catches up").
  std::optional<IcpResult> MotionBetterByOdometryTotal(const std::vector<Eigen::Vector2d>& source,
                                                       const Pose2& motion_T_world_laser,
                                                       const IcpResult& from_odometry,
                                                       const Pose2& odometry_laser) const;

  ScanOdometryConfig config_;
  std::size_t num_scans_ = 0;
  bool have_previous_odometry_ = false;
  // The previous scan had odometry: only then is the increment one step's measurement.
  bool previous_scan_had_odometry_ = false;
  Pose2 previous_odometry_laser_;  // T_odom_laser of the previous scan
  Pose2 previous_T_world_laser_;
  // The previous scan's step as ICP estimated it, in its predecessor's laser frame; only when
  // that scan converged (a fallback's step is the odometry's own).
  Pose2 previous_step_laser_;
  bool have_previous_icp_step_ = false;
  // The latest scans, each with odometry since the oldest: pose and odometry (laser frames).
  struct Past {
    Pose2 T_world_laser;
    Pose2 T_odom_laser;
  };
  std::deque<Past> odometry_window_;
  // The latest registered scans with odometry: the match's inlier ratio and how far ICP's step
  // parted from the odometry's per unit of motion (the odometry's trust, measured online).
  struct Agreement {
    double inlier_ratio = 0.0;
    double disagreement_per_motion = 0.0;
  };
  std::deque<Agreement> agreement_window_;
  Pose2 last_keyframe_T_world_laser_;
  struct Keyframe {
    std::vector<Eigen::Vector2d> points_world;  // endpoints, world frame
    PointNormals normals_world;                 // fitted within the scan, rotated to world
  };
  std::deque<Keyframe> keyframes_;
  std::vector<Eigen::Vector2d> map_points_;  // concatenation of the keyframes' points
  std::unique_ptr<IcpTarget> target_;        // over map_points_
  // The keyframes' occupancy (grid_refinement only).
  std::unique_ptr<ProbabilityGrid> grid_;
};

}  // namespace keyplace
