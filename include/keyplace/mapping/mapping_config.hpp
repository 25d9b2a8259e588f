#pragma once
// Parameters of stable-keypoint mapping (paper Section 3, defaults from Table V and Section 5.2).

#include <cstdint>

namespace keyplace {

struct MappingConfig {
  // --- stability grid G (Section 3.1.1)
  double cell_size_m = 0.10;           // l_g: side of a cell of G
  double min_stability = 0.3;          // s_min: a cell's keypoint is stable when s >= s_min
  int min_scan_count = 4;              // ns_min: s = d * occ / max(ns, ns_min)
  double descriptor_match_chi2 = 0.4;  // similar descriptors: symmetric chi2 below this
  // How h and m of the density d = h / (h + m) are counted. kScans: once per scan, h when one of
  // its beams ends in the cell, m when its beams only cross it (a wall cell grazed by the beams
  // to the next wall points of the same scan stays occupied). kBeams: once per beam.
  enum class DensityCounting { kScans, kBeams };
  DensityCounting density_counting = DensityCounting::kScans;

  // Which member of a history cluster a new keypoint is compared with. The paper says "look for a
  // match with keypoints in every history cluster": kAnyMember joins the first (largest) cluster
  // holding any keypoint within descriptor_match_chi2; kLatestMember compares with the cluster's
  // most recent keypoint only (cheaper, and follows a slowly changing descriptor).
  enum class ClusterMatch { kAnyMember, kLatestMember };
  ClusterMatch cluster_match = ClusterMatch::kAnyMember;

  // --- submap completion (Sections 3.1.3 and 5.2)
  double min_overlap = 0.75;  // rho_min: complete once rho = a_int / a_uni < rho_min
  // Cells that make the binary occupancy grids of rho: kHit = cells some beam ended in (the
  // occupied cells), kObserved = cells some beam ended in or crossed (the seen area).
  enum class OverlapCells { kHit, kObserved };
  OverlapCells overlap_cells = OverlapCells::kObserved;
  bool use_distribution = true;      // also require delta <= max_distribution (Section 5.2)
  double max_distribution = 0.5;     // delta_max
  double distribution_cell_m = 0.5;  // l: cell of the grid D of the histograms of delta
  // Which cells of G are the "laser points" of h_lp: kHit = every cell a beam ended in;
  // kOccupied = cells of the occupancy grid, d = h / (h + m) > 0.5; kPersistent = occupied cells
  // hit by at least ns_min scans (the cells whose keypoints could reach s_min). See
  // docs/MAPPING.md for why the default is kPersistent.
  enum class LaserCells { kHit, kOccupied, kPersistent };
  LaserCells distribution_laser_cells = LaserCells::kHit;
  // What the binary histograms are divided by: kPoints = "normalized with the respective
  // population in each category of points" read literally, the number of laser points and of
  // stable keypoints (then delta <= 1 as the paper says, and it reproduces the paper's delta);
  // kCells = the number of occupied cells of each histogram (each sums to 1).
  enum class DistributionNormalization { kPoints, kCells };
  DistributionNormalization distribution_normalization = DistributionNormalization::kPoints;
  int min_stable_keypoints = 10;  // and at least this many stable keypoints (Section 5.2)
  // Absent from the paper: a submap is also complete once the robot has travelled this far since
  // its first scan (its path length, which bounds its extent: no pose lies farther than this
  // from the origin), whatever rho, delta and the keypoint count say. In open halls delta stays
  // above delta_max for tens of metres; on FR079 and Intel every submap the criteria close is
  // shorter than this (docs/MAPPING.md). 0 = no bound.
  double max_path_m = 8.0;
  // Safety net absent from the paper: a submap that has not met the criteria after this many
  // scans is closed anyway and flagged `forced` (0 = never; then Algorithm 2 stops at the first
  // submap that cannot be completed, as in the paper).
  int max_scans_per_submap = 300;
  // Safety net absent from the paper, bounding memory: G spans the bounding box of the submap's
  // beams (plus a margin); its counters, sizeof(CellCounts) = 20 bytes per cell, are allocated
  // in tiles of 16 x 16 cells where beams pass, so the box bounds them. A scan that would grow
  // the box beyond this many cells (a pose jump: an odometry glitch) closes the submap instead:
  // its pose is kept, its beams and keypoints are not inserted, and the submap is flagged
  // `forced`. A single scan that needs more on its own is an error. See docs/MAPPING.md. The
  // default, 2^24 cells (about 320 MiB of counters at most: tiles at the box's edges are whole),
  // holds 400 m x 400 m at l_g = 0.1 m.
  std::int64_t max_grid_cells = std::int64_t{1} << 24;
};

// Bounds of the cell sides (cell_size_m, distribution_cell_m, and the occupancy of a stored
// submap). Below 1 cm a cell is finer than the range noise of 2D lidars (1-3 cm), so a keypoint
// cannot reappear in its cell, and G's cell budget (max_grid_cells) would hold less than one scan;
// above 10 m a cell holds a whole room and "the same cell" means nothing. Both bounds also keep
// infinite and NaN sides, which passed "positive", out of the grids (docs/MAPPING.md).
constexpr double kMinCellSizeM = 0.01;
constexpr double kMaxCellSizeM = 10.0;
constexpr double kMaxDistributionCellM = 100.0;
// Upper bound of max_grid_cells: 2^28 cells of 20 bytes (5 GiB), 1.6 km x 1.6 km at l_g = 0.1 m;
// a submap needing more is a pose glitch, and a stored map cannot ask for more memory than this.
constexpr std::int64_t kMaxGridCellsLimit = std::int64_t{1} << 28;

/// Throws std::invalid_argument naming the first invalid field. Every real field must be finite.
void Validate(const MappingConfig& config);

}  // namespace keyplace

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace keyplace {

/// Every field as (name, text value), in declaration order; enums as lower-case names.
std::vector<std::pair<std::string, std::string>> ToKeyValues(const MappingConfig& config);

/// Sets the named fields of `config` from text. Throws std::invalid_argument naming the key for
/// an unknown key or a value that does not parse. The result is validated.
void ApplyKeyValues(const std::map<std::string, std::string>& values, MappingConfig& config);

/// ApplyKeyValues for the configuration recorded in a map file: a setting added after the map
/// was written (absent from `values`) takes the value that reproduces how the map was built
/// (max_path_m = 0, no bound), so that its queries complete as its submaps did.
void ApplyStoredKeyValues(const std::map<std::string, std::string>& values, MappingConfig& config);

}  // namespace keyplace
