#pragma once
// Whether a fix still fits the map. Answers confirm a fix only now and then (every few metres in
// a corridor, rarely in a hall), and between them the fix is carried by odometry alone: a wheel
// glitch or a turn faster than the odometry saw puts the robot metres or tens of degrees off
// while the fix still claims the confidence of its answers. The scans the robot has now say so
// at once: put into the map by the fix, their beams must end on the walls of the submaps around
// the robot and must not pass through them. This is the dense check of place recognition
// (place/dense_check.hpp, docs/PLACE.md) applied to the track, with its thresholds.

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/io/laser_scan.hpp"
#include "keyplace/localization/global_localizer.hpp"
#include "keyplace/place/dense_check.hpp"
#include "keyplace/place/place_config.hpp"
#include "keyplace/place/place_recognizer.hpp"

namespace keyplace {

enum class TrackFit {
  // Nothing to tell: too few beams fall where the map looked (no map here, too few scans), or
  // they miss its walls but so they do at every pose nearby (the map did not see this).
  kUnknown,
  kFits,    // the beams end on the map's walls (place recognition's dense veto passes)
  kMisfit,  // a fix turned from this one, found by the last check, fits the latest scans far better
};

std::string ToString(TrackFit fit);  // "unknown", "fits", "misfit"

struct TrackCheckResult {
  TrackFit fit = TrackFit::kUnknown;
  DenseScore score;  // at the fix
  int places = 0;    // map places whose occupancy made the reference
  // The hit fraction of the latest 3 scans at the fix (every 2nd endpoint); when the fix did not
  // fit beyond doubt, the best of the last check's suspect, if there was one, and of the poses
  // searched around the fix (the robot turned by up to 45 degrees, shifted by up to 0.8 m) that
  // could make a suspect, with the fix that gives it (0 and the fix itself when none could).
  double latest_hit_fraction = 0.0;
  double best_hit_fraction = 0.0;
  Pose2 T_world_odom_best;
};

/// Keeps the beams of the robot's latest scans (kDenseQueryScans) with their odometry poses and
/// scores them against the map at a fix.
class TrackCheck {
 public:
  /// A misfit must also turn the robot by more than `misfit_turn_deg` (two answers that differ by
  /// less agree: FixPolicy::agree_deg): what odometry gets wrong in a fast turn is the heading, and
  /// a shift below a metre that fits a few scans better may be a corridor's own look-alike.
  explicit TrackCheck(double misfit_turn_deg = 10.0);

  /// Adds the latest scan and the robot's odometry pose at it (and the caller's scan id, for the
  /// exclusion).
  void AddScan(const LaserScan& scan, const Pose2& T_odom_robot, int scan_id);

  /// The recent scans put into the map by T_world_odom, scored against the occupancy of the map
  /// places nearest the robot (those `exclusion` allows for the recent scans' ids), judged by
  /// `place`'s dense thresholds. When the best of the poses searched around the fix is turned
  /// from it by more than misfit_turn_deg and puts the latest scans on the walls beyond doubt
  /// (dense_sure_hit_fraction) and 0.3 (dense_sure_hit_fraction - dense_min_hit_fraction) better
  /// than the fix, it becomes a suspect; the next check is a misfit when the suspect does so again
  /// with that check's latest scans. Otherwise the fix fits when the recent scans pass the veto
  /// (dense_min_hit_fraction); kUnknown when they do not.
  TrackCheckResult Check(const PlaceRecognizer& recognizer, const PlaceRecognitionConfig& place,
                         const Pose2& T_world_odom, const QueryExclusion& exclusion);

  void Reset() {
    scans_.clear();
    suspect_T_world_odom_.reset();
  }

 private:
  struct RecentScan {
    Pose2 T_odom_robot;
    QueryScanPoints points;  // robot frame
    int scan_id = -1;
  };
  void Judge(const DenseReference& reference, const std::vector<QueryScanPoints>& latest,
             const Eigen::Vector2d& robot_m, const PlaceRecognitionConfig& place,
             const Pose2& T_world_odom, TrackCheckResult& result);

  double misfit_turn_rad_ = 0.0;
  std::deque<RecentScan> scans_;
  // The fix a check's search preferred (a misfit if the next check's scans confirm it).
  std::optional<Pose2> suspect_T_world_odom_;
};

}  // namespace keyplace
