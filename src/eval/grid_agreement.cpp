#include "keyplace/eval/grid_agreement.hpp"

#include <cmath>
#include <utility>
#include <vector>

namespace keyplace {
namespace {

std::vector<Eigen::Vector2d> OccupiedCentres(const OccupancyGrid& grid,
                                             const OccupancyGridConfig& config) {
  std::vector<Eigen::Vector2d> centres;
  for (int row = 0; row < grid.height; ++row) {
    for (int column = 0; column < grid.width; ++column) {
      if (grid.State(column, row, config) == CellState::kOccupied) {
        centres.push_back(grid.origin_m +
                          grid.resolution_m * Eigen::Vector2d(column + 0.5, row + 0.5));
      }
    }
  }
  return centres;
}

// Cells of `grid` within tolerance_m (Chebyshev, in cells) of the world point: whether one is
// occupied, and whether all of them are free (false outside the grid).
struct Neighbourhood {
  bool any_occupied = false;
  bool all_free = false;
};

Neighbourhood Around(const OccupancyGrid& grid, const OccupancyGridConfig& config,
                     const Eigen::Vector2d& point_m, double tolerance_m) {
  Neighbourhood around;
  int column = 0;
  int row = 0;
  if (!grid.CellOf(point_m, column, row)) return around;
  const int reach = static_cast<int>(std::ceil(tolerance_m / grid.resolution_m));
  around.all_free = true;
  for (int r = row - reach; r <= row + reach; ++r) {
    for (int c = column - reach; c <= column + reach; ++c) {
      const bool inside = r >= 0 && c >= 0 && r < grid.height && c < grid.width;
      const CellState state = inside ? grid.State(c, r, config) : CellState::kUnknown;
      around.any_occupied = around.any_occupied || state == CellState::kOccupied;
      around.all_free = around.all_free && state == CellState::kFree;
    }
  }
  return around;
}

// Shares of `points` (mapped by T) with an occupied cell of `grid` within tolerance_m, and with
// only free cells there.
std::pair<double, double> Shares(const std::vector<Eigen::Vector2d>& points, const Pose2& T,
                                 const OccupancyGrid& grid, const OccupancyGridConfig& config,
                                 double tolerance_m) {
  if (points.empty()) return {0.0, 0.0};
  std::size_t occupied = 0;
  std::size_t free = 0;
  for (const Eigen::Vector2d& point : points) {
    const Neighbourhood around = Around(grid, config, T * point, tolerance_m);
    if (around.any_occupied) ++occupied;
    if (around.all_free) ++free;
  }
  const auto count = static_cast<double>(points.size());
  return {static_cast<double>(occupied) / count, static_cast<double>(free) / count};
}

}  // namespace

GridAgreement CompareOccupancyGrids(const OccupancyGrid& estimate, const OccupancyGrid& reference,
                                    const Pose2& T_reference_estimate,
                                    const OccupancyGridConfig& config, double tolerance_m) {
  GridAgreement agreement;
  agreement.tolerance_m = tolerance_m;
  const std::vector<Eigen::Vector2d> occupied = OccupiedCentres(estimate, config);
  const std::vector<Eigen::Vector2d> occupied_reference = OccupiedCentres(reference, config);
  agreement.occupied = occupied.size();
  agreement.occupied_reference = occupied_reference.size();
  const auto [matched, on_free] =
      Shares(occupied, T_reference_estimate, reference, config, tolerance_m);
  agreement.occupied_matched = matched;
  agreement.occupied_on_free = on_free;
  agreement.reference_matched =
      Shares(occupied_reference, T_reference_estimate.inverse(), estimate, config, tolerance_m)
          .first;
  return agreement;
}

}  // namespace keyplace
