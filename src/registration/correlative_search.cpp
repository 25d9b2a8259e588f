#include "correlative_search.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace keyplace {
namespace {

// Cell coordinates further out than this are outside any field (at most kMaxProximityFieldWidth
// cells wide); clamping to it keeps the integer arithmetic of the search from overflowing.
constexpr double kFarCell = 1e6;

int CellIndex(double coordinate) {
  if (!(std::abs(coordinate) < kFarCell)) return -static_cast<int>(kFarCell);
  return static_cast<int>(std::floor(coordinate));
}

double Square(double value) { return value * value; }

double CheckedPositive(double value, const char* name) {
  if (!(std::isfinite(value) && value > 0.0)) {
    throw std::invalid_argument(std::string("ProximityField: ") + name + " must be finite and > 0");
  }
  return value;
}

// The cell side: `cell_m`, or larger when the extent needs more than the widest grid.
double FieldCell(double half_extent_m, double cell_m) {
  CheckedPositive(half_extent_m, "half_extent_m");
  CheckedPositive(cell_m, "cell_m");
  return std::max(cell_m, 2.0 * half_extent_m / kMaxProximityFieldWidth);
}

}  // namespace

ProximityField::ProximityField(const std::vector<Eigen::Vector2d>& target_points,
                               const Eigen::Vector2d& centre, double half_extent_m, double cell_m,
                               double sigma_m)
    : cell_m_(FieldCell(half_extent_m, cell_m)),
      origin_(centre - Eigen::Vector2d(half_extent_m, half_extent_m)),
      width_(std::min(kMaxProximityFieldWidth,
                      std::max(1, static_cast<int>(std::ceil(2.0 * half_extent_m / cell_m_))))) {
  CheckedPositive(sigma_m, "sigma_m");
  if (!centre.allFinite()) throw std::invalid_argument("ProximityField: centre must be finite");
  values_.assign(static_cast<std::size_t>(width_) * static_cast<std::size_t>(width_), 0.0F);
  // Closeness is sampled at cell centres: a sigma below the cell would miss points between them.
  sigma_m = std::max(sigma_m, cell_m_);
  const double reach_m = 3.0 * sigma_m;
  const int reach_cells =
      std::min(kMaxProximityFieldWidth, static_cast<int>(std::ceil(reach_m / cell_m_)));
  const double inverse_two_sigma2 = 1.0 / (2.0 * sigma_m * sigma_m);
  for (const Eigen::Vector2d& point : target_points) {
    const Eigen::Vector2d cell = CellCoordinates(point);
    if (!(cell.x() > -reach_cells - 1 && cell.y() > -reach_cells - 1 &&
          cell.x() < width_ + reach_cells + 1 && cell.y() < width_ + reach_cells + 1)) {
      continue;  // also NaN
    }
    const int column = static_cast<int>(std::floor(cell.x()));
    const int row = static_cast<int>(std::floor(cell.y()));
    for (int r = std::max(0, row - reach_cells); r <= std::min(width_ - 1, row + reach_cells);
         ++r) {
      for (int c = std::max(0, column - reach_cells);
           c <= std::min(width_ - 1, column + reach_cells); ++c) {
        const Eigen::Vector2d cell_centre = origin_ + cell_m_ * Eigen::Vector2d(c + 0.5, r + 0.5);
        const double d2 = (cell_centre - point).squaredNorm();
        if (d2 > reach_m * reach_m) continue;
        float& value = values_[static_cast<std::size_t>(r) * static_cast<std::size_t>(width_) +
                               static_cast<std::size_t>(c)];
        value = std::max(value, static_cast<float>(std::exp(-d2 * inverse_two_sigma2)));
      }
    }
  }
}

double ProximityField::At(const Eigen::Vector2d& point) const {
  const Eigen::Vector2d cell = CellCoordinates(point);
  return AtCell(CellIndex(cell.x()), CellIndex(cell.y()));
}

CorrelativeMatch SearchCorrelative(const ProximityField& field,
                                   const std::vector<Eigen::Vector2d>& source,
                                   const Pose2& T_target_source_guess,
                                   const CorrelativeWindow& window) {
  CorrelativeMatch best;
  best.T_target_source = T_target_source_guess;
  if (source.empty()) return best;
  const double inverse_n = 1.0 / static_cast<double>(source.size());
  // The guess first: with prior 1 it wins every tie.
  for (const Eigen::Vector2d& p : source) {
    best.score_at_guess += field.At(T_target_source_guess * p) * inverse_n;
  }
  best.score = best.score_at_guess;
  // Translations move whole cells, so a rotated scan's cells are computed once per rotation.
  const int step_cells =
      std::max(1, static_cast<int>(std::lround(window.translation_step_m / field.cell_m())));
  const double step_m = step_cells * field.cell_m();
  const int translation_steps =
      window.translation_m > 0.0
          ? static_cast<int>(std::floor(window.translation_m / step_m + 1e-9))
          : 0;
  const int rotation_steps =
      window.rotation_rad > 0.0 && window.rotation_step_rad > 0.0
          ? static_cast<int>(std::floor(window.rotation_rad / window.rotation_step_rad + 1e-9))
          : 0;
  std::vector<int> columns(source.size());
  std::vector<int> rows(source.size());
  for (int ir = -rotation_steps; ir <= rotation_steps; ++ir) {
    const double rotation_offset_rad = ir * window.rotation_step_rad;
    const Pose2 rotated(T_target_source_guess.x, T_target_source_guess.y,
                        WrapAngle(T_target_source_guess.theta + rotation_offset_rad));
    for (std::size_t i = 0; i < source.size(); ++i) {
      const Eigen::Vector2d cell = field.CellCoordinates(rotated * source[i]);
      columns[i] = CellIndex(cell.x());
      rows[i] = CellIndex(cell.y());
    }
    const double rotation_prior =
        rotation_steps > 0 ? Square(rotation_offset_rad / window.rotation_rad) : 0.0;
    for (int iy = -translation_steps; iy <= translation_steps; ++iy) {
      for (int ix = -translation_steps; ix <= translation_steps; ++ix) {
        double sum = 0.0;
        for (std::size_t i = 0; i < source.size(); ++i) {
          sum += field.AtCell(columns[i] + ix * step_cells, rows[i] + iy * step_cells);
        }
        const double closeness = sum * inverse_n;
        const double translation_prior =
            translation_steps > 0
                ? (Square(ix * step_m) + Square(iy * step_m)) / Square(window.translation_m)
                : 0.0;
        const double score = closeness * std::exp(-0.5 * (translation_prior + rotation_prior));
        if (score > best.score) {
          best.score = score;
          best.moved = ix != 0 || iy != 0 || ir != 0;
          best.T_target_source =
              Pose2(rotated.x + ix * step_m, rotated.y + iy * step_m, rotated.theta);
        }
      }
    }
  }
  return best;
}

}  // namespace keyplace
