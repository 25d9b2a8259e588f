#pragma once
// The stability grid G of a submap under construction (paper Section 3.1.1, Eq. 1-5).
// Each cell counts beam hits h and misses m (ray casting), the number of scans ns that hit it,
// and keeps the history H of the keypoints that fell in it, grouped into clusters of similar
// descriptors sorted by decreasing size. Everything is in the submap frame.

#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "keyplace/features/keypoint.hpp"
#include "keyplace/mapping/mapping_config.hpp"

namespace keyplace {

/// Integer cell coordinates of G (column i along x, row j along y).
struct CellIndex {
  int i = 0;
  int j = 0;
  bool operator==(const CellIndex& other) const { return i == other.i && j == other.j; }
};

/// Packs a cell (i, j) into one 64-bit key: i in the high and j in the low 32 bits (two's
/// complement). Computed on unsigned values, so that negative cells are well defined (a left
/// shift of a negative value is undefined behaviour before C++20).
constexpr std::int64_t CellKey(int i, int j) {
  return static_cast<std::int64_t>(
      (static_cast<std::uint64_t>(static_cast<std::uint32_t>(i)) << 32) |
      static_cast<std::uint64_t>(static_cast<std::uint32_t>(j)));
}

struct CellCounts {
  std::int32_t hits = 0;             // h: beams that ended in the cell
  std::int32_t misses = 0;           // m: beams that crossed the cell without ending in it
  std::int32_t scans_hit = 0;        // ns: scans with at least one hit in the cell
  std::int32_t last_scan = -1;       // scan id of the latest hit (to count ns once per scan)
  std::int32_t last_miss_scan = -1;  // scan id of the latest miss (per-scan counting)
};

/// A keypoint of some scan, expressed in the submap frame.
struct GridKeypoint {
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  double orientation_rad = 0.0;
  double scale_m = 0.0;
  int scale_level = 0;
  int scan_index = 0;  // index of the scan in the log
  BetaGridDescriptor descriptor{};
};

class StabilityGrid {
 public:
  explicit StabilityGrid(const MappingConfig& config);

  void Clear();

  /// UpdateG's counters: ray-casts each endpoint from `origin_m` (both in the submap frame). The
  /// endpoint's cell gets a hit, every other cell the ray crosses a miss (counted per beam or
  /// once per scan, MappingConfig::density_counting). `scan_id` must grow. Throws
  /// std::invalid_argument, leaving the grid unchanged, when a point has no cell (CellOf) or
  /// the counters would grow beyond MappingConfig::max_grid_cells (CellsToCover).
  void InsertRays(const Eigen::Vector2d& origin_m, const std::vector<Eigen::Vector2d>& endpoints_m,
                  int scan_id);

  /// UpdateG's history: puts the keypoint into the cluster of its cell it matches (largest
  /// first), or into a new cluster; keeps clusters sorted by decreasing size (stable).
  void InsertKeypoint(const GridKeypoint& keypoint);

  /// Cells are indexed within +-kMaxCellIndex along each axis (about 54 000 km at 0.1 m cells),
  /// so that no index or grid size computation can overflow.
  static constexpr int kMaxCellIndex = 1 << 29;

  /// The cell of a point; nullopt when a coordinate is not finite or its cell index lies beyond
  /// +-kMaxCellIndex.
  std::optional<CellIndex> TryCellOf(const Eigen::Vector2d& point_m) const;
  /// TryCellOf, or std::invalid_argument naming the point when it has no cell.
  CellIndex CellOf(const Eigen::Vector2d& point_m) const;
  Eigen::Vector2d CellCenter(const CellIndex& cell) const;

  /// Cells of the grid's bounding box once grown to cover every cell from `min` to `max`
  /// (inclusive), as InsertRays grows it (with a margin). The current count when it already
  /// covers them.
  std::int64_t CellsToCover(const CellIndex& min, const CellIndex& max) const;
  /// Cells of the grown bounding box (CellsToCover's measure). Counters are allocated only in
  /// the tiles of 16 x 16 cells of it that beams have ended in or crossed.
  std::int64_t allocated_cell_count() const {
    return static_cast<std::int64_t>(width_) * static_cast<std::int64_t>(height_);
  }
  /// Counters of a cell (all zero outside the grown area).
  CellCounts Counts(const CellIndex& cell) const;

