#pragma once
// Internal: the quantile of a sample, for the summaries of relocalization runs
// (eval/relocalization.cpp) and of odometry steps (eval/odometry_evaluation.cpp).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace keyplace {

/// The q-quantile (q in [0, 1]) of `values`, interpolated linearly between the two nearest
/// order statistics; 0 for an empty sample.
inline double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double position = q * static_cast<double>(values.size() - 1);
  const auto low = static_cast<std::size_t>(std::floor(position));
  const std::size_t high = std::min(low + 1, values.size() - 1);
  const double fraction = position - static_cast<double>(low);
  return values[low] + fraction * (values[high] - values[low]);
}

}  // namespace keyplace
