#pragma once
// An occupancy probability grid of a few registered scans, and the refinement of a scan's pose
// against it (scan-to-map matching as Cartographer's 2D front end does it, Hess et al. 2016:
// bicubic interpolation of the grid, solved by Ceres). ICP pairs points with lines fitted to a
// few neighbours; the grid pools every beam of the local map instead, its hits and the free space
// its rays crossed, which is what a scan with few points on far walls needs.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <vector>

#include <Eigen/Core>

#include "keyplace/common/pose2.hpp"

namespace keyplace {

/// One scan in the world frame: where the laser stood and where its beams ended.
struct GridScan {
  Eigen::Vector2d origin_world;
  std::vector<Eigen::Vector2d> points_world;
};

/// Occupancy of the last few scans on a square grid that follows the robot: a beam's end cell
/// counts as a hit, the cells its ray crossed before it as misses, each cell at most once per
/// scan (a hit wins), and a cell's log-odds is the sum of its hits' and misses' (Cartographer's
/// inserter probabilities, 0.55 and 0.49). Counting them lets the oldest scan be taken out
/// exactly, so a scan costs one insertion and one removal instead of a rebuild per key scan.
/// The grid is `width_cells` cells per side, centred on a scan's origin; when a new scan's origin
/// lies more than a quarter of the width from the centre (L∞), it is centred again on that origin
/// and refilled from the scans it holds. What lies beyond it is left out, and a point there costs
/// what an unobserved cell does. Memory: 12 bytes per cell, plus 4 bytes per cell each held scan
/// touched (its hits and the cells its rays crossed).
class ProbabilityGrid {
 public:
  /// Throws std::invalid_argument unless cell_m is finite and > 0 and width_cells in [8, 8192].
  ProbabilityGrid(double cell_m, int width_cells);
  ProbabilityGrid(const ProbabilityGrid&) = delete;
  ProbabilityGrid& operator=(const ProbabilityGrid&) = delete;
  ProbabilityGrid(ProbabilityGrid&&) = default;
  ProbabilityGrid& operator=(ProbabilityGrid&&) = default;

  /// Adds the newest scan. A scan with a non-finite origin is left out, as are non-finite points.
  /// Throws std::length_error when kMaxScans are held already: a cell's counts are 16-bit.
  void Push(GridScan scan);
  /// Takes the oldest scan out (none: no effect).
  void Pop();
  std::size_t num_scans() const { return scans_.size(); }

  int width() const { return width_; }
  double cell_m() const { return cell_m_; }
  /// The world position of the centre of cell (0, 0); cell (c, r) is centred at origin + (c,
  /// r)·cell.
  const Eigen::Vector2d& origin() const { return origin_; }
  /// P(occupied) of cell (column, row), clamped to [kMinProbability, kMaxProbability];
  /// kMinProbability for a cell no ray reached or one outside the grid.
  double Probability(int column, int row) const;
  /// 1 − Probability for every cell, row by row: what the matcher interpolates.
  const std::vector<float>& correspondence_costs() const { return costs_; }

  static constexpr double kMinProbability = 0.1;
  static constexpr double kMaxProbability = 0.9;
  static constexpr std::size_t kMaxScans = 32767;

 private:
  struct Inserted {
    GridScan scan;
    std::vector<std::int32_t> hit_cells;
    std::vector<std::int32_t> miss_cells;
  };
  void CentreOn(const Eigen::Vector2d& position_world);
  Eigen::Vector2d Centre() const;  // where the grid was last centred
  void Insert(Inserted& inserted);
  void Count(const std::vector<std::int32_t>& cells, std::vector<std::int16_t>& counts, int sign);
  void UpdateCost(std::int32_t index);
  static float CostOfCounts(int hits, int misses);
  // Costs of the counts below this, computed once (a cell counts at most one hit or miss per
  // scan it holds).
  static constexpr int kCountTableSize = 128;
  std::int32_t IndexOf(const Eigen::Vector2d& point_world) const;  // -1 outside

  double cell_m_;
  int width_;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  std::deque<Inserted> scans_;
  std::vector<std::int16_t> hits_;
  std::vector<std::int16_t> misses_;
  std::vector<float> costs_;
  std::vector<float> cost_of_counts_;     // kCountTableSize² entries, hits major
  std::vector<std::uint32_t> last_scan_;  // the scan that last updated the cell (dedup)
  std::uint32_t scan_counter_ = 0;
};

/// The mean correspondence cost (1 − P, bicubically interpolated) of the points at a pose: how
/// well the grid supports it, from kMinProbability (every point on a certain hit) to 0.9.
double MeanGridCost(const ProbabilityGrid& grid, const std::vector<Eigen::Vector2d>& points_laser,
                    const Pose2& T_world_laser);

struct GridMatch {
  Pose2 T_world_laser;
  bool converged = false;  // Ceres reported a usable solution
};

/// The pose of `points_laser` that best fits the grid near `initial_T_world_laser`: the sum of
/// the points' squared correspondence costs (1 − P, bicubically interpolated), weighted 1 / √n,
/// plus the squared translation and rotation from the initial pose weighted 10 per metre and 40
/// per radian (Cartographer's published 2D defaults: occupied_space_weight 1,
/// translation_weight 10, rotation_weight 40), solved by Ceres from the initial pose.
GridMatch MatchOnGrid(const ProbabilityGrid& grid, const std::vector<Eigen::Vector2d>& points_laser,
                      const Pose2& initial_T_world_laser);

}  // namespace keyplace
