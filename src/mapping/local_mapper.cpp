#include "keyplace/mapping/local_mapper.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>

namespace keyplace {
namespace {

// floor(coordinate / cell), saturated to the int range (NaN to its lower end) instead of an
// undefined conversion. Points of a submap lie far inside it (StabilityGrid::kMaxCellIndex).
int SaturatedCell(double coordinate_m, double cell_m) {
  const double cell = std::floor(coordinate_m / cell_m);
  if (!(cell >= std::numeric_limits<int>::min())) return std::numeric_limits<int>::min();
  if (!(cell <= std::numeric_limits<int>::max())) return std::numeric_limits<int>::max();
  return static_cast<int>(cell);
}

std::int64_t DistributionKey(const Eigen::Vector2d& point_m, double cell_m) {
  return CellKey(SaturatedCell(point_m.x(), cell_m), SaturatedCell(point_m.y(), cell_m));
}

bool Finite(const Pose2& pose) {
  return std::isfinite(pose.x) && std::isfinite(pose.y) && std::isfinite(pose.theta);
}

std::string PoseText(const Pose2& pose) {
  std::ostringstream text;
  text << "(" << pose.x << ", " << pose.y << ", " << pose.theta << ")";
  return text.str();
}

[[noreturn]] void FailScan(int scan_index, const std::string& what) {
  throw std::invalid_argument("LocalMapper: scan " + std::to_string(scan_index) + ": " + what);
}

// delta from the two sets of occupied cells of D; every keypoint cell normally holds laser
// points too (keypoints are beam endpoints), but the formula does not rely on it.
double DistributionFromCells(const std::unordered_set<std::int64_t>& laser_cells,
                             std::size_t laser_population,
                             const std::unordered_set<std::int64_t>& keypoint_cells,
                             std::size_t keypoint_population) {
  if (keypoint_cells.empty() || laser_cells.empty()) return 1.0;
  const double q = 1.0 / static_cast<double>(laser_population);
  const double p = 1.0 / static_cast<double>(keypoint_population);
  double distance = 0.0;
  std::size_t shared = 0;
  for (const auto cell : keypoint_cells) {
    if (laser_cells.count(cell) != 0) {
      ++shared;
      distance += 0.5 * (q - p) * (q - p) / (q + p);
    } else {
      distance += 0.5 * p;
    }
  }
  distance += 0.5 * q * static_cast<double>(laser_cells.size() - shared);
  return distance;
}

}  // namespace

double DistributionDistance(const std::vector<Eigen::Vector2d>& laser_points_m,
                            const std::vector<Eigen::Vector2d>& keypoints_m, double cell_m,
                            MappingConfig::DistributionNormalization normalization) {
  std::unordered_set<std::int64_t> laser_cells;
  std::unordered_set<std::int64_t> keypoint_cells;
  for (const auto& point : laser_points_m) laser_cells.insert(DistributionKey(point, cell_m));
  for (const auto& point : keypoints_m) keypoint_cells.insert(DistributionKey(point, cell_m));
  if (normalization == MappingConfig::DistributionNormalization::kCells) {
    return DistributionFromCells(laser_cells, laser_cells.size(), keypoint_cells,
                                 keypoint_cells.size());
  }
  return DistributionFromCells(laser_cells, laser_points_m.size(), keypoint_cells,
                               keypoints_m.size());
}

LocalMapper::LocalMapper(const MappingConfig& config) : config_(config), grid_(config) {}

void LocalMapper::Reset() {
  grid_.Clear();
  scan_indices_.clear();
  poses_.clear();
  stable_.clear();
  hit_cells_.clear();
  laser_points_ = 0;
  initial_cells_ = 0;
  overlap_ = 1.0;
  distribution_ = 1.0;
  path_m_ = 0.0;
  extent_m_ = 0.0;
  complete_ = false;
  forced_ = false;
  grid_limited_ = false;
  path_limited_ = false;
}

bool LocalMapper::AddScan(int scan_index, const LaserScan& scan, const Pose2& T_world_robot,
                          const std::vector<Keypoint>& keypoints) {
  // Everything is checked before anything changes: on an exception the mapper is as before.
  if (!Finite(T_world_robot))
    FailScan(scan_index, "robot pose " + PoseText(T_world_robot) + " is not finite");
  if (!Finite(scan.T_robot_laser)) {
    FailScan(scan_index, "laser mounting " + PoseText(scan.T_robot_laser) + " is not finite");
  }
  if (scan.valid.size() != scan.size() || scan.angles_rad.size() != scan.size()) {
    FailScan(scan_index, "ranges, angles and valid flags differ in size");
  }
  const bool first = poses_.empty();
  const Pose2& T_world_submap = first ? T_world_robot : poses_.front();
  const Pose2 T_submap_laser = Between(T_world_submap, T_world_robot) * scan.T_robot_laser;

  std::vector<Eigen::Vector2d> endpoints_m;
  endpoints_m.reserve(scan.size());
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan.valid[i] == 0) continue;
    endpoints_m.push_back(T_submap_laser * scan.Endpoint(i));
    if (!endpoints_m.back().allFinite()) {
      std::ostringstream what;
      what << "beam " << i << " (range " << scan.ranges_m[i] << " m, angle " << scan.angles_rad[i]
           << " rad) has no finite endpoint";
      FailScan(scan_index, what.str());
    }
  }
  std::vector<GridKeypoint> grid_keypoints;
  grid_keypoints.reserve(keypoints.size());
  for (const Keypoint& keypoint : keypoints) {
    GridKeypoint grid_keypoint;
    grid_keypoint.position_m = T_submap_laser * keypoint.position_m;
    grid_keypoint.orientation_rad = WrapAngle(keypoint.orientation_rad + T_submap_laser.theta);
    grid_keypoint.scale_m = keypoint.scale_m;
    grid_keypoint.scale_level = keypoint.scale_level;
    grid_keypoint.scan_index = scan_index;
    grid_keypoint.descriptor = keypoint.descriptor;
    if (!grid_keypoint.position_m.allFinite() || !std::isfinite(grid_keypoint.orientation_rad)) {
      FailScan(scan_index, "a keypoint has no finite position or orientation");
    }
    grid_keypoints.push_back(grid_keypoint);
  }
  const std::int64_t cells = CellsNeeded(T_submap_laser.translation(), endpoints_m, grid_keypoints);
  if (cells > config_.max_grid_cells) {
    if (first) {
      double farthest_m = 0.0;
      for (const auto& endpoint : endpoints_m) {
        farthest_m = std::max(farthest_m, (endpoint - T_submap_laser.translation()).norm());
      }
      std::ostringstream what;
      what << "alone it would grow the stability grid beyond MappingConfig.max_grid_cells = "
           << config_.max_grid_cells << " (its farthest beam ends " << farthest_m
           << " m from the laser); raise max_grid_cells or cell_size_m";
      FailScan(scan_index, what.str());
    }
    // A pose jump: close the submap with the scan's pose but without its data (MappingConfig).
    scan_indices_.push_back(scan_index);
    poses_.push_back(T_world_robot);
    grid_limited_ = true;
    complete_ = true;
    forced_ = true;
    return complete_;
  }
  if (!first) {
    path_m_ += (T_world_robot.translation() - poses_.back().translation()).norm();
    extent_m_ =
        std::max(extent_m_, (T_world_robot.translation() - T_world_submap.translation()).norm());
  }
  scan_indices_.push_back(scan_index);
  poses_.push_back(T_world_robot);

  // UpdateG: counters by ray casting, then the keypoint histories.
  grid_.InsertRays(T_submap_laser.translation(), endpoints_m, static_cast<int>(poses_.size()) - 1);
  laser_points_ += endpoints_m.size();
  hit_cells_.insert(hit_cells_.end(), grid_.newly_hit_cells().begin(),
                    grid_.newly_hit_cells().end());
  for (const GridKeypoint& grid_keypoint : grid_keypoints) grid_.InsertKeypoint(grid_keypoint);
  if (first) initial_cells_ = OverlapCellCount();

  // UpdateS: F is overwritten with the current stable keypoints.
  stable_ = grid_.SelectStable();
  UpdateCompletion();
  return complete_;
}