  /// Stability s = d * occ / max(ns, ns_min) of a cell, with d = h / (h + m) and occ the size of
  /// its largest history cluster (0 for a cell without keypoints).
  double Stability(const CellIndex& cell) const;

  /// UpdateS's selection: for every cell with a history and s >= s_min, the most recent keypoint
  /// of its largest cluster, in the order the cells first received a keypoint.
  struct Selected {
    GridKeypoint keypoint;
    double stability = 0.0;
    int occurrences = 0;  // occ
  };
  std::vector<Selected> SelectStable() const;

  /// History clusters of a cell (each a list of keypoints, oldest first), largest cluster first.
  std::vector<std::vector<GridKeypoint>> Clusters(const CellIndex& cell) const;

  /// Number of cells hit by at least one beam / hit or crossed by at least one beam.
  std::int64_t hit_cell_count() const { return hit_cells_; }
  std::int64_t observed_cell_count() const { return observed_cells_; }

  /// Cells hit by at least one beam.
  std::vector<CellIndex> HitCells() const;
  /// Cells hit or crossed by at least one beam (the observed area), row by row.
  std::vector<CellIndex> ObservedCells() const;
  /// Cells whose first hit came from the latest InsertRays call.
  const std::vector<CellIndex>& newly_hit_cells() const { return newly_hit_cells_; }

  double cell_size_m() const { return cell_size_m_; }

 private:
  struct Cluster {
    std::vector<int> members;  // indices into keypoints_, oldest first
  };
  struct History {
    CellIndex cell;
    std::vector<Cluster> clusters;  // sorted by decreasing size
  };

  void EnsureCovers(int min_i, int min_j, int max_i, int max_j);
  // Within the grown bounding box (its counters may not be allocated yet).
  bool InBox(int i, int j) const {
    return i >= origin_i_ && j >= origin_j_ && i < origin_i_ + width_ && j < origin_j_ + height_;
  }
  // The counters of a cell InBox: nullptr while its tile holds none.
  const CellCounts* Find(int i, int j) const;
  // The counters of a cell InBox, its tile allocated when it has none.
  CellCounts& At(int i, int j);
  // Where a cell's counters lie: its tile's slot in tiles_, and its place within the tile.
  struct TiledCell {
    std::size_t slot = 0;
    std::size_t within = 0;
  };
  TiledCell Locate(int i, int j) const;
  // Calls visit(i, j, counts) for every cell of an allocated tile, row by row (j, then i).
  template <typename Visit>
  void ForEachTiledCell(const Visit& visit) const;
  void AddMiss(int i, int j, int scan_id);
  void AddHit(int i, int j, int scan_id);
  static std::int64_t Key(const CellIndex& cell) { return CellKey(cell.i, cell.j); }

  MappingConfig config_;
  double cell_size_m_;
  // The grown bounding box [origin, origin + size) of cells: what max_grid_cells bounds.
  int origin_i_ = 0;
  int origin_j_ = 0;
  int width_ = 0;
  int height_ = 0;
  // Its counters, in tiles of kTileSide x kTileSide cells (row by row within a tile) allocated
  // where a beam first ends or passes: in an open hall a few long beams stretch the box to tens
  // of times the cells any beam observes (acapulco), and clearing and copying a dense box of them
  // was 43 % of a relocalization update. Tile (ti, tj) holds cells [ti, ti + 1) * kTileSide
  // along i and likewise along j; tiles_ spans tiles [tile_origin, tile_origin + tiles) of the box.
  static constexpr int kTileSide = 16;
  static constexpr std::size_t kTileCells = std::size_t{kTileSide} * kTileSide;
  int tile_origin_i_ = 0;
  int tile_origin_j_ = 0;
  int tiles_wide_ = 0;
  int tiles_high_ = 0;
  std::vector<std::vector<CellCounts>> tiles_;  // empty: no counters yet
  std::int64_t hit_cells_ = 0;
  std::int64_t observed_cells_ = 0;
  std::vector<CellIndex> newly_hit_cells_;

  std::vector<GridKeypoint> keypoints_;
  std::vector<History> histories_;  // in the order cells first received a keypoint
  std::unordered_map<std::int64_t, int> history_of_cell_;
};

}  // namespace keyplace
