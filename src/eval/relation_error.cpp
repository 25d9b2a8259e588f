#include "keyplace/eval/relation_error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

namespace keyplace {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

void MeanStdMax(const std::vector<double>& values, double* mean, double* std_dev, double* max) {
  *mean = *std_dev = *max = 0.0;
  if (values.empty()) return;
  double sum = 0.0;
  for (const double v : values) sum += v;
  *mean = sum / static_cast<double>(values.size());
  double sum_sq = 0.0;
  for (const double v : values) sum_sq += (v - *mean) * (v - *mean);
  *std_dev = std::sqrt(sum_sq / static_cast<double>(values.size()));
  *max = *std::max_element(values.begin(), values.end());
}

void ValidateRelationConfig(const RelationErrorConfig& config) {
  if (!(config.local_max_dt_s >= 0.0)) {
    throw std::invalid_argument("RelationErrorConfig.local_max_dt_s must be >= 0");
  }
  if (!(config.stamp_tolerance_s >= 0.0 && config.stamp_tolerance_s <= 1.0)) {
    throw std::invalid_argument("RelationErrorConfig.stamp_tolerance_s must lie in [0, 1] s");
  }
  if (!(config.min_matched_fraction >= 0.0 && config.min_matched_fraction <= 1.0)) {
    throw std::invalid_argument("RelationErrorConfig.min_matched_fraction must lie in [0, 1]");
  }
}

// The trajectory's stamps in increasing order (equal stamps in trajectory order), for matching
// relation stamps by value.
class StampIndex {
 public:
  explicit StampIndex(const std::vector<TimedPose>& trajectory) {
    order_.resize(trajectory.size());
    for (std::size_t i = 0; i < trajectory.size(); ++i) order_[i] = i;
    std::stable_sort(order_.begin(), order_.end(), [&trajectory](std::size_t a, std::size_t b) {
      return trajectory[a].timestamp_s < trajectory[b].timestamp_s;
    });
    stamps_.reserve(order_.size());
    for (std::size_t i : order_) stamps_.push_back(trajectory[i].timestamp_s);
    for (std::size_t k = 1; k < stamps_.size(); ++k) duplicates_ += stamps_[k] == stamps_[k - 1];
  }

  std::size_t duplicates() const { return duplicates_; }

  // Whether `stamp_s` lies within the first..last stamp, widened by the tolerance.
  bool Spans(double stamp_s, double tolerance_s) const {
    return !stamps_.empty() && stamps_.front() - stamp_s <= tolerance_s &&
           stamp_s - stamps_.back() <= tolerance_s;
  }

  // The trajectory index of the nearest stamp within tolerance_s; ties go to the earlier stamp,
  // and among equal stamps to the earlier pose.
  std::optional<std::size_t> Nearest(double stamp_s, double tolerance_s) const {
    const auto above = std::lower_bound(stamps_.begin(), stamps_.end(), stamp_s);
    auto nearest = stamps_.end();
    double gap_s = std::numeric_limits<double>::infinity();
    if (above != stamps_.begin()) {
      nearest = std::lower_bound(stamps_.begin(), above, *std::prev(above));  // first of equals
      gap_s = stamp_s - *nearest;
    }
    if (above != stamps_.end() && *above - stamp_s < gap_s) {
      nearest = above;
      gap_s = *above - stamp_s;
    }
    if (nearest == stamps_.end() || !(gap_s <= tolerance_s)) return std::nullopt;
    return order_[static_cast<std::size_t>(nearest - stamps_.begin())];
  }

 private:
  std::vector<std::size_t> order_;  // trajectory indices by stamp
  std::vector<double> stamps_;      // their stamps
  std::size_t duplicates_ = 0;
};

std::string RefusalOf(const RelationErrorReport& report, const RelationErrorConfig& config) {
  const std::size_t inside = report.matched + report.unmatched;
  if (report.relations == 0) return "the relation file holds no relation";
  if (report.trajectory_poses == 0) return "the trajectory has no pose";
  if (inside == 0) {
    return "no relation lies within the trajectory's time span (" +
           std::to_string(report.outside_span) +
           " outside it): the relation file belongs to another log";
  }
  const double fraction = static_cast<double>(report.matched) / static_cast<double>(inside);
  if (report.matched > 0 && fraction >= config.min_matched_fraction) return "";
  char numbers[96];
  std::snprintf(numbers, sizeof(numbers),
                " (%.1f %%) matched a scan stamp within %g ms, below %g %%",
                std::floor(1000.0 * fraction) / 10.0, 1e3 * config.stamp_tolerance_s,
                100.0 * config.min_matched_fraction);
  return "only " + std::to_string(report.matched) + " of the " + std::to_string(inside) +
         " relations inside the trajectory's time span" + numbers +
         ": the relation file belongs to another log, or its stamps differ from the log's";
}

}  // namespace

