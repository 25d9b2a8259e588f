#pragma once
// Loop closure correctness without ground truth (paper Section 6.2.2): the overlap rate of two
// matched submaps, its histogram and the loop precision at an overlap threshold.

#include <array>
#include <cstddef>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/mapping/submap.hpp"

namespace keyplace {

/// Intersection over union of the binary occupancy of two submaps, with `current` mapped into
/// the frame of `reference` by T_ref_cur: each occupied cell centre of `current` is transformed
/// and snapped to the reference grid (cell size of `reference`); the rate is
/// |A ∩ B| / |A ∪ B| over the distinct cells. In [0, 1]; 0 when both are empty. `cell_m` > 0
/// compares on a coarser grid of that size instead (both sides' cell centres snapped to it), a
/// sensitivity check: at 0.1 m a 5 cm misregistration of a wall already halves the rate. Throws
/// std::invalid_argument when a cell size is not positive.
double OccupancyOverlap(const OccupancySummary& reference, const OccupancySummary& current,
                        const Pose2& T_ref_cur, double cell_m = 0.0);

/// The same intersection over union of the two submaps' occupied (hit) cells, counted only over
/// the cells that *both* submaps observed (a beam of each ended in or crossed the cell;
/// `reference_observed`, `current_observed`, e.g. OnlineSlam::ObservedArea): a cell occupied in
/// one submap and outside the other's observed area is no disagreement, the other never looked
/// there. Occupied cells of a submap are expected inside its observed area. All four summaries
/// must have the same positive cell size (std::invalid_argument otherwise); `current`'s cell
/// centres are mapped by T_ref_cur and snapped to the reference grid. In [0, 1]; 0 when no
/// occupied cell lies in the common area.
double CommonAreaOverlap(const OccupancySummary& reference, const OccupancySummary& current,
                         const OccupancySummary& reference_observed,
                         const OccupancySummary& current_observed, const Pose2& T_ref_cur);

/// The paper's bins of overlap rate: [0,10), [10,20), [20,30), [30,40), [40,100] %.
struct OverlapHistogram {
  static constexpr std::array<double, 6> kEdges{0.0, 0.1, 0.2, 0.3, 0.4, 1.0};
  std::array<std::size_t, 5> counts{};
  std::size_t total = 0;
};
OverlapHistogram HistogramOfOverlaps(const std::vector<double>& overlaps);

/// Fraction of loops whose overlap is >= `min_overlap` (a loop counts as correct then); 0 for
/// no loops.
double LoopPrecision(const std::vector<double>& overlaps, double min_overlap);

}  // namespace keyplace
