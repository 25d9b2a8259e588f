#include "place/candidate_ranking.hpp"

#include <algorithm>
#include <numeric>

namespace keyplace {

int LargestRigidStar(const std::vector<DescriptorPair>& pairs,
                     const std::vector<Eigen::Vector2d>& current_positions,
                     const std::vector<Eigen::Vector2d>& reference_positions, double rigidity_m2) {
  const std::size_t n = pairs.size();
  if (n == 0) return 0;
  std::vector<int> agreeing(n, 0);
  for (std::size_t a = 0; a < n; ++a) {
    const Eigen::Vector2d& current_a = current_positions[pairs[a].current];
    const Eigen::Vector2d& reference_a = reference_positions[pairs[a].reference];
    for (std::size_t b = a + 1; b < n; ++b) {
      // The test, in the same arithmetic, of EstimateRigidTransformRansac's samples.
      const double d_cur = (current_a - current_positions[pairs[b].current]).squaredNorm();
      const double d_ref = (reference_a - reference_positions[pairs[b].reference]).squaredNorm();
      if (d_cur <= 0.0 || d_ref <= 0.0) continue;
      // Written as "not within" so that a non-finite keypoint agrees with nothing.
      if (!((d_cur - d_ref) * (d_cur - d_ref) / (8.0 * (d_cur + d_ref)) <= rigidity_m2)) continue;
      ++agreeing[a];
      ++agreeing[b];
    }
  }
  return 1 + *std::max_element(agreeing.begin(), agreeing.end());
}

std::vector<std::size_t> KeepMostRigid(const std::vector<int>& rigid_star, std::size_t keep) {
  std::vector<std::size_t> positions(rigid_star.size());
  std::iota(positions.begin(), positions.end(), std::size_t{0});
  if (keep >= positions.size()) return positions;
  std::stable_sort(positions.begin(), positions.end(), [&rigid_star](std::size_t a, std::size_t b) {
    return rigid_star[a] > rigid_star[b];
  });
  positions.resize(keep);
  std::sort(positions.begin(), positions.end());
  return positions;
}

}  // namespace keyplace