RelationErrorConfig RelationConfigFrom(const EvaluationConfig& config) {
  RelationErrorConfig relation_config;
  relation_config.local_max_dt_s = config.local_relation_max_dt_s;
  relation_config.stamp_tolerance_s = config.relation_stamp_tolerance_s;
  relation_config.min_matched_fraction = config.min_matched_relations;
  return relation_config;
}

ErrorStats Summarize(const std::vector<double>& translation_errors_m,
                     const std::vector<double>& rotation_errors_deg) {
  if (translation_errors_m.size() != rotation_errors_deg.size()) {
    throw std::invalid_argument(
        "Summarize: translation_errors_m and rotation_errors_deg differ in size");
  }
  ErrorStats stats;
  stats.count = translation_errors_m.size();
  MeanStdMax(translation_errors_m, &stats.translation_mean_m, &stats.translation_std_m,
             &stats.translation_max_m);
  MeanStdMax(rotation_errors_deg, &stats.rotation_mean_deg, &stats.rotation_std_deg,
             &stats.rotation_max_deg);
  return stats;
}

PoseError RelativePoseError(const Pose2& estimated_T_a_b, const Pose2& true_T_a_b) {
  const Pose2 epsilon = Between(true_T_a_b, estimated_T_a_b);
  return {TranslationNorm(epsilon), std::abs(WrapAngle(epsilon.theta)) * kRadToDeg};
}

RelationErrorReport EvaluateRelations(const std::vector<TimedPose>& trajectory,
                                      const std::vector<Relation>& relations,
                                      const RelationErrorConfig& config) {
  ValidateRelationConfig(config);
  RelationErrorReport report;
  report.relations = relations.size();
  report.trajectory_poses = trajectory.size();
  const StampIndex stamps(trajectory);
  report.duplicate_timestamps = stamps.duplicates();
  std::vector<double> t_all, r_all, t_local, r_local, t_loop, r_loop;
  for (std::size_t k = 0; k < relations.size(); ++k) {
    const Relation& relation = relations[k];
    if (!stamps.Spans(relation.timestamp_a_s, config.stamp_tolerance_s) ||
        !stamps.Spans(relation.timestamp_b_s, config.stamp_tolerance_s)) {
      ++report.outside_span;
      continue;
    }
    const auto a = stamps.Nearest(relation.timestamp_a_s, config.stamp_tolerance_s);
    const auto b = stamps.Nearest(relation.timestamp_b_s, config.stamp_tolerance_s);
    if (!a || !b) {
      ++report.unmatched;
      continue;
    }
    ++report.matched;
    RelationErrorItem item;
    item.relation_index = k;
    item.dt_s = std::abs(relation.timestamp_b_s - relation.timestamp_a_s);
    item.local = item.dt_s < config.local_max_dt_s;
    const Pose2 estimated = Between(trajectory[*a].pose, trajectory[*b].pose);
    item.error = RelativePoseError(estimated, relation.T_a_b);
    t_all.push_back(item.error.translation_m);
    r_all.push_back(item.error.rotation_deg);
    (item.local ? t_local : t_loop).push_back(item.error.translation_m);
    (item.local ? r_local : r_loop).push_back(item.error.rotation_deg);
    report.items.push_back(item);
  }
  report.all = Summarize(t_all, r_all);
  report.local = Summarize(t_local, r_local);
  report.loop = Summarize(t_loop, r_loop);
  report.refusal = RefusalOf(report, config);
  return report;
}

