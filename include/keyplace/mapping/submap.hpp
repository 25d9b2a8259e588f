#pragma once
// A submap S = {P, F} (paper Eq. 6): the poses of its scans and its stable keypoints, plus the
// binary occupancy needed later for overlap measures.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"
#include "keyplace/features/descriptor.hpp"

namespace keyplace {

struct StableKeypoint {
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();  // submap frame (robot frame of P[0])
  double orientation_rad = 0.0;                          // submap frame
  double scale_m = 0.0;
  int scale_level = 0;
  int scan_index = 0;      // the log scan this instance was detected in
  float stability = 0.0f;  // s of its cell when the submap was completed
  int occurrences = 0;     // occ: size of the cell's largest history cluster
  BetaGridDescriptor descriptor{};
};

/// Binary occupancy of a submap: the cells of G that some beam ended in, in the submap frame.
struct OccupancySummary {
  double cell_size_m = 0.0;
  std::vector<Eigen::Vector2i> cells;  // cell (i, j) covers [i l, (i+1) l) x [j l, (j+1) l)
};

struct Submap {
  int id = 0;
  std::vector<int> scan_indices;          // log scans, in insertion order
  std::vector<Pose2> poses;               // P: T_world_robot of each scan; P[0] is the submap frame
  std::vector<StableKeypoint> keypoints;  // F
  OccupancySummary occupancy;
  double overlap = 1.0;       // rho when completed
  double distribution = 1.0;  // delta when completed
  bool forced = false;        // closed by max_scans_per_submap, not by the criteria

  const Pose2& origin() const { return poses.front(); }
  int first_scan() const { return scan_indices.front(); }
  int last_scan() const { return scan_indices.back(); }
};

}  // namespace keyplace
