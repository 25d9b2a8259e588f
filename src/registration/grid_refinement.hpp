#pragma once
// Scan-to-map refinement on a smoothed occupancy grid (the likelihood field of Thrun et al.,
// Probabilistic Robotics, 6.4; the way Cartographer's real-time front end refines a scan against
// its submap, Hess et al. 2016): Ceres moves the pose so that the scan's points fall where the
// field is high, held near the start by a prior, with the field interpolated bicubically so the
// cost is smooth. No normals are needed, which is what ICP lacks on sparse scans.

#include <vector>

#include <Eigen/Core>

#include "correlative_search.hpp"
#include "keyplace/common/pose2.hpp"

namespace keyplace {

struct GridRefinementWeights {
  // Residuals: the points' (1 - field) scaled by occupied / sqrt(points), and the pose's offset
  // from the start, translation (per m) and rotation (per rad). Cartographer's 2D defaults are
  // 1, 10 and 40 (its trajectory_builder_2d.lua).
  double occupied = 1.0;
  double translation_per_m = 10.0;
  double rotation_per_rad = 40.0;
};

struct GridRefinement {
  Pose2 T_target_source;
  bool usable = false;       // Ceres returned a usable solution
  double mean_field = 0.0;   // mean field value of the points at the result
  double start_field = 0.0;  // the same at the start
};

/// Refines `start` (the source points' pose in the field's frame) against `field`.
GridRefinement RefineOnField(const ProximityField& field,
                             const std::vector<Eigen::Vector2d>& source, const Pose2& start,
                             const GridRefinementWeights& weights);

}  // namespace keyplace
