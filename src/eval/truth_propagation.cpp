#include "keyplace/eval/truth_propagation.hpp"

#include <stdexcept>

namespace keyplace {

std::vector<std::optional<PropagatedTruth>> PropagateTruth(
    const std::vector<std::optional<Pose2>>& corrected, const std::vector<Pose2>& odometry,
    int max_gap) {
  if (corrected.size() != odometry.size()) {
    throw std::invalid_argument("PropagateTruth: corrected and odometry differ in length");
  }
  if (max_gap < 0) throw std::invalid_argument("PropagateTruth: max_gap must be >= 0");
  const int n = static_cast<int>(corrected.size());
  // Nearest position with a corrected pose at or before / at or after each position.
  std::vector<int> before(corrected.size(), -1), after(corrected.size(), -1);
  for (int k = 0, last = -1; k < n; ++k) {
    if (corrected[k]) last = k;
    before[k] = last;
  }
  for (int k = n - 1, next = -1; k >= 0; --k) {
    if (corrected[k]) next = k;
    after[k] = next;
  }
  std::vector<std::optional<PropagatedTruth>> result(corrected.size());
  for (int k = 0; k < n; ++k) {
    int source = -1;
    if (before[k] >= 0 && k - before[k] <= max_gap) source = before[k];
    if (after[k] >= 0 && after[k] - k <= max_gap && (source < 0 || after[k] - k < k - source)) {
      source = after[k];
    }
    if (source < 0) continue;
    PropagatedTruth truth;
    truth.T_world_robot = *corrected[source] * Between(odometry[source], odometry[k]);
    truth.source = source;
    truth.gap = source > k ? source - k : k - source;
    result[k] = truth;
  }
  return result;
}

}  // namespace keyplace
