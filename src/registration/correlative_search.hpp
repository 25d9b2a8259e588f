#pragma once
// Correlative scan matching at a coarse resolution (Olson 2009; the real-time matcher that
// Cartographer and Karto run before refinement): every pose of a window around a guess is scored
// by how close the transformed source points fall to the target points, and the best one wins.
// ICP only finds the basin it starts in; this finds the right basin when the guess is tens of
// degrees off, as in a fast turn whose odometry increment is wrong.

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"

namespace keyplace {

/// Closeness to a target point set on a grid of square cells: exp(-d² / (2 σ²)) of the distance d
/// from a cell's centre to the nearest target point, 0 beyond 3 σ and outside the grid. Only
/// the square of half-size `half_extent_m` around `centre` is covered, with at most
/// kMaxProximityFieldWidth cells per side (the cells grow beyond `cell_m` when the extent needs
/// more, and σ grows to at least one cell), so the memory stays below 64 MiB whatever the
/// target's spread and the caller's extent.
/// Throws std::invalid_argument unless cell_m, sigma_m and half_extent_m are finite and > 0.
inline constexpr int kMaxProximityFieldWidth = 4096;

class ProximityField {
 public:
  ProximityField(const std::vector<Eigen::Vector2d>& target_points, const Eigen::Vector2d& centre,
                 double half_extent_m, double cell_m, double sigma_m);

  /// The value at a point (its cell's), 0 outside the grid.
  double At(const Eigen::Vector2d& point) const;

  double cell_m() const { return cell_m_; }
  int width() const { return width_; }
  /// The cell column and row of a point (may lie outside [0, width)).
  Eigen::Vector2d CellCoordinates(const Eigen::Vector2d& point) const {
    return (point - origin_) / cell_m_;
  }
  /// The value of cell (column, row), 0 outside the grid.
  double AtCell(int column, int row) const {
    if (column < 0 || row < 0 || column >= width_ || row >= width_) return 0.0;
    return values_[static_cast<std::size_t>(row) * static_cast<std::size_t>(width_) +
                   static_cast<std::size_t>(column)];
  }

 private:
  double cell_m_;
  Eigen::Vector2d origin_;  // the corner of cell (0, 0)
  int width_;               // cells per side
  std::vector<float> values_;
};

/// The poses searched: every combination of the translation offsets −k·s … k·s along x and y of the
/// target frame (s: translation_step_m rounded to whole cells of the field, k = ⌊t / s⌋) and the
/// rotation offsets −m·q … m·q (q: rotation_step_rad, m = ⌊r / q⌋) around the guess.
struct CorrelativeWindow {
  double translation_m = 0.5;
  double rotation_rad = 0.785398163;
  double translation_step_m = 0.1;
  double rotation_step_rad = 0.0174532925;
};

struct CorrelativeMatch {
  Pose2 T_target_source;        // the best pose of the window
  double score = 0.0;           // its mean closeness, times the prior (below)
  double score_at_guess = 0.0;  // the mean closeness at the guess (prior 1)
  bool moved = false;           // another pose scored higher than the guess
};

/// The best pose of the window for `source` (points in the source frame) against the field.
/// The score is the mean closeness of the points times a Gaussian prior on the offset from the
/// guess whose sigmas are the window's half-sizes (1 at the guess, exp(-1/2) = 0.61 at the end of
/// one axis, exp(-3/2) = 0.22 at a corner in x, y and rotation): where the scan cannot tell poses
/// apart (along a corridor), the guess wins; where it can, a clearly better fit far from the guess
/// still wins. The guess wins every tie (also when nothing scores, e.g. an empty source); among
/// the other poses the first in the order of rotation, then y, then x offsets does.
CorrelativeMatch SearchCorrelative(const ProximityField& field,
                                   const std::vector<Eigen::Vector2d>& source,
                                   const Pose2& T_target_source_guess,
                                   const CorrelativeWindow& window);

}  // namespace keyplace
