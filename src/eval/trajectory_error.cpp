#include "keyplace/eval/trajectory_error.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "keyplace/eval/relation_error.hpp"

namespace keyplace {

PairedTrajectory PairTrajectory(const std::vector<Pose2>& estimate_by_raw_index,
                                const std::vector<Pose2>& corrected_by_corrected_index,
                                const std::vector<IndexPair>& pairs) {
  std::vector<IndexPair> sorted = pairs;
  std::stable_sort(sorted.begin(), sorted.end(), [](const IndexPair& a, const IndexPair& b) {
    return a.corrected_index < b.corrected_index;
  });
  PairedTrajectory trajectory;
  for (const IndexPair& pair : sorted) {
    if (pair.raw_index >= estimate_by_raw_index.size()) {
      throw std::invalid_argument("PairTrajectory: raw_index " + std::to_string(pair.raw_index) +
                                  " out of range (" + std::to_string(estimate_by_raw_index.size()) +
                                  " scans)");
    }
    if (pair.corrected_index >= corrected_by_corrected_index.size()) {
      throw std::invalid_argument("PairTrajectory: corrected_index " +
                                  std::to_string(pair.corrected_index) + " out of range (" +
                                  std::to_string(corrected_by_corrected_index.size()) + " scans)");
    }
    trajectory.estimated.push_back(estimate_by_raw_index[pair.raw_index]);
    trajectory.truth.push_back(corrected_by_corrected_index[pair.corrected_index]);
    trajectory.raw_index.push_back(pair.raw_index);
  }
  return trajectory;
}

std::vector<RpePoint> RelativePoseErrorCurve(const PairedTrajectory& trajectory,
                                             const std::vector<std::size_t>& deltas) {
  const std::size_t n = trajectory.estimated.size();
  if (trajectory.truth.size() != n) {
    throw std::invalid_argument("RelativePoseErrorCurve: estimated and truth differ in length");
  }
  std::vector<RpePoint> curve;
  for (std::size_t delta : deltas) {
    if (delta == 0) throw std::invalid_argument("RelativePoseErrorCurve: delta must be > 0");
    RpePoint point;
    point.delta = delta;
    double sum_t = 0.0, sum_r = 0.0;
    for (std::size_t i = 0; i + delta < n; ++i) {
      const Pose2 true_motion = Between(trajectory.truth[i], trajectory.truth[i + delta]);
      const Pose2 estimated_motion =
          Between(trajectory.estimated[i], trajectory.estimated[i + delta]);
      const Pose2 error = Between(true_motion, estimated_motion);
      sum_t += error.x * error.x + error.y * error.y;
      sum_r += error.theta * error.theta;
      ++point.count;
    }
    if (point.count > 0) {
      point.translation_rmse_m = std::sqrt(sum_t / point.count);
      point.rotation_rmse_deg = std::sqrt(sum_r / point.count) * 180.0 / M_PI;
    }
    curve.push_back(point);
  }
  return curve;
}

AteSeries AbsoluteTrajectoryErrors(const PairedTrajectory& trajectory) {
  const std::size_t n = trajectory.estimated.size();
  if (trajectory.truth.size() != n) {
    throw std::invalid_argument("AbsoluteTrajectoryErrors: estimated and truth differ in length");
  }
  AteSeries series;
  if (n == 0) return series;
  std::vector<IndexPair> identity(n);
  for (std::size_t i = 0; i < n; ++i) identity[i] = {i, i};
  series.alignment =
      EvaluateDrift(trajectory.estimated, trajectory.truth, identity).T_corrected_estimate;
  double path = 0.0, sum_t = 0.0, sum_r = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) {
      path += (trajectory.truth[i].translation() - trajectory.truth[i - 1].translation()).norm();
    }
    const Pose2 error = Between(trajectory.truth[i], series.alignment * trajectory.estimated[i]);
    AtePoint point;
    point.path_length_m = path;
    point.translation_m = TranslationNorm(error);
    point.rotation_deg = std::abs(error.theta) * 180.0 / M_PI;
    sum_t += point.translation_m * point.translation_m;
    sum_r += point.rotation_deg * point.rotation_deg;
    series.points.push_back(point);
  }
  series.translation_rmse_m = std::sqrt(sum_t / n);
  series.rotation_rmse_deg = std::sqrt(sum_r / n);
  return series;
}

}  // namespace keyplace
