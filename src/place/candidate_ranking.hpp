#pragma once
// Which candidates get geometric verification when there are more than n_c of them (issue 15:
// among 10^4 distractor submaps the right place was often not among the 500 with the smallest
// mean pair distance).

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "keyplace/place/place_recognizer.hpp"

namespace keyplace {

/// The most descriptor pairs that one rigid transform can explain, as RANSAC's own sample test
/// sees it: 1 + the largest number of other pairs that pass the rigidity pre-check
/// (d_cur - d_ref)^2 / (8 (d_cur + d_ref)) <= rigidity_m2 (squared distances) together with one
/// pair. A true revisit's correct pairs all pass it with each other; pairs of a wrong place agree
/// in distance only by chance. 0 without pairs; O(pairs^2).
int LargestRigidStar(const std::vector<DescriptorPair>& pairs,
                     const std::vector<Eigen::Vector2d>& current_positions,
                     const std::vector<Eigen::Vector2d>& reference_positions, double rigidity_m2);

/// The positions (in `order`, the verification order) of the `keep` entries with the largest
/// `rigid_star`, ties broken by earlier position; returned in increasing position, so that the
/// kept candidates are verified in their original order. Keeps all when keep >= the size.
std::vector<std::size_t> KeepMostRigid(const std::vector<int>& rigid_star, std::size_t keep);

}  // namespace keyplace
