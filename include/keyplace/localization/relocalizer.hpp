#pragma once
// A localizer a robot can act on: the GlobalLocalizer's answers, one per query submap, turned
// into a fix only when they agree with each other through odometry, then a track that every
// later answer must confirm, and a "lost" signal when none does or a confident one contradicts
// it.
//
// Why agreement: two query submaps built from different scans are matched independently, so a
// wrong answer that happens to agree (within a metre, through odometry) with another wrong answer
// is far rarer than a single wrong answer, while correct answers agree by construction. Two
// identical rooms give ambiguous answers (never accepted); the fix comes when motion brings the
// robot somewhere that tells them apart.
//
//   keyplace::Relocalizer relocalizer(keyplace::LoadMap("site.kpm"));
//   for (each scan, odometry pose) {
//     const keyplace::RelocalizationUpdate update = relocalizer.AddScan(scan, T_odom_robot);
//     if (update.status == keyplace::FixStatus::kFixed) drive(update.T_world_robot);
//     if (update.lost) stop_and_search();
//   }

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"
#include "keyplace/features/flirt.hpp"
#include "keyplace/features/keypoint.hpp"
#include "keyplace/io/laser_scan.hpp"
#include "keyplace/localization/global_localizer.hpp"
#include "keyplace/localization/map_search.hpp"
#include "keyplace/localization/track_check.hpp"
#include "keyplace/mapping/global_map.hpp"

namespace keyplace {

enum class FixStatus {
  kSearching,  // no fix: answers are collected until enough of them agree
  kFixed,      // the pose is known and confirmed by the answers
  kLost,       // there was a fix, but the answers stopped confirming it: searching again
};
std::string ToString(FixStatus status);

/// The result of one scan.
struct RelocalizationUpdate {
  FixStatus status = FixStatus::kSearching;
  // A fix was declared with this scan: the first one, or a new one after a loss or after
  // confirmed contradicting answers.
  bool new_fix = false;
  // The fix was given up with this scan (status is kLost or, when answers already agree on
  // another pose, kFixed with new_fix).
  bool lost = false;
  // Valid when status is kFixed: the robot's pose in the map now, the map <- odometry transform,
  // and the confidence of the fix (1 - product of (1 - confidence) of the agreeing answers).
  Pose2 T_world_robot;
  Pose2 T_world_odom;
  double confidence = 0.0;
  // Odometry distance since the last answer that confirmed the fix (0 without a fix).
  double unconfirmed_m = 0.0;
  // Valid when status is kFixed: the variance of the fix's position (each of x and y; isotropic)
  // and heading, as the filter weighs answers against odometry drift (docs/LOCALIZATION.md).
  double position_variance_m2 = 0.0;
  double heading_variance_rad2 = 0.0;
  // Valid when status is kFixed: the covariance of T_world_robot over its (x, y, theta), derived
  // from the matches (PlaceMatch::estimated_pose_covariance of the answer that made the fix,
  // fused as the filter fuses the confirming answers, carried to the robot's pose now through
  // odometry) plus the same drift allowance as the variances above, plus the map's own error
  // (FixPolicy::map_sigma_m, map_sigma_deg). What /initialpose gets.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  // The localizer's answer when a query submap completed with this scan.
  std::optional<LocalizationResult> answer;
  // The answer of a search of the whole map taken with this scan (LocalizerConfig::
  // map_search_window_m; submap_id -1, an empty match), judged after `answer`; dropped (none
  // here) when `answer` made a fix.
  std::optional<LocalizationResult> map_search_answer;
  // The answer (accepted, or weak: LocalizationResult::weak_T_world_odom) agreed with the fix
  // (confirmation) or contradicted it.
  bool confirmed = false;
  bool contradicted = false;
  // The answer came from a query whose accepted answers disagree with each other (it sees a
  // place that looks like another); it and the query's other answers were set aside.
  bool self_contradicted = false;
  // The track was checked against the map with this scan (FixPolicy::track_check_every_m):
  // kUnknown when it was not, or when the map has too little around the robot to tell.
  TrackFit track_fit = TrackFit::kUnknown;
  // The fix was given up (lost) because the track check found the scans off the map.
  bool track_misfit = false;
};

/// The temporal part alone: turns a stream of answers (most scans have none) into fixes,
/// confirmations and losses. Relocalizer feeds it the GlobalLocalizer's answers; tests
/// and other front ends can feed it their own.
class FixFilter {
 public:
  /// Throws std::invalid_argument for an invalid policy (naming the field).
  explicit FixFilter(const FixPolicy& policy = {});

