#include "keyplace/place/ransac.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "place/nearest_reference.hpp"

namespace keyplace {
namespace {

// The transform mapping segment (c1, c2) of the current set onto (r1, r2) of the reference set
// (rotation from the segment directions, translation from the second point, as FLIRTLib).
Pose2 HypothesisFromTwoPairs(const Eigen::Vector2d& c1, const Eigen::Vector2d& c2,
                             const Eigen::Vector2d& r1, const Eigen::Vector2d& r2) {
  const Eigen::Vector2d base = c1 - c2;
  const Eigen::Vector2d moved = r1 - r2;
  const double angle = std::atan2(base.x() * moved.y() - base.y() * moved.x(), base.dot(moved));
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  const Eigen::Vector2d rotated(c * c2.x() - s * c2.y(), s * c2.x() + c * c2.y());
  return {r2.x() - rotated.x(), r2.y() - rotated.y(), angle};
}

}  // namespace

Pose2 FitRigidTransform(const std::vector<Eigen::Vector2d>& reference,
                        const std::vector<Eigen::Vector2d>& current) {
  const std::size_t n = std::min(reference.size(), current.size());
  if (n < 2) return {};
  Eigen::Vector2d mean_ref = Eigen::Vector2d::Zero();
  Eigen::Vector2d mean_cur = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    mean_ref += reference[i];
    mean_cur += current[i];
  }
  mean_ref /= static_cast<double>(n);
  mean_cur /= static_cast<double>(n);
  double sum_cos = 0.0;
  double sum_sin = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d a = current[i] - mean_cur;
    const Eigen::Vector2d b = reference[i] - mean_ref;
    sum_cos += a.dot(b);
    sum_sin += a.x() * b.y() - a.y() * b.x();
  }
  const double angle = std::atan2(sum_sin, sum_cos);
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  const Eigen::Vector2d rotated(c * mean_cur.x() - s * mean_cur.y(),
                                s * mean_cur.x() + c * mean_cur.y());
  return {mean_ref.x() - rotated.x(), mean_ref.y() - rotated.y(), angle};
}

Eigen::Matrix3d RigidFitCovariance(const std::vector<Eigen::Vector2d>& reference,
                                   const std::vector<Eigen::Vector2d>& current,
                                   const std::vector<std::pair<int, int>>& inliers,
                                   const Pose2& T_ref_cur, double min_sigma_m) {
  Eigen::Matrix3d undetermined =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()).asDiagonal();
  if (inliers.size() < 2) return undetermined;
  const double c = std::cos(T_ref_cur.theta);
  const double s = std::sin(T_ref_cur.theta);
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();  // sum of J^T J
  double squared_residuals = 0.0;
  for (const auto& [current_index, reference_index] : inliers) {
    if (current_index < 0 || reference_index < 0 ||
        static_cast<std::size_t>(current_index) >= current.size() ||
        static_cast<std::size_t>(reference_index) >= reference.size()) {
      throw std::invalid_argument("RigidFitCovariance: pair (" + std::to_string(current_index) +
                                  ", " + std::to_string(reference_index) + ") out of range");
    }
    const Eigen::Vector2d& p = current[static_cast<std::size_t>(current_index)];
    squared_residuals +=
        (T_ref_cur * p - reference[static_cast<std::size_t>(reference_index)]).squaredNorm();
    Eigen::Matrix<double, 2, 3> jacobian;
    jacobian << 1.0, 0.0, -s * p.x() - c * p.y(),  // d(R p)/dtheta
        0.0, 1.0, c * p.x() - s * p.y();
    information += jacobian.transpose() * jacobian;
  }
  const double dof = 2.0 * static_cast<double>(inliers.size()) - 3.0;
  const double variance = std::max(squared_residuals / dof, min_sigma_m * min_sigma_m);
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(information);
  if (!lu.isInvertible()) return undetermined;
  return variance * lu.inverse();
}

Eigen::Matrix3d ComposedCovariance(const Pose2& T_a_b, const Pose2& T_b_c, const Pose2& T_c_d,
                                   const Eigen::Matrix3d& covariance_b_c) {
  const double ca = std::cos(T_a_b.theta);
  const double sa = std::sin(T_a_b.theta);
  Eigen::Matrix2d R_ab;
  R_ab << ca, -sa, sa, ca;
  // d(R_bc t_cd)/dtheta_bc: R_bc t_cd turned by 90 degrees.
  const Eigen::Vector2d arm = T_b_c * T_c_d.translation() - T_b_c.translation();
  const Eigen::Vector2d d_arm(-arm.y(), arm.x());
  Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();
  jacobian.topLeftCorner<2, 2>() = R_ab;
  jacobian.topRightCorner<2, 1>() = R_ab * d_arm;
  jacobian(2, 2) = 1.0;
  return jacobian * covariance_b_c * jacobian.transpose();
}

