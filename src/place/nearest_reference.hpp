#pragma once
// The inlier search of RANSAC's scoring: each hypothesis maps every query keypoint into the
// reference frame and asks for its nearest reference keypoint, but only one closer than the
// inlier threshold counts. Sorting the reference keypoints by x once per candidate turns the
// O(reference) scan per query keypoint into a binary search and a look at the few keypoints in a
// strip as wide as the threshold, with the same answer as the scan (issue 15: RANSAC scoring was
// a third of a query's time).

#include <utility>
#include <vector>

#include <Eigen/Core>

namespace keyplace {

class NearestReference {
 public:
  /// `reference` must outlive this object; keypoints with a non-finite coordinate are never near.
  NearestReference(const std::vector<Eigen::Vector2d>& reference, double radius_m);

  /// The reference keypoint nearest to `point` if its squared distance is below radius_m^2 (the
  /// smallest index among equally near ones, as a scan in index order finds it) and that
  /// squared distance, computed as (point - reference[j]).squaredNorm(); {-1, radius_m^2} when
  /// no keypoint is that near.
  std::pair<int, double> Nearest(const Eigen::Vector2d& point) const;

 private:
  const std::vector<Eigen::Vector2d>& reference_;
  double radius_m_;
  double radius2_;
  std::vector<double> x_sorted_;   // x of the finite reference keypoints, increasing
  std::vector<int> index_sorted_;  // their indices into reference_, in the same order
};

}  // namespace keyplace
