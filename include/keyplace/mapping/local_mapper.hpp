#pragma once
// Local mapping (paper Algorithm 1): builds one submap from consecutive registered scans.

#include <cstdint>
#include <unordered_set>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/features/keypoint.hpp"
#include "keyplace/io/laser_scan.hpp"
#include "keyplace/mapping/mapping_config.hpp"
#include "keyplace/mapping/stability_grid.hpp"
#include "keyplace/mapping/submap.hpp"

namespace keyplace {

/// Spatial distribution distance delta (Eq. 8): symmetric chi2 between the binary histograms, on
/// a grid of `cell_m`, of the laser points and of the keypoints, each divided by its population
/// (number of points, or number of occupied cells). In [0, 1].
double DistributionDistance(const std::vector<Eigen::Vector2d>& laser_points_m,
                            const std::vector<Eigen::Vector2d>& keypoints_m, double cell_m,
                            MappingConfig::DistributionNormalization normalization);

class LocalMapper {
 public:
  explicit LocalMapper(const MappingConfig& config = {});

  /// Starts a new, empty submap.
  void Reset();

  /// Adds the next scan: its laser data, the robot pose T_world_robot and its keypoints (laser
  /// frame). Runs UpdateG and UpdateS; returns true when the submap is complete after this scan.
  /// A scan whose beams would grow G beyond MappingConfig::max_grid_cells (a pose jump) completes
  /// the submap (forced, grid_limited()) with its pose but without its beams and keypoints.
  /// Throws std::invalid_argument naming the scan, leaving the mapper unchanged, when the pose,
  /// the laser mounting, a valid beam's endpoint or a keypoint is not finite, or when the scan
  /// alone, as the first of a submap, needs more than max_grid_cells.
  bool AddScan(int scan_index, const LaserScan& scan, const Pose2& T_world_robot,
               const std::vector<Keypoint>& keypoints);

  /// The submap as it stands (F from the latest UpdateS).
  Submap Snapshot() const;

  std::size_t scan_count() const { return poses_.size(); }
  std::size_t stable_count() const { return stable_.size(); }
  double overlap() const { return overlap_; }
  double distribution() const { return distribution_; }
  bool complete() const { return complete_; }
  bool forced() const { return forced_; }
  /// Robot path length since the submap's first scan, and the largest distance of a robot
  /// position from the first one (never more than the path length).
  double path_m() const { return path_m_; }
  double extent_m() const { return extent_m_; }
  /// The submap was completed by MappingConfig::max_path_m, not by the paper's criteria.
  bool path_limited() const { return path_limited_; }
  /// The submap was closed because a scan did not fit in max_grid_cells (then also forced()).
  bool grid_limited() const { return grid_limited_; }
  const StabilityGrid& grid() const { return grid_; }

 private:
  void UpdateCompletion();
  std::int64_t OverlapCellCount() const;
  // Cells G would hold after inserting these (submap frame); int64 max when a point has no cell.
  std::int64_t CellsNeeded(const Eigen::Vector2d& origin_m,
                           const std::vector<Eigen::Vector2d>& endpoints_m,
                           const std::vector<GridKeypoint>& keypoints) const;

  MappingConfig config_;
  StabilityGrid grid_;
  std::vector<int> scan_indices_;
  std::vector<Pose2> poses_;
  std::vector<StabilityGrid::Selected> stable_;
  std::vector<CellIndex> hit_cells_;  // cells of G hit so far, in order of their first hit
  std::size_t laser_points_ = 0;      // valid beam endpoints inserted so far
  std::int64_t initial_cells_ = 0;
  double overlap_ = 1.0;
  double distribution_ = 1.0;
  double path_m_ = 0.0;
  double extent_m_ = 0.0;
  bool complete_ = false;
  bool forced_ = false;
  bool grid_limited_ = false;
  bool path_limited_ = false;
};

}  // namespace keyplace
