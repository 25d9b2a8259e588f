#include "keyplace/localization/relocalizer.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

namespace keyplace {
namespace {

constexpr double kRadPerDeg = M_PI / 180.0;

// 1 - prod(1 - c): the chance that not all of independent answers are wrong.
double CombinedConfidence(const std::vector<double>& confidences) {
  double all_wrong = 1.0;
  for (const double confidence : confidences) all_wrong *= 1.0 - std::clamp(confidence, 0.0, 1.0);
  return 1.0 - all_wrong;
}

}  // namespace

std::string ToString(FixStatus status) {
  switch (status) {
    case FixStatus::kSearching:
      return "searching";
    case FixStatus::kFixed:
      return "fixed";
    case FixStatus::kLost:
      return "lost";
  }
  return "?";
}

Relocalizer::Relocalizer(const GlobalMap& map, const LocalizerConfig& config,
                         const FlirtConfig& features)
    : localizer_(map, config, features),
      filter_(config.fix),
      track_(config.fix.agree_deg),
      map_search_(config.map_search_window_m, config.map_search_every_m, config.map_search_margin) {
}

RelocalizationUpdate Relocalizer::AddScan(const LaserScan& scan, const Pose2& T_odom_robot) {
  RememberForTrackCheck(scan, T_odom_robot, -1);
  map_search_.AddScan(scan, T_odom_robot, -1);
  localizer_.set_beliefs(filter_.Beliefs(), filter_.status() == FixStatus::kFixed);
  return Update(localizer_.AddScan(scan, T_odom_robot), T_odom_robot);
}

RelocalizationUpdate Relocalizer::AddScan(const LaserScan& scan, const Pose2& T_odom_robot,
                                          std::vector<Keypoint> keypoints, int scan_id) {
  RememberForTrackCheck(scan, T_odom_robot, scan_id);
  map_search_.AddScan(scan, T_odom_robot, scan_id);
  localizer_.set_beliefs(filter_.Beliefs(), filter_.status() == FixStatus::kFixed);
  return Update(localizer_.AddScan(scan, T_odom_robot, std::move(keypoints), scan_id),
                T_odom_robot);
}

RelocalizationUpdate Relocalizer::Update(std::optional<LocalizationResult> localizer_answer,
                                         const Pose2& T_odom_robot) {
  std::optional<LocalizationResult> searched = MapSearchAnswer();
  RelocalizationUpdate update = filter_.Update(std::move(localizer_answer), T_odom_robot);
  if (searched && update.status != FixStatus::kFixed) {
    // Judged after the localizer's answer of the same scan, with no motion between them: an
    // answer of the search waiting for a scan without one cost about a metre in fhw.
    RelocalizationUpdate after = filter_.Update(std::move(searched), T_odom_robot);
    after.map_search_answer = std::move(after.answer);
    after.answer = std::move(update.answer);
    after.self_contradicted = update.self_contradicted;
    update = std::move(after);
  }
  CheckTrack(T_odom_robot, update);
  return update;
}

std::optional<LocalizationResult> Relocalizer::MapSearchAnswer() {
  if (filter_.status() == FixStatus::kFixed) {
    map_search_.Cancel();
    return std::nullopt;
  }
  return map_search_.Search(localizer_.recognizer(), localizer_.exclusion());
}

void Relocalizer::Reset() {
  localizer_.Reset();
  filter_.Reset();
  track_.Reset();
  map_search_.Reset();
  last_T_odom_robot_.reset();
  since_check_m_ = 0.0;
}

void Relocalizer::RememberForTrackCheck(const LaserScan& scan, const Pose2& T_odom_robot,
                                        int scan_id) {
  if (localizer_.config().fix.track_check_every_m > 0.0) {
    track_.AddScan(scan, T_odom_robot, scan_id);
  }
}

// A new fix passed the dense check of its answers: the first check comes a check distance later.
// An answer confirming the fix does not spare it the check: answers come from query submaps that
// may straddle an odometry error.
void Relocalizer::CheckTrack(const Pose2& T_odom_robot, RelocalizationUpdate& update) {
  const FixPolicy& policy = localizer_.config().fix;
  if (last_T_odom_robot_) {
    since_check_m_ += TranslationNorm(Between(*last_T_odom_robot_, T_odom_robot));
  }
  last_T_odom_robot_ = T_odom_robot;
  if (update.status != FixStatus::kFixed || update.new_fix) {
    since_check_m_ = 0.0;
    return;
  }
  if (policy.track_check_every_m <= 0.0 || since_check_m_ < policy.track_check_every_m) return;
  since_check_m_ = 0.0;
  const TrackCheckResult check = track_.Check(localizer_.recognizer(), localizer_.config().place,
                                              update.T_world_odom, localizer_.exclusion());
  update.track_fit = check.fit;
  if (check.fit != TrackFit::kMisfit) return;
  // The odometry, not the map, went wrong: the query being built spans the error too, and its
  // answers would put the robot where the error did.
  localizer_.Reset();
  map_search_.Reset();
  filter_.GiveUp(update);
  update.track_misfit = true;
}

FixFilter::FixFilter(const FixPolicy& policy) : policy_(policy) { Validate(policy_); }

std::vector<Pose2> FixFilter::Beliefs() const {
  std::vector<Pose2> beliefs;
  if (status_ == FixStatus::kFixed) beliefs.push_back(T_world_odom_);
  // The pools are pruned when an answer comes; one older than the window is already forgotten.
  for (const std::vector<Hypothesis>* pool : {&hypotheses_, &challengers_}) {
    for (const Hypothesis& hypothesis : *pool) {
      if (!Forgotten(hypothesis)) beliefs.push_back(hypothesis.T_world_odom);
    }
  }
  return beliefs;
}

void FixFilter::Reset() {
  status_ = FixStatus::kSearching;
  last_T_odom_robot_.reset();
  self_contradicted_query_ = -1;
  odometry_m_ = 0.0;
  hypotheses_.clear();
  challengers_.clear();
  fix_confidence_ = 0.0;
  fix_weak_ = false;
  fix_variance_m2_ = 0.0;
  confirmed_at_m_ = 0.0;
  fix_covariance_.setZero();
  fix_covariance_at_ = Pose2();
}

RelocalizationUpdate FixFilter::Update(std::optional<LocalizationResult> answer,
                                       const Pose2& T_odom_robot) {
  if (last_T_odom_robot_) {
    odometry_m_ += TranslationNorm(Between(*last_T_odom_robot_, T_odom_robot));
  }
  last_T_odom_robot_ = T_odom_robot;

  RelocalizationUpdate update;
  const OwnQuery own = answer ? JudgeOwnQuery(*answer, T_odom_robot) : OwnQuery::kKeepsEarlier;
  if (own == OwnQuery::kSetAside) {
    update.self_contradicted = true;
  } else if (own == OwnQuery::kReplaces && (answer->found || answer->weak_T_world_odom)) {
    const Hypothesis hypothesis = HypothesisOf(*answer, T_odom_robot);
    if (status_ == FixStatus::kFixed) {
      Track(hypothesis, T_odom_robot, update);
    } else {
      Search(hypothesis, T_odom_robot, update);
    }
  }
  if (status_ == FixStatus::kFixed && odometry_m_ - confirmed_at_m_ > policy_.lost_after_m) {
    DeclareLost(update);
  }
  update.answer = std::move(answer);
  update.status = status_;
  if (status_ == FixStatus::kFixed) {
    update.T_world_odom = T_world_odom_;
    update.T_world_robot = T_world_odom_ * T_odom_robot;
    update.confidence = fix_confidence_;
    update.unconfirmed_m = odometry_m_ - confirmed_at_m_;
    // The filter's own uncertainty now: the fix's variance plus the drift allowance since its
    // last confirmation.
    update.position_variance_m2 = fix_variance_m2_ + DriftVarianceM2();
    update.heading_variance_rad2 = HeadingVarianceFor(update.position_variance_m2);
    // The matches' covariance, carried here, plus the map's own error (not fused away: every
    // answer in one place shares it).
    update.covariance = FixCovarianceAt(T_odom_robot);
    const double map_sigma_rad = policy_.map_sigma_deg * kRadPerDeg;
    update.covariance(0, 0) += policy_.map_sigma_m * policy_.map_sigma_m;
    update.covariance(1, 1) += policy_.map_sigma_m * policy_.map_sigma_m;
    update.covariance(2, 2) += map_sigma_rad * map_sigma_rad;
  }
  return update;
}

FixFilter::Hypothesis FixFilter::HypothesisOf(const LocalizationResult& answer,
                                              const Pose2& T_odom_robot) const {
  if (answer.found) {
    Hypothesis hypothesis{answer.T_world_odom, answer.confidence,
                          odometry_m_,         answer.match.estimated_pose_covariance,
                          T_odom_robot,        answer.query_id};
    hypothesis.window_first_scan = answer.window_first_scan;
    hypothesis.window_last_scan = answer.window_last_scan;
    return hypothesis;
  }
  // Zero only for results built by hand (the localizer sets both): the fix then claims the
  // filter's own variances alone.
  const Eigen::Matrix3d covariance = answer.match.weak
                                         ? answer.match.weak->estimated_pose_covariance
                                         : Eigen::Matrix3d::Zero().eval();
  return {*answer.weak_T_world_odom,
          answer.match.weak_confidence,
          odometry_m_,
          covariance,
          T_odom_robot,
          answer.query_id,
          true};
}

// The fix's covariance holds at the robot's pose of its last confirmation; the robot has moved
// by odometry since. Odometry taken as exact, a heading error d_theta of the fix moves the robot
// now by d_theta times its displacement turned by 90 degrees (the lever arm); odometry's own
// drift adds the allowance of the variances, (agree_per_m * distance)^2 per position coordinate
// and the heading's share of it scaled as there.
Eigen::Matrix3d FixFilter::FixCovarianceAt(const Pose2& T_odom_robot) const {
  const Eigen::Vector2d moved_m = (T_world_odom_ * T_odom_robot).translation() -
                                  (T_world_odom_ * fix_covariance_at_).translation();
  Eigen::Matrix3d jacobian = Eigen::Matrix3d::Identity();
  jacobian(0, 2) = -moved_m.y();
  jacobian(1, 2) = moved_m.x();
  Eigen::Matrix3d covariance = jacobian * fix_covariance_ * jacobian.transpose();
  const double drift_m2 = DriftVarianceM2();
  covariance(0, 0) += drift_m2;
  covariance(1, 1) += drift_m2;
  covariance(2, 2) += HeadingVarianceFor(drift_m2);
  return covariance;
}

// The drift allowance since the last confirmation, (agree_per_m * distance)^2 per position
// coordinate.
double FixFilter::DriftVarianceM2() const {
  const double drift_m = policy_.agree_per_m * (odometry_m_ - confirmed_at_m_);
  return drift_m * drift_m;
}

// Heading is fused with the same weights as position (Confirm), so a position variance comes
// with the answers' heading variance (agree_deg / 2, one sigma) scaled as their position
// variance (agree_m / 2).
double FixFilter::HeadingVarianceFor(double position_variance_m2) const {
  const double heading_per_position = (policy_.agree_deg * kRadPerDeg) / policy_.agree_m;
  return position_variance_m2 * heading_per_position * heading_per_position;
}

void FixFilter::Search(const Hypothesis& hypothesis, const Pose2& T_odom_robot,
                       RelocalizationUpdate& update) {
  Forget(hypotheses_);
  const std::vector<Hypothesis> agreeing = Agreeing(hypotheses_, hypothesis, T_odom_robot);
  if (Enough(agreeing, hypothesis)) {
    DeclareFix(agreeing, hypothesis, update);
  } else {
    hypotheses_.push_back(hypothesis);
  }
}

void FixFilter::Track(const Hypothesis& hypothesis, const Pose2& T_odom_robot,
                      RelocalizationUpdate& update) {
  Hypothesis fix{T_world_odom_, fix_confidence_, confirmed_at_m_, FixCovarianceAt(T_odom_robot),
                 T_odom_robot};
  // After a confident contradiction the fix stays a hypothesis: one of weak answers alone
  // counts as weak again.
  fix.weak = fix_weak_;
  // A weak answer that agrees confirms the fix even from the spot of the last confirmation: the
  // fix was made by answers that agreed, and a confirmation only averages within the agreement.
  if (Agree(fix, hypothesis, T_odom_robot)) {
    Confirm(hypothesis, T_odom_robot);
    update.confirmed = true;
    return;
  }
  update.contradicted = true;
  // A weak answer does not challenge a fix: along a corridor with doors at regular spacing weak
  // answers from several looks agreed on one pose 8.4 m off (belgioioso).
  if (hypothesis.weak) return;
  Forget(challengers_);
  const std::vector<Hypothesis> agreeing = Agreeing(challengers_, hypothesis, T_odom_robot);
  if (Enough(agreeing, hypothesis)) {
    DeclareLost(update);
    DeclareFix(agreeing, hypothesis, update);
  } else if (hypothesis.confidence >= policy_.contradiction_confidence) {
    // Either may be right: one more answer agreeing with the old fix restores it.
    DeclareLost(update);
    hypotheses_ = {fix, hypothesis};
  } else {
    challengers_.push_back(hypothesis);
  }
}

// The fix and the answer are two estimates of the robot's pose now: the fix carries the odometry
// drift since its last confirmation, the answer its own error (agree_m / 2, one sigma). Their
// weighted mean is the new fix; its variance never falls below that of four answers, so odometry
// that drifts more than agree_per_m allows is still pulled back by the answers. The covariance
// derived from the matches follows the same fusion: the new fix is (1 - w) fix + w answer, so for
// independent errors its covariance is (1 - w)^2 C_fix + w^2 C_answer (whatever w is).
void FixFilter::Confirm(const Hypothesis& answer, const Pose2& T_odom_robot) {
  const double answer_variance = 0.25 * policy_.agree_m * policy_.agree_m;
  const double drift_m = policy_.agree_per_m * (odometry_m_ - confirmed_at_m_);
  const double fix_variance = fix_variance_m2_ + drift_m * drift_m;
  const double weight = fix_variance / (fix_variance + answer_variance);
  const Pose2 fix_now = T_world_odom_ * T_odom_robot;
  const Pose2 answer_now = answer.T_world_odom * T_odom_robot;
  fix_covariance_ = (1.0 - weight) * (1.0 - weight) * FixCovarianceAt(T_odom_robot) +
                    weight * weight * answer.covariance;
  fix_covariance_at_ = T_odom_robot;
  const Pose2 fused(fix_now.x + weight * (answer_now.x - fix_now.x),
                    fix_now.y + weight * (answer_now.y - fix_now.y),
                    fix_now.theta + weight * WrapAngle(answer_now.theta - fix_now.theta));
  T_world_odom_ = fused * T_odom_robot.inverse();
  fix_variance_m2_ = std::max(fix_variance * answer_variance / (fix_variance + answer_variance),
                              answer_variance / 4.0);
  fix_confidence_ = CombinedConfidence({fix_confidence_, answer.confidence});
  fix_weak_ = fix_weak_ && answer.weak;
  confirmed_at_m_ = odometry_m_;
  challengers_.clear();
}

// `confirmations` agreeing answers make a fix when one of them is accepted. Weak answers alone
// need more looks, spread along the path (FixPolicy::weak_fix_*): in the time split of Intel (map
// of the first half, starts in the second) weak answers from several looks agreed on rooms
// turned by 90 degrees (the lab's rooms look alike): two of them made 508 wrong fixes of 2270,
// three over a span of 3 m 443 of 2262.
bool FixFilter::Enough(const std::vector<Hypothesis>& agreeing, const Hypothesis& latest) const {
  const auto accepted = [](const Hypothesis& h) { return !h.weak; };
  const bool any_accepted =
      accepted(latest) || std::any_of(agreeing.begin(), agreeing.end(), accepted);
  if (any_accepted && static_cast<int>(agreeing.size()) + 1 >= policy_.confirmations) return true;
  if (policy_.weak_fix_answers == 0) return false;
  // Looks: answers more than agree_m of odometry after the previous look (Agreeing keeps each
  // that far from the latest only; two answers from nearly one spot are one look).
  std::vector<double> at_m{latest.odometry_m};
  for (const Hypothesis& h : agreeing) at_m.push_back(h.odometry_m);
  std::sort(at_m.begin(), at_m.end());
  int looks = 1;
  double look_m = at_m.front();
  for (const double m : at_m) {
    if (m - look_m <= policy_.agree_m) continue;
    ++looks;
    look_m = m;
  }
  return looks >= policy_.weak_fix_answers && at_m.back() - at_m.front() >= policy_.weak_fix_span_m;
}

// Searches a metre apart over windows of up to 5 m see nearly the same beams: in the time split of
// belgioioso, where most of the drive is off the map, pairs of them agreeing on a wrong pose made
// 312 of 644 fixes wrong. Windows a whole window apart share their boundary scan only.
bool FixFilter::ShareSearchedScans(const Hypothesis& a, const Hypothesis& b) {
  if (a.window_last_scan < 0 || b.window_last_scan < 0) return false;
  return std::max(a.window_first_scan, b.window_first_scan) <
         std::min(a.window_last_scan, b.window_last_scan);
}

bool FixFilter::Agree(const Hypothesis& a, const Hypothesis& b, const Pose2& T_odom_robot) const {
  const Pose2 difference = Between(b.T_world_odom * T_odom_robot, a.T_world_odom * T_odom_robot);
  const double travelled_m = std::abs(a.odometry_m - b.odometry_m);
  const double tolerance_m = policy_.agree_m + policy_.agree_per_m * travelled_m;
  return TranslationNorm(difference) <= tolerance_m &&
         std::abs(difference.theta) <= policy_.agree_deg * kRadPerDeg;
}

std::vector<FixFilter::Hypothesis> FixFilter::Agreeing(const std::vector<Hypothesis>& pool,
                                                       const Hypothesis& hypothesis,
                                                       const Pose2& T_odom_robot) const {
  std::vector<Hypothesis> agreeing;
  for (const Hypothesis& other : pool) {
    if (hypothesis.query_id >= 0 && other.query_id == hypothesis.query_id) continue;
    if (ShareSearchedScans(hypothesis, other)) continue;
    // Two looks from nearly one spot are one look: a weak answer counts with another only when
    // the robot moved farther than agree_m between them (Intel: turning on the spot, the robot
    // saw one look-alike room in three queries over 0.7 m, one of them accepted).
    const bool weak = hypothesis.weak || other.weak;
    if (weak && std::abs(hypothesis.odometry_m - other.odometry_m) <= policy_.agree_m) continue;
    if (Agree(hypothesis, other, T_odom_robot)) agreeing.push_back(other);
  }
  return agreeing;
}

// A query that grows (LocalizerConfig::query_every_m) answers several times; a newer answer
// that says something replaces its older ones as evidence (an ambiguous one withdraws them). A
// newer answer that says nothing, neither accepted, weak nor ambiguous, takes nothing back: the
// scans added since may only cover ground the place lacks; in open halls a query grows over up
// to max_path_m (8 m) and is mostly silent, and withdrawing on silence kept 7 of acapulco's 23
// starts with a revisit from a fix. A weak answer that agrees with the query's accepted one (not
// yet forgotten) leaves that in place too: the added scans lowered gamma or the coverage, not the
// pose (replaced by the weak one, an accepted answer of acapulco (a) no longer seconded the next
// query's weak answer 16 m on). A query whose accepted answers name places that disagree is
// itself ambiguous: two look-alike rooms seen from part of one of them. Nothing it says counts
// any more.
FixFilter::OwnQuery FixFilter::JudgeOwnQuery(const LocalizationResult& answer,
                                             const Pose2& T_odom_robot) {
  if (answer.query_id < 0) return OwnQuery::kReplaces;
  if (answer.query_id == self_contradicted_query_) return OwnQuery::kSetAside;
  const bool ambiguous = answer.ambiguous || answer.match.weak_ambiguous;
  if (!answer.found && !ambiguous &&
      (!answer.weak_T_world_odom || UpholdsItsAcceptedAnswer(answer, T_odom_robot))) {
    return OwnQuery::kKeepsEarlier;  // silence, or a weak answer that upholds the accepted one
  }
  const Hypothesis latest{answer.T_world_odom, answer.confidence, odometry_m_, {},
                          T_odom_robot,        answer.query_id};
  bool contradicted = false;
  for (std::vector<Hypothesis>* pool : {&hypotheses_, &challengers_}) {
    for (const Hypothesis& earlier : *pool) {
      if (earlier.query_id != answer.query_id) continue;
      if (answer.found && !earlier.weak && !Agree(latest, earlier, T_odom_robot)) {
        contradicted = true;
      }
    }
    pool->erase(std::remove_if(pool->begin(), pool->end(),
                               [&](const Hypothesis& h) { return h.query_id == answer.query_id; }),
                pool->end());
  }
  if (contradicted) self_contradicted_query_ = answer.query_id;
  return contradicted ? OwnQuery::kSetAside : OwnQuery::kReplaces;
}

bool FixFilter::UpholdsItsAcceptedAnswer(const LocalizationResult& weak_answer,
                                         const Pose2& T_odom_robot) const {
  const Hypothesis weak = HypothesisOf(weak_answer, T_odom_robot);
  for (const std::vector<Hypothesis>* pool : {&hypotheses_, &challengers_}) {
    for (const Hypothesis& earlier : *pool) {
      if (earlier.query_id == weak.query_id && !earlier.weak && !Forgotten(earlier) &&
          Agree(weak, earlier, T_odom_robot)) {
        return true;
      }
    }
  }
  return false;
}

bool FixFilter::Forgotten(const Hypothesis& hypothesis) const {
  return odometry_m_ - hypothesis.odometry_m > policy_.window_m;
}

void FixFilter::Forget(std::vector<Hypothesis>& pool) const {
  pool.erase(std::remove_if(pool.begin(), pool.end(),
                            [this](const Hypothesis& h) { return Forgotten(h); }),
             pool.end());
}

void FixFilter::DeclareFix(const std::vector<Hypothesis>& agreeing, const Hypothesis& latest,
                           RelocalizationUpdate& update) {
  std::vector<double> confidences{latest.confidence};
  for (const Hypothesis& h : agreeing) confidences.push_back(h.confidence);
  status_ = FixStatus::kFixed;
  T_world_odom_ = latest.T_world_odom;  // the newest answer carries the least odometry drift
  fix_variance_m2_ = 0.25 * policy_.agree_m * policy_.agree_m;
  fix_covariance_ = latest.covariance;
  fix_covariance_at_ = latest.T_odom_robot;
  fix_confidence_ = CombinedConfidence(confidences);
  fix_weak_ = latest.weak && std::all_of(agreeing.begin(), agreeing.end(),
                                         [](const Hypothesis& h) { return h.weak; });
  confirmed_at_m_ = odometry_m_;
  hypotheses_.clear();
  challengers_.clear();
  update.new_fix = true;
}

void FixFilter::GiveUp(RelocalizationUpdate& update) {
  if (status_ != FixStatus::kFixed) return;
  DeclareLost(update);
  update.status = status_;
  update.T_world_robot = Pose2();
  update.T_world_odom = Pose2();
  update.confidence = 0.0;
  update.unconfirmed_m = 0.0;
  update.position_variance_m2 = 0.0;
  update.heading_variance_rad2 = 0.0;
  update.covariance.setZero();
  update.confirmed = false;  // an answer of this scan may have confirmed what is now given up
}

void FixFilter::DeclareLost(RelocalizationUpdate& update) {
  status_ = FixStatus::kLost;
  fix_confidence_ = 0.0;
  hypotheses_.clear();
  challengers_.clear();
  update.lost = true;
}

}  // namespace keyplace
