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
