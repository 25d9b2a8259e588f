#pragma once
// RANSAC estimation of the rigid transform between two keypoint sets from descriptor pairs
// (paper Section 4.1.1, after FLIRTLib's RansacFeatureSetMatcher): 2-pair hypotheses with a
// rigidity pre-check, verification by geometric nearest neighbours, MSAC score (mean squared
// distance truncated at the acceptance threshold), least-squares refit on the inliers.

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"

namespace keyplace {

struct RansacConfig {
  double inlier_distance_m = 0.1;  // acceptance threshold
  int iterations = 18;             // sampled hypotheses
  // Enumerate all pairs of correspondences when there are at most this many (0 = never).
  int exhaustive_max_pairs = 40;
  double rigidity_m2 = 0.0064;  // reject a sample when (d1 - d2)^2 / (8 (d1 + d2)) exceeds this,
                                // d1, d2 the squared lengths of its two segments
  bool refine = true;           // least-squares refit on the inliers, kept when it scores better
  std::uint64_t seed = 1;
  // Lower bound of the per-coordinate residual sigma in RigidFitCovariance (the covariance of an
  // accepted match): stable keypoints are kept one per cell of the stability grid G (l_g =
  // 0.1 m), a position known to within a cell has sigma l_g / sqrt(12) = 0.029 m, so a fit is
  // never trusted to better than that however well its few inliers happen to agree.
  double min_fit_sigma_m = 0.03;
};

struct RansacResult {
  bool valid = false;  // at least one hypothesis was evaluated
  Pose2 T_ref_cur;     // maps current keypoints into the reference frame
  // (current index, reference index) of every inlier: current keypoints whose geometric nearest
  // reference keypoint lies within the acceptance threshold after the transform.
  std::vector<std::pair<int, int>> inliers;
  double score = 0.0;  // mean truncated squared distance (m^2), lower is better
  int hypotheses = 0;  // hypotheses evaluated (after the rigidity pre-check)
};

/// Least-squares rigid transform T with T * current[i] ~ reference[i] (2D Kabsch). Needs >= 2
/// points; returns identity for fewer.
Pose2 FitRigidTransform(const std::vector<Eigen::Vector2d>& reference,
                        const std::vector<Eigen::Vector2d>& current);

/// Covariance over (x, y, theta) of T_ref_cur, the least-squares rigid fit of the pairs
/// `inliers` (current index, reference index): reference[r] ~ T_ref_cur * current[c]. Each pair
/// gives two residuals e = T * c - r; linearised at T_ref_cur their Jacobian over (x, y, theta) is
/// J = [I2 | dR/dtheta * c]. With the residual variance per coordinate
///   sigma^2 = max(sum |e|^2 / (2 n - 3), min_sigma_m^2)   (2 n equations, 3 unknowns)
/// the covariance of the fit is sigma^2 (sum J^T J)^-1 (Gauss-Newton): smaller when the inliers
/// are many and spread out (the heading is pinned by points far apart), larger when the residuals
/// are. Infinite on the diagonal when the pairs do not determine the transform (fewer than 2, or
/// all at one spot); throws std::invalid_argument for an index out of range.
Eigen::Matrix3d RigidFitCovariance(const std::vector<Eigen::Vector2d>& reference,
                                   const std::vector<Eigen::Vector2d>& current,
                                   const std::vector<std::pair<int, int>>& inliers,
                                   const Pose2& T_ref_cur, double min_sigma_m);

/// The covariance of T_a_b * T_b_c * T_c_d over (x, y, theta) of the result, when only T_b_c is
/// uncertain with covariance `covariance_b_c` over its (x, y, theta): first-order propagation
/// with position = t_ab + R_ab (t_bc + R_bc t_cd), heading = theta_ab + theta_bc + theta_cd.
Eigen::Matrix3d ComposedCovariance(const Pose2& T_a_b, const Pose2& T_b_c, const Pose2& T_c_d,
                                   const Eigen::Matrix3d& covariance_b_c);

/// Scores T_ref_cur: for every current keypoint, its geometric nearest reference keypoint.
double ScoreTransform(const std::vector<Eigen::Vector2d>& reference,
                      const std::vector<Eigen::Vector2d>& current, const Pose2& T_ref_cur,
                      double inlier_distance_m, std::vector<std::pair<int, int>>* inliers);

/// `pairs` are (current index, reference index) descriptor correspondences.
RansacResult EstimateRigidTransformRansac(const std::vector<Eigen::Vector2d>& reference,
                                          const std::vector<Eigen::Vector2d>& current,
                                          const std::vector<std::pair<int, int>>& pairs,
                                          const RansacConfig& config);

}  // namespace keyplace