namespace {

// How many keypoints RANSAC scores between two looks at whether a hypothesis can still win.
constexpr std::size_t kBeatCheckEvery = 8;

// ScoreTransform against reference keypoints already sorted for the inlier search. When the
// score cannot come below `to_beat` it returns +infinity early: the terms are never negative, so
// the partial sum, divided as the whole, only grows (rounding is monotone too).
double ScoreAgainst(const NearestReference& reference, const std::vector<Eigen::Vector2d>& current,
                    const Pose2& T_ref_cur, std::vector<std::pair<int, int>>* inliers,
                    double to_beat = std::numeric_limits<double>::infinity()) {
  if (inliers) inliers->clear();
  if (current.empty()) return 0.0;
  const auto n = static_cast<double>(current.size());
  double score = 0.0;
  const PointMapper ref_from_cur(T_ref_cur);
  for (std::size_t i = 0; i < current.size(); ++i) {
    const auto [nearest, distance2] = reference.Nearest(ref_from_cur(current[i]));
    if (nearest >= 0 && inliers) inliers->emplace_back(static_cast<int>(i), nearest);
    score += distance2;  // the threshold^2 when there is no inlier: the truncated (MSAC) cost
    if ((i + 1) % kBeatCheckEvery == 0 && score / n >= to_beat) {
      return std::numeric_limits<double>::infinity();
    }
  }
  return score / n;
}

}  // namespace

double ScoreTransform(const std::vector<Eigen::Vector2d>& reference,
                      const std::vector<Eigen::Vector2d>& current, const Pose2& T_ref_cur,
                      double inlier_distance_m, std::vector<std::pair<int, int>>* inliers) {
  return ScoreAgainst(NearestReference(reference, inlier_distance_m), current, T_ref_cur, inliers);
}

RansacResult EstimateRigidTransformRansac(const std::vector<Eigen::Vector2d>& reference,
                                          const std::vector<Eigen::Vector2d>& current,
                                          const std::vector<std::pair<int, int>>& pairs,
                                          const RansacConfig& config) {
  RansacResult result;
  result.score = std::numeric_limits<double>::infinity();
  const int n = static_cast<int>(pairs.size());
  if (n < 2) return result;

  std::vector<std::pair<int, int>> inliers;
  const NearestReference nearest_reference(reference, config.inlier_distance_m);
  auto try_hypothesis = [&](int a, int b) {
    const Eigen::Vector2d& c1 = current[pairs[a].first];
    const Eigen::Vector2d& c2 = current[pairs[b].first];
    const Eigen::Vector2d& r1 = reference[pairs[a].second];
    const Eigen::Vector2d& r2 = reference[pairs[b].second];
    const double d_cur = (c1 - c2).squaredNorm();
    const double d_ref = (r1 - r2).squaredNorm();
    if (d_cur <= 0.0 || d_ref <= 0.0) return;
    if ((d_cur - d_ref) * (d_cur - d_ref) / (8.0 * (d_cur + d_ref)) > config.rigidity_m2) return;
    const Pose2 hypothesis = HypothesisFromTwoPairs(c1, c2, r1, r2);
    ++result.hypotheses;
    const double score =
        ScoreAgainst(nearest_reference, current, hypothesis, &inliers, result.score);
    if (score < result.score) {
      result.score = score;
      result.T_ref_cur = hypothesis;
      result.inliers = inliers;
      result.valid = true;
    }
  };

  if (config.exhaustive_max_pairs > 0 && n <= config.exhaustive_max_pairs) {
    for (int a = 0; a < n; ++a) {
      for (int b = a + 1; b < n; ++b) try_hypothesis(a, b);
    }
  } else {
    std::seed_seq seed_sequence{static_cast<std::uint32_t>(config.seed),
                                static_cast<std::uint32_t>(config.seed >> 32)};
    std::mt19937_64 rng(seed_sequence);
    std::uniform_int_distribution<int> pick(0, n - 1);
    for (int iteration = 0; iteration < config.iterations; ++iteration) {
      const int a = pick(rng);
      int b = pick(rng);
      while (b == a) b = pick(rng);
      try_hypothesis(a, b);
    }
  }

  if (result.valid && config.refine && result.inliers.size() >= 2) {
    std::vector<Eigen::Vector2d> ref_points;
    std::vector<Eigen::Vector2d> cur_points;
    for (const auto& [c, r] : result.inliers) {
      cur_points.push_back(current[c]);
      ref_points.push_back(reference[r]);
    }
    const Pose2 refined = FitRigidTransform(ref_points, cur_points);
    const double score = ScoreAgainst(nearest_reference, current, refined, &inliers);
    if (score <= result.score) {
      result.score = score;
      result.T_ref_cur = refined;
      result.inliers = inliers;
    }
  }
  return result;
}

}  // namespace keyplace