DriftReport EvaluateDrift(const std::vector<Pose2>& estimate_by_raw_index,
                          const std::vector<Pose2>& corrected_by_corrected_index,
                          const std::vector<IndexPair>& pairs_in) {
  std::vector<IndexPair> pairs = pairs_in;
  for (const IndexPair& pair : pairs) {
    if (pair.raw_index >= estimate_by_raw_index.size()) {
      throw std::invalid_argument("EvaluateDrift: raw_index " + std::to_string(pair.raw_index) +
                                  " out of range (" + std::to_string(estimate_by_raw_index.size()) +
                                  " raw poses)");
    }
    if (pair.corrected_index >= corrected_by_corrected_index.size()) {
      throw std::invalid_argument("EvaluateDrift: corrected_index " +
                                  std::to_string(pair.corrected_index) + " out of range (" +
                                  std::to_string(corrected_by_corrected_index.size()) +
                                  " corrected poses)");
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const IndexPair& a, const IndexPair& b) {
    return a.corrected_index < b.corrected_index;
  });
  DriftReport report;
  report.pairs = pairs.size();
  if (pairs.empty()) return report;

  std::vector<double> t_errors, r_errors;
  for (std::size_t k = 1; k < pairs.size(); ++k) {
    const Pose2 estimated = Between(estimate_by_raw_index[pairs[k - 1].raw_index],
                                    estimate_by_raw_index[pairs[k].raw_index]);
    const Pose2 truth = Between(corrected_by_corrected_index[pairs[k - 1].corrected_index],
                                corrected_by_corrected_index[pairs[k].corrected_index]);
    const PoseError error = RelativePoseError(estimated, truth);
    t_errors.push_back(error.translation_m);
    r_errors.push_back(error.rotation_deg);
  }
  report.consecutive = Summarize(t_errors, r_errors);
  for (std::size_t k = kDriftWindowSteps; k < pairs.size(); ++k) {
    const IndexPair& first = pairs[k - kDriftWindowSteps];
    const Pose2 estimated =
        Between(estimate_by_raw_index[first.raw_index], estimate_by_raw_index[pairs[k].raw_index]);
    const Pose2 truth = Between(corrected_by_corrected_index[first.corrected_index],
                                corrected_by_corrected_index[pairs[k].corrected_index]);
    const double heading_deg = RelativePoseError(estimated, truth).rotation_deg;
    if (!report.window_heading_max_deg || heading_deg > *report.window_heading_max_deg) {
      report.window_heading_max_deg = heading_deg;
      report.window_start_raw_index = first.raw_index;
    }
  }

  // Closed-form SE(2) alignment of the estimated positions onto the corrected ones.
  Eigen::Vector2d mean_e = Eigen::Vector2d::Zero();
  Eigen::Vector2d mean_c = Eigen::Vector2d::Zero();
  for (const IndexPair& pair : pairs) {
    mean_e += estimate_by_raw_index[pair.raw_index].translation();
    mean_c += corrected_by_corrected_index[pair.corrected_index].translation();
  }
  mean_e /= static_cast<double>(pairs.size());
  mean_c /= static_cast<double>(pairs.size());
  double dot = 0.0;
  double cross = 0.0;
  for (const IndexPair& pair : pairs) {
    const Eigen::Vector2d e = estimate_by_raw_index[pair.raw_index].translation() - mean_e;
    const Eigen::Vector2d c =
        corrected_by_corrected_index[pair.corrected_index].translation() - mean_c;
    dot += e.dot(c);
    cross += e.x() * c.y() - e.y() * c.x();
  }
  const double angle = (dot == 0.0 && cross == 0.0) ? 0.0 : std::atan2(cross, dot);
  const Pose2 rotation(0.0, 0.0, angle);
  const Eigen::Vector2d shift = mean_c - rotation * mean_e;
  report.T_corrected_estimate = Pose2(shift.x(), shift.y(), angle);

  double sum_sq = 0.0;
  double sum = 0.0;
  double sum_sq_rot = 0.0;
  for (const IndexPair& pair : pairs) {
    const Pose2 aligned = report.T_corrected_estimate * estimate_by_raw_index[pair.raw_index];
    const Pose2& truth = corrected_by_corrected_index[pair.corrected_index];
    const double d = std::hypot(aligned.x - truth.x, aligned.y - truth.y);
    const double dr = WrapAngle(aligned.theta - truth.theta) * kRadToDeg;
    sum += d;
    sum_sq += d * d;
    sum_sq_rot += dr * dr;
    report.ate_max_m = std::max(report.ate_max_m, d);
  }
  const double n = static_cast<double>(pairs.size());
  report.ate_mean_m = sum / n;
  report.ate_rmse_m = std::sqrt(sum_sq / n);
  report.ate_rotation_rmse_deg = std::sqrt(sum_sq_rot / n);
  return report;
}

}  // namespace keyplace