  /// The next scan: its odometry pose and the answer that came with it, if any. A scan with two
  /// answers (the Relocalizer's keypoints and search) is two calls with the same pose: the
  /// second adds no odometry.
  RelocalizationUpdate Update(std::optional<LocalizationResult> answer, const Pose2& T_odom_robot);

  void Reset();
  FixStatus status() const { return status_; }

  /// Where the answers held put the odometry frame in the map (map <- odometry): the fix's while
  /// fixed, and every pending or challenging answer's not older than window_m, in the order
  /// held.
  std::vector<Pose2> Beliefs() const;

  /// Gives the fix up, as an answer contradicting it would (update: the one of this scan, which
  /// becomes kLost without a pose). No effect without a fix.
  void GiveUp(RelocalizationUpdate& update);

 private:
  // An accepted answer, kept as a hypothesis of T_world_odom.
  struct Hypothesis {
    Pose2 T_world_odom;
    double confidence = 0.0;
    double odometry_m = 0.0;  // odometry distance when it was given
    // Covariance of the robot's pose in the map at T_odom_robot, from the match.
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    Pose2 T_odom_robot;
    long long query_id = -1;           // LocalizationResult::query_id
    bool weak = false;                 // a weak answer (LocalizationResult::weak_T_world_odom)
    long long window_first_scan = -1;  // LocalizationResult::window_first_scan, window_last_scan
    long long window_last_scan = -1;
  };
  // The hypothesis an answer names: its accepted match, or else its weak answer.
  Hypothesis HypothesisOf(const LocalizationResult& answer, const Pose2& T_odom_robot) const;

  void Search(const Hypothesis& hypothesis, const Pose2& T_odom_robot,
              RelocalizationUpdate& update);
  void Track(const Hypothesis& hypothesis, const Pose2& T_odom_robot, RelocalizationUpdate& update);
  // Whether `latest` and the hypotheses agreeing with it are enough for a fix.
  bool Enough(const std::vector<Hypothesis>& agreeing, const Hypothesis& latest) const;
  // Whether two hypotheses name the same robot pose now, within the policy's tolerances.
  bool Agree(const Hypothesis& a, const Hypothesis& b, const Pose2& T_odom_robot) const;
  // Both are answers of searches of the whole map whose windows share more than one scan: the
  // same beams, not two looks.
  static bool ShareSearchedScans(const Hypothesis& a, const Hypothesis& b);
  // What an answer does to the earlier answers of its query in the pools.
  enum class OwnQuery {
    kReplaces,      // they are dropped; the answer counts in their place
    kKeepsEarlier,  // they stay; the answer adds nothing (it names nothing, or upholds them)
    kSetAside,      // the query contradicts itself: nothing it says counts any more
  };
  OwnQuery JudgeOwnQuery(const LocalizationResult& answer, const Pose2& T_odom_robot);
  // A weak answer agrees with an accepted, not forgotten answer of its query held in the pools.
  bool UpholdsItsAcceptedAnswer(const LocalizationResult& weak_answer,
                                const Pose2& T_odom_robot) const;
  // The hypotheses in `pool` that agree with `hypothesis` at the robot's current pose and come
  // from another query (answers of one query share its scans: their agreement proves nothing).
  std::vector<Hypothesis> Agreeing(const std::vector<Hypothesis>& pool,
                                   const Hypothesis& hypothesis, const Pose2& T_odom_robot) const;
  void Forget(std::vector<Hypothesis>& pool) const;    // drops the Forgotten ones
  bool Forgotten(const Hypothesis& hypothesis) const;  // older than window_m
  void Confirm(const Hypothesis& answer, const Pose2& T_odom_robot);
  void DeclareFix(const std::vector<Hypothesis>& agreeing, const Hypothesis& latest,
                  RelocalizationUpdate& update);
  void DeclareLost(RelocalizationUpdate& update);
  // fix_covariance_ carried to the robot's odometry pose T_odom_robot, plus the drift allowance.
  Eigen::Matrix3d FixCovarianceAt(const Pose2& T_odom_robot) const;
  double DriftVarianceM2() const;
  double HeadingVarianceFor(double position_variance_m2) const;

