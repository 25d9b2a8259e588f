#pragma once
// A global occupancy grid from scans at known poses (corrected, or a SLAM trajectory): what a
// navigation stack (ROS map_server, nav2/AMCL, move_base) loads as its map. Each beam marks the
// cells it crosses as free and the cell it ends in as occupied, in log-odds (docs/NAVIGATION.md).

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"
#include "keyplace/io/laser_scan.hpp"

namespace keyplace {

struct OccupancyGridConfig {
  double resolution_m = 0.05;  // side of a cell (map_server's `resolution`)
  // Occupancy probability a beam's endpoint gives its cell, and the one each crossed cell gets;
  // they add as log-odds and are clamped to [min_probability, max_probability].
  double hit_probability = 0.7;
  double miss_probability = 0.4;
  double min_probability = 0.12;
  double max_probability = 0.97;
  // Classify the cells for the trinary image: probability >= occupied_thresh is occupied (pixel
  // 0), <= free_thresh free (254), else unknown (205). 0.65 and 0.196 are map_saver's values.
  // The YAML always carries the thresholds that decode those pixels (map_server.hpp).
  double occupied_thresh = 0.65;
  double free_thresh = 0.196;
  // Beams are traced at most this far (a no-return beam is not traced): far beams at grazing
  // angles mostly add noise to a map meant for navigation.
  double max_trace_range_m = 30.0;
  // The grid never has more cells than this (a pose glitch of kilometres is an error, not a
  // gigabyte image); 2^26 cells are 410 m x 410 m at 5 cm, 9 bytes each while building.
  std::int64_t max_cells = std::int64_t{1} << 26;
};

/// Throws std::invalid_argument naming the first invalid field.
void Validate(const OccupancyGridConfig& config);

enum class CellState : std::uint8_t { kUnknown, kFree, kOccupied };

struct OccupancyGrid {
  double resolution_m = 0.05;
  // World position of the lower-left corner of cell (0, 0) (map_server's `origin`, yaw 0).
  Eigen::Vector2d origin_m = Eigen::Vector2d::Zero();
  int width = 0;   // cells along x
  int height = 0;  // cells along y
  // Row-major from the bottom row (y = origin.y) up; 0 for a cell no beam reached.
  std::vector<float> log_odds;
  std::vector<std::uint8_t> observed;  // 1 when some beam reached the cell

  /// Occupancy probability of cell (column, row) of an observed cell; 0.5 when unobserved.
  double Probability(int column, int row) const;
  /// The cell's state under the config's thresholds.
  CellState State(int column, int row, const OccupancyGridConfig& config) const;
  /// Cell holding a world point; false when the point is outside the grid.
  bool CellOf(const Eigen::Vector2d& point_m, int& column, int& row) const;
  std::size_t Index(int column, int row) const {
    return static_cast<std::size_t>(row) * static_cast<std::size_t>(width) +
           static_cast<std::size_t>(column);
  }
};

/// The grid of `scans` seen from robot poses `T_world_robot` (one per scan; the laser is at
/// T_world_robot * scan.T_robot_laser). The grid covers every traced beam plus one cell. Throws
/// std::invalid_argument when the sizes differ, the config is invalid, or the grid would exceed
/// config.max_cells (naming its extent and suggesting a coarser resolution).
OccupancyGrid BuildOccupancyGrid(const std::vector<const LaserScan*>& scans,
                                 const std::vector<Pose2>& T_world_robot,
                                 const OccupancyGridConfig& config);

}  // namespace keyplace