std::int64_t LocalMapper::CellsNeeded(const Eigen::Vector2d& origin_m,
                                      const std::vector<Eigen::Vector2d>& endpoints_m,
                                      const std::vector<GridKeypoint>& keypoints) const {
  constexpr std::int64_t kNoCell = std::numeric_limits<std::int64_t>::max();
  for (const GridKeypoint& keypoint : keypoints) {
    if (!grid_.TryCellOf(keypoint.position_m)) return kNoCell;
  }
  if (endpoints_m.empty()) return grid_.allocated_cell_count();  // InsertRays grows nothing
  const std::optional<CellIndex> start = grid_.TryCellOf(origin_m);
  if (!start) return kNoCell;
  CellIndex min = *start;
  CellIndex max = *start;
  for (const auto& endpoint : endpoints_m) {
    const std::optional<CellIndex> cell = grid_.TryCellOf(endpoint);
    if (!cell) return kNoCell;
    min = {std::min(min.i, cell->i), std::min(min.j, cell->j)};
    max = {std::max(max.i, cell->i), std::max(max.j, cell->j)};
  }
  return grid_.CellsToCover(min, max);
}

std::int64_t LocalMapper::OverlapCellCount() const {
  return config_.overlap_cells == MappingConfig::OverlapCells::kHit ? grid_.hit_cell_count()
                                                                    : grid_.observed_cell_count();
}

