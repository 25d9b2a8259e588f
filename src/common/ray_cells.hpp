#pragma once
// Internal: the cells of a square grid that a laser ray crosses before the cell it ends in, as
// occupancy grids mark free space (Amanatides and Woo, "A fast voxel traversal algorithm", 1987).

#include <cmath>
#include <cstdlib>
#include <limits>

#include <Eigen/Core>

namespace keyplace {

/// Calls visit(column, row) for every cell the segment from `from` to `to` crosses, from the cell
/// holding `from` up to the one before the cell holding `to`, in order, until visit returns false.
/// Both points are in cell units: cell (c, r) spans [c, c + 1) × [r, r + 1). It visits at most |Δc|
/// + |Δr| cells (rounding can end a step off the end cell, never further), whether or not they lie
/// in the caller's grid. Nothing is visited unless both points are finite and within `max_cells` of
/// each other along each axis, so the counts stay in range whatever the input.
template <typename Visit>
void ForEachCellBeforeEnd(const Eigen::Vector2d& from, const Eigen::Vector2d& to, Visit&& visit,
                          double max_cells = 1e6) {
  if (!from.allFinite() || !to.allFinite() ||
      !((to - from).lpNorm<Eigen::Infinity>() <= max_cells) ||
      !(from.lpNorm<Eigen::Infinity>() < 1e9) || !(to.lpNorm<Eigen::Infinity>() < 1e9)) {
    return;
  }
  int column = static_cast<int>(std::floor(from.x()));
  int row = static_cast<int>(std::floor(from.y()));
  const int end_column = static_cast<int>(std::floor(to.x()));
  const int end_row = static_cast<int>(std::floor(to.y()));
  const Eigen::Vector2d direction = to - from;
  const int step_column = direction.x() > 0 ? 1 : -1;
  const int step_row = direction.y() > 0 ? 1 : -1;
  const double inf = std::numeric_limits<double>::infinity();
  const double column_t_step = direction.x() != 0 ? std::abs(1.0 / direction.x()) : inf;
  const double row_t_step = direction.y() != 0 ? std::abs(1.0 / direction.y()) : inf;
  const double first_column = step_column > 0 ? column + 1 - from.x() : from.x() - column;
  const double first_row = step_row > 0 ? row + 1 - from.y() : from.y() - row;
  double next_column_t = direction.x() != 0 ? first_column * column_t_step : inf;
  double next_row_t = direction.y() != 0 ? first_row * row_t_step : inf;
  const int steps = std::abs(end_column - column) + std::abs(end_row - row);
  for (int step = 0; step < steps; ++step) {
    if (!visit(column, row)) return;
    if (next_column_t < next_row_t) {
      column += step_column;
      next_column_t += column_t_step;
    } else {
      row += step_row;
      next_row_t += row_t_step;
    }
  }
}

}  // namespace keyplace
