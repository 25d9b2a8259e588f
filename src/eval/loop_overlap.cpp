#include "keyplace/eval/loop_overlap.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <unordered_set>

namespace keyplace {
namespace {

std::uint64_t Key(std::int64_t i, std::int64_t j) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(i)) << 32) |
         static_cast<std::uint32_t>(j);
}

using CellSet = std::unordered_set<std::uint64_t>;

CellSet CellsOf(const OccupancySummary& summary) {
  CellSet cells;
  cells.reserve(summary.cells.size() * 2);
  for (const Eigen::Vector2i& c : summary.cells) cells.insert(Key(c.x(), c.y()));
  return cells;
}

// The cells of `summary` with their centres mapped by T_ref_cur, snapped to a grid of `cell_m`.
CellSet MappedCellsOf(const OccupancySummary& summary, const Pose2& T_ref_cur, double cell_m) {
  const double l = summary.cell_size_m;
  CellSet cells;
  cells.reserve(summary.cells.size() * 2);
  for (const Eigen::Vector2i& c : summary.cells) {
    const Eigen::Vector2d p = T_ref_cur * Eigen::Vector2d((c.x() + 0.5) * l, (c.y() + 0.5) * l);
    cells.insert(Key(static_cast<std::int64_t>(std::floor(p.x() / cell_m)),
                     static_cast<std::int64_t>(std::floor(p.y() / cell_m))));
  }
  return cells;
}

}  // namespace

double CommonAreaOverlap(const OccupancySummary& reference, const OccupancySummary& current,
                         const OccupancySummary& reference_observed,
                         const OccupancySummary& current_observed, const Pose2& T_ref_cur) {
  const double l = reference.cell_size_m;
  if (!(l > 0.0) || current.cell_size_m != l || reference_observed.cell_size_m != l ||
      current_observed.cell_size_m != l) {
    throw std::invalid_argument(
        "CommonAreaOverlap: the four occupancy summaries need the same positive cell_size_m");
  }
  const CellSet reference_hit = CellsOf(reference);
  const CellSet reference_seen = CellsOf(reference_observed);
  const CellSet current_hit = MappedCellsOf(current, T_ref_cur, l);
  const CellSet current_seen = MappedCellsOf(current_observed, T_ref_cur, l);
  std::size_t intersection = 0;
  std::size_t union_size = 0;
  for (std::uint64_t key : reference_hit) {
    if (current_seen.count(key) == 0) continue;
    ++union_size;
    intersection += current_hit.count(key);
  }
  for (std::uint64_t key : current_hit) {
    if (reference_seen.count(key) != 0 && reference_hit.count(key) == 0) ++union_size;
  }
  return union_size == 0 ? 0.0 : static_cast<double>(intersection) / union_size;
}

double OccupancyOverlap(const OccupancySummary& reference, const OccupancySummary& current,
                        const Pose2& T_ref_cur, double cell_m) {
  if (reference.cells.empty() && current.cells.empty()) return 0.0;
  const double l_ref = reference.cell_size_m;
  const double l_cur = current.cell_size_m;
  if (!(l_ref > 0.0) || (!current.cells.empty() && !(l_cur > 0.0))) {
    throw std::invalid_argument("OccupancyOverlap: cell_size_m must be > 0");
  }
  if (cell_m < 0.0) throw std::invalid_argument("OccupancyOverlap: cell_m must be >= 0");
  const double l = cell_m > 0.0 ? cell_m : l_ref;
  const CellSet a = cell_m > 0.0 ? MappedCellsOf(reference, Pose2(), l) : CellsOf(reference);
  const CellSet b = MappedCellsOf(current, T_ref_cur, l);
  std::size_t intersection = 0;
  for (std::uint64_t key : b) intersection += a.count(key);
  const std::size_t union_size = a.size() + b.size() - intersection;
  return union_size == 0 ? 0.0 : static_cast<double>(intersection) / union_size;
}

OverlapHistogram HistogramOfOverlaps(const std::vector<double>& overlaps) {
  OverlapHistogram histogram;
  for (double overlap : overlaps) {
    std::size_t bin = 4;
    for (std::size_t k = 0; k < 4; ++k) {
      if (overlap < OverlapHistogram::kEdges[k + 1]) {
        bin = k;
        break;
      }
    }
    ++histogram.counts[bin];
    ++histogram.total;
  }
  return histogram;
}

double LoopPrecision(const std::vector<double>& overlaps, double min_overlap) {
  if (overlaps.empty()) return 0.0;
  const auto correct = std::count_if(overlaps.begin(), overlaps.end(),
                                     [&](double overlap) { return overlap >= min_overlap; });
  return static_cast<double>(correct) / overlaps.size();
}

}  // namespace keyplace
