#include "place/nearest_reference.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace keyplace {

NearestReference::NearestReference(const std::vector<Eigen::Vector2d>& reference, double radius_m)
    : reference_(reference), radius_m_(radius_m), radius2_(radius_m * radius_m) {
  std::vector<int> order;
  order.reserve(reference.size());
  for (std::size_t j = 0; j < reference.size(); ++j) {
    if (reference[j].allFinite()) order.push_back(static_cast<int>(j));
  }
  std::stable_sort(order.begin(), order.end(),
                   [&reference](int a, int b) { return reference[a].x() < reference[b].x(); });
  index_sorted_ = std::move(order);
  x_sorted_.reserve(index_sorted_.size());
  for (int j : index_sorted_) x_sorted_.push_back(reference[j].x());
}

std::pair<int, double> NearestReference::Nearest(const Eigen::Vector2d& point) const {
  if (!point.allFinite()) return {-1, radius2_};
  // A keypoint with squared distance below radius^2 has |dx| < radius; the strip is a little
  // wider so that rounding of point.x() -/+ radius cannot leave such a keypoint out (extra
  // keypoints in the strip are only compared, never wrongly chosen).
  const double half_width = radius_m_ * (1.0 + 1e-9) + 1e-12;
  const auto first = std::lower_bound(x_sorted_.begin(), x_sorted_.end(), point.x() - half_width);
  int best_index = -1;
  double best = radius2_;
  for (auto it = first; it != x_sorted_.end() && *it <= point.x() + half_width; ++it) {
    const int j = index_sorted_[static_cast<std::size_t>(it - x_sorted_.begin())];
    const double d2 = (point - reference_[j]).squaredNorm();
    if (d2 < best || (d2 == best && best_index >= 0 && j < best_index)) {
      best = d2;
      best_index = j;
    }
  }
  return {best_index, best};
}

}  // namespace keyplace