void LocalMapper::UpdateCompletion() {
  // Cells are never removed from the binary grid, so the initial grid is a subset of the current
  // one: a_int = initial cells, a_uni = current cells.
  const std::int64_t current = OverlapCellCount();
  overlap_ = current > 0 ? static_cast<double>(initial_cells_) / static_cast<double>(current) : 1.0;
  std::unordered_set<std::int64_t> keypoint_cells;
  for (const auto& selected : stable_) {
    keypoint_cells.insert(
        DistributionKey(selected.keypoint.position_m, config_.distribution_cell_m));
  }
  std::unordered_set<std::int64_t> laser_cells;
  using LaserCells = MappingConfig::LaserCells;
  const LaserCells which = config_.distribution_laser_cells;
  for (const auto& cell : hit_cells_) {
    const CellCounts counts = grid_.Counts(cell);
    if (which != LaserCells::kHit && 2 * counts.hits <= counts.hits + counts.misses) continue;
    if (which == LaserCells::kPersistent && counts.scans_hit < config_.min_scan_count) continue;
    laser_cells.insert(DistributionKey(grid_.CellCenter(cell), config_.distribution_cell_m));
  }
  if (config_.distribution_normalization == MappingConfig::DistributionNormalization::kCells) {
    distribution_ = DistributionFromCells(laser_cells, laser_cells.size(), keypoint_cells,
                                          keypoint_cells.size());
  } else {
    distribution_ =
        DistributionFromCells(laser_cells, laser_points_, keypoint_cells, stable_.size());
  }
  if (grid_limited_) {  // sticky until Reset
    complete_ = forced_ = true;
    return;
  }
  complete_ = overlap_ < config_.min_overlap &&
              (!config_.use_distribution || distribution_ <= config_.max_distribution) &&
              static_cast<int>(stable_.size()) >= config_.min_stable_keypoints;
  if (!complete_ && config_.max_path_m > 0.0 && path_m_ >= config_.max_path_m) {
    complete_ = true;
    path_limited_ = true;
  }
  if (!complete_ && config_.max_scans_per_submap > 0 &&
      static_cast<int>(poses_.size()) >= config_.max_scans_per_submap) {
    complete_ = true;
    forced_ = true;
  }
}

Submap LocalMapper::Snapshot() const {
  Submap submap;
  submap.scan_indices = scan_indices_;
  submap.poses = poses_;
  submap.keypoints.reserve(stable_.size());
  for (const auto& selected : stable_) {
    StableKeypoint keypoint;
    keypoint.position_m = selected.keypoint.position_m;
    keypoint.orientation_rad = selected.keypoint.orientation_rad;
    keypoint.scale_m = selected.keypoint.scale_m;
    keypoint.scale_level = selected.keypoint.scale_level;
    keypoint.scan_index = selected.keypoint.scan_index;
    keypoint.stability = static_cast<float>(selected.stability);
    keypoint.occurrences = selected.occurrences;
    keypoint.descriptor = selected.keypoint.descriptor;
    submap.keypoints.push_back(keypoint);
  }
  submap.occupancy.cell_size_m = grid_.cell_size_m();
  for (const auto& cell : grid_.HitCells()) submap.occupancy.cells.emplace_back(cell.i, cell.j);
  submap.overlap = overlap_;
  submap.distribution = distribution_;
  submap.forced = forced_;
  return submap;
}

}  // namespace keyplace
