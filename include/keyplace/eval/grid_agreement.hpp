#pragma once
// How well an occupancy grid (e.g. from SLAM) agrees with a reference grid (the same scans at the
// corrected poses): the check that a grid handed to a navigation stack is the building's.

#include <cstddef>

#include "keyplace/common/pose2.hpp"
#include "keyplace/mapping/occupancy_grid.hpp"

namespace keyplace {

struct GridAgreement {
  double tolerance_m = 0.0;
  std::size_t occupied = 0;            // occupied cells of the estimate
  std::size_t occupied_reference = 0;  // occupied cells of the reference
  // Share of the estimate's occupied cells with an occupied reference cell within tolerance_m
  // (a precision), and of the reference's occupied cells with an occupied estimate cell within
  // tolerance_m (a recall).
  double occupied_matched = 0.0;
  double reference_matched = 0.0;
  // Share of the estimate's occupied cells with only free reference cells within tolerance_m:
  // walls where the reference saw free space (the sign of a wrong loop or a broken map).
  double occupied_on_free = 0.0;
};

/// Compares `estimate` with `reference`; `T_reference_estimate` maps the estimate's frame into
/// the reference's (for SLAM: the ATE alignment). Cell states follow `config`'s thresholds.
GridAgreement CompareOccupancyGrids(const OccupancyGrid& estimate, const OccupancyGrid& reference,
                                    const Pose2& T_reference_estimate,
                                    const OccupancyGridConfig& config, double tolerance_m);

}  // namespace keyplace