  FixPolicy policy_;
  FixStatus status_ = FixStatus::kSearching;
  std::optional<Pose2> last_T_odom_robot_;
  double odometry_m_ = 0.0;
  std::vector<Hypothesis> hypotheses_;   // accepted answers while searching
  std::vector<Hypothesis> challengers_;  // accepted answers contradicting the fix
  long long self_contradicted_query_ = -1;
  Pose2 T_world_odom_;  // the fix
  double fix_confidence_ = 0.0;
  bool fix_weak_ = false;  // made by weak answers alone and confirmed by no accepted one since
  double fix_variance_m2_ = 0.0;  // of the fix's position at its last confirmation
  double confirmed_at_m_ = 0.0;   // odometry distance of the last confirmation
  // Covariance of the fix (robot pose in the map) at odometry pose fix_covariance_at_, at the last
  // confirmation, derived from the matches.
  Eigen::Matrix3d fix_covariance_ = Eigen::Matrix3d::Zero();
  Pose2 fix_covariance_at_;
};

/// A copy shares the map's place recognizer (read-only; safe from several threads) and has its own
/// query and fix: one Relocalizer per thread or per robot costs no rebuild of the index.
class Relocalizer {
 public:
  /// Throws std::invalid_argument for an invalid config (naming the field).
  explicit Relocalizer(const GlobalMap& map, const LocalizerConfig& config = {},
                       const FlirtConfig& features = {});

  /// Adds the next scan with the robot's pose in its odometry frame.
  RelocalizationUpdate AddScan(const LaserScan& scan, const Pose2& T_odom_robot);

  /// The same with the scan's keypoints already extracted (laser frame) and the caller's id of the
  /// scan (for the exclusion of GlobalLocalizer::set_exclusion).
  RelocalizationUpdate AddScan(const LaserScan& scan, const Pose2& T_odom_robot,
                               std::vector<Keypoint> keypoints, int scan_id = -1);

  /// Forgets everything: fix, hypotheses and the query being built (the robot was kidnapped).
  void Reset();

  void set_exclusion(QueryExclusion exclusion) { localizer_.set_exclusion(std::move(exclusion)); }
  /// Searches of the whole map (LocalizerConfig::map_search_window_m) run on a thread of their
  /// own and answer with the first scan after they end (a robot's node: its scans are not held
  /// up by a search of a large map), or before AddScan returns (the default: a replay's answers
  /// then depend on its scans alone, not on the machine's speed).
  void set_background_search(bool background) { map_search_.set_background(background); }
  FixStatus status() const { return filter_.status(); }
  const GlobalLocalizer& localizer() const { return localizer_; }
  const MapSearch& map_search() const { return map_search_; }

 private:
  // The beams the track check needs (none when it is off).
  void RememberForTrackCheck(const LaserScan& scan, const Pose2& T_odom_robot, int scan_id);
  // The track check of FixPolicy::track_check_every_m, on `update` of the scan just added.
  void CheckTrack(const Pose2& T_odom_robot, RelocalizationUpdate& update);
  // The answer of a search of the whole map taken with this scan, when the filter has no fix
  // (MapSearch::Search: one is due, or one running in the background ended); a fix stops a
  // running search.
  std::optional<LocalizationResult> MapSearchAnswer();
  // The filter's update with the localizer's answer of this scan and then the search's, checked.
  RelocalizationUpdate Update(std::optional<LocalizationResult> localizer_answer,
                              const Pose2& T_odom_robot);

  GlobalLocalizer localizer_;
  FixFilter filter_;
  TrackCheck track_;
  MapSearch map_search_;
  std::optional<Pose2> last_T_odom_robot_;
  double since_check_m_ = 0.0;  // odometry since the fix or its last check
};

}  // namespace keyplace
