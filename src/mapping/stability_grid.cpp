#include "keyplace/mapping/stability_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "keyplace/features/descriptor.hpp"

namespace keyplace {
namespace {

constexpr int kGrowthMarginCells = 64;

// floor(coordinate / cell) when it lies within +-kMaxCellIndex (false for NaN and infinities).
bool CellIndexOf(double coordinate_m, double cell_size_m, int& index) {
  const double cell = std::floor(coordinate_m / cell_size_m);
  if (!(std::abs(cell) <= StabilityGrid::kMaxCellIndex)) return false;
  index = static_cast<int>(cell);
  return true;
}

// floor(cell / side) for any sign of cell.
int TileOf(int cell, int side) { return cell >= 0 ? cell / side : -((-cell - 1) / side) - 1; }

// Where tile (ti, tj) of an index `tiles_wide` tiles wide lies in it (relative to its origin).
std::size_t TileSlot(int ti, int tj, int tiles_wide) {
  return static_cast<std::size_t>(tj) * static_cast<std::size_t>(tiles_wide) +
         static_cast<std::size_t>(ti);
}

std::string PointText(const Eigen::Vector2d& point_m) {
  std::ostringstream text;
  text << "(" << point_m.x() << ", " << point_m.y() << ")";
  return text.str();
}

}  // namespace

StabilityGrid::StabilityGrid(const MappingConfig& config)
    : config_(config), cell_size_m_(config.cell_size_m) {
  Validate(config_);
}

void StabilityGrid::Clear() {
  origin_i_ = origin_j_ = width_ = height_ = 0;
  tile_origin_i_ = tile_origin_j_ = tiles_wide_ = tiles_high_ = 0;
  tiles_.clear();
  hit_cells_ = observed_cells_ = 0;
  newly_hit_cells_.clear();
  keypoints_.clear();
  histories_.clear();
  history_of_cell_.clear();
}

std::optional<CellIndex> StabilityGrid::TryCellOf(const Eigen::Vector2d& point_m) const {
  CellIndex cell;
  if (!CellIndexOf(point_m.x(), cell_size_m_, cell.i) ||
      !CellIndexOf(point_m.y(), cell_size_m_, cell.j)) {
    return std::nullopt;
  }
  return cell;
}

CellIndex StabilityGrid::CellOf(const Eigen::Vector2d& point_m) const {
  const std::optional<CellIndex> cell = TryCellOf(point_m);
  if (!cell) {
    throw std::invalid_argument("StabilityGrid: point " + PointText(point_m) +
                                " m has no cell (not finite, or beyond " +
                                std::to_string(kMaxCellIndex) + " cells from the origin)");
  }
  return *cell;
}

Eigen::Vector2d StabilityGrid::CellCenter(const CellIndex& cell) const {
  return {(cell.i + 0.5) * cell_size_m_, (cell.j + 0.5) * cell_size_m_};
}

CellCounts StabilityGrid::Counts(const CellIndex& cell) const {
  if (!InBox(cell.i, cell.j)) return {};
  const CellCounts* counts = Find(cell.i, cell.j);
  return counts != nullptr ? *counts : CellCounts{};
}

StabilityGrid::TiledCell StabilityGrid::Locate(int i, int j) const {
  const int tile_i = TileOf(i, kTileSide);
  const int tile_j = TileOf(j, kTileSide);
  const std::size_t slot = TileSlot(tile_i - tile_origin_i_, tile_j - tile_origin_j_, tiles_wide_);
  const std::size_t within = static_cast<std::size_t>(j - tile_j * kTileSide) * kTileSide +
                             static_cast<std::size_t>(i - tile_i * kTileSide);
  return {slot, within};
}

const CellCounts* StabilityGrid::Find(int i, int j) const {
  const TiledCell cell = Locate(i, j);
  const std::vector<CellCounts>& tile = tiles_[cell.slot];
  if (tile.empty()) return nullptr;
  return &tile[cell.within];
}

CellCounts& StabilityGrid::At(int i, int j) {
  const TiledCell cell = Locate(i, j);
  std::vector<CellCounts>& tile = tiles_[cell.slot];
  if (tile.empty()) tile.resize(kTileCells);
  return tile[cell.within];
}

std::int64_t StabilityGrid::CellsToCover(const CellIndex& min, const CellIndex& max) const {
  if (width_ > 0 && InBox(min.i, min.j) && InBox(max.i, max.j)) {
    return allocated_cell_count();
  }
  // As EnsureCovers, in 64 bits (indices lie within +-kMaxCellIndex, so nothing overflows).
  std::int64_t new_min_i = std::int64_t{min.i} - kGrowthMarginCells;
  std::int64_t new_min_j = std::int64_t{min.j} - kGrowthMarginCells;
  std::int64_t new_max_i = std::int64_t{max.i} + kGrowthMarginCells;
  std::int64_t new_max_j = std::int64_t{max.j} + kGrowthMarginCells;
  if (width_ > 0) {
    new_min_i = std::min<std::int64_t>(new_min_i, origin_i_);
    new_min_j = std::min<std::int64_t>(new_min_j, origin_j_);
    new_max_i = std::max<std::int64_t>(new_max_i, std::int64_t{origin_i_} + width_ - 1);
    new_max_j = std::max<std::int64_t>(new_max_j, std::int64_t{origin_j_} + height_ - 1);
  }
  return (new_max_i - new_min_i + 1) * (new_max_j - new_min_j + 1);
}

void StabilityGrid::EnsureCovers(int min_i, int min_j, int max_i, int max_j) {
  if (width_ > 0 && InBox(min_i, min_j) && InBox(max_i, max_j)) return;
  int new_min_i = min_i - kGrowthMarginCells;
  int new_min_j = min_j - kGrowthMarginCells;
  int new_max_i = max_i + kGrowthMarginCells;
  int new_max_j = max_j + kGrowthMarginCells;
  if (width_ > 0) {
    new_min_i = std::min(new_min_i, origin_i_);
    new_min_j = std::min(new_min_j, origin_j_);
    new_max_i = std::max(new_max_i, origin_i_ + width_ - 1);
    new_max_j = std::max(new_max_j, origin_j_ + height_ - 1);
  }
  // The tile index first: nothing changes if its allocation throws.
  const int tile_min_i = TileOf(new_min_i, kTileSide);
  const int tile_min_j = TileOf(new_min_j, kTileSide);
  const int tiles_wide = TileOf(new_max_i, kTileSide) - tile_min_i + 1;
  const int tiles_high = TileOf(new_max_j, kTileSide) - tile_min_j + 1;
  if (tile_min_i != tile_origin_i_ || tile_min_j != tile_origin_j_ || tiles_wide != tiles_wide_ ||
      tiles_high != tiles_high_) {
    std::vector<std::vector<CellCounts>> grown(static_cast<std::size_t>(tiles_wide) *
                                               static_cast<std::size_t>(tiles_high));
    for (int tj = 0; tj < tiles_high_; ++tj) {
      for (int ti = 0; ti < tiles_wide_; ++ti) {
        grown[TileSlot(ti + tile_origin_i_ - tile_min_i, tj + tile_origin_j_ - tile_min_j,
                       tiles_wide)] = std::move(tiles_[TileSlot(ti, tj, tiles_wide_)]);
      }
    }
    tiles_ = std::move(grown);
    tile_origin_i_ = tile_min_i;
    tile_origin_j_ = tile_min_j;
    tiles_wide_ = tiles_wide;
    tiles_high_ = tiles_high;
  }
  origin_i_ = new_min_i;
  origin_j_ = new_min_j;
  width_ = new_max_i - new_min_i + 1;
  height_ = new_max_j - new_min_j + 1;
}

void StabilityGrid::AddMiss(int i, int j, int scan_id) {
  // Rounding can step the traversal one cell past the endpoint's; never outside the counters.
  if (!InBox(i, j)) return;
  CellCounts& cell = At(i, j);
  if (config_.density_counting == MappingConfig::DensityCounting::kScans) {
    // Once per scan, and not at all when this scan also ends a beam in the cell (the hits of a
    // scan are all cast before its misses).
    if (cell.last_scan == scan_id || cell.last_miss_scan == scan_id) return;
    cell.last_miss_scan = scan_id;
  }
  if (cell.hits == 0 && cell.misses == 0) ++observed_cells_;
  ++cell.misses;
}

void StabilityGrid::AddHit(int i, int j, int scan_id) {
  CellCounts& cell = At(i, j);
  if (cell.hits == 0) {
    ++hit_cells_;
    newly_hit_cells_.push_back({i, j});
    if (cell.misses == 0) ++observed_cells_;
  }
  if (cell.last_scan != scan_id) {
    cell.last_scan = scan_id;
    ++cell.scans_hit;
    ++cell.hits;
  } else if (config_.density_counting == MappingConfig::DensityCounting::kBeams) {
    ++cell.hits;
  }
}

void StabilityGrid::InsertRays(const Eigen::Vector2d& origin_m,
                               const std::vector<Eigen::Vector2d>& endpoints_m, int scan_id) {
  newly_hit_cells_.clear();
  if (endpoints_m.empty()) return;
  const CellIndex start = CellOf(origin_m);
  int min_i = start.i, max_i = start.i, min_j = start.j, max_j = start.j;
  for (const auto& endpoint : endpoints_m) {
    const CellIndex cell = CellOf(endpoint);
    min_i = std::min(min_i, cell.i);
    max_i = std::max(max_i, cell.i);
    min_j = std::min(min_j, cell.j);
    max_j = std::max(max_j, cell.j);
  }
  const std::int64_t cells = CellsToCover({min_i, min_j}, {max_i, max_j});
  if (cells > config_.max_grid_cells) {
    throw std::invalid_argument("StabilityGrid: scan " + std::to_string(scan_id) +
                                " would grow the grid to " + std::to_string(cells) +
                                " cells, more than MappingConfig.max_grid_cells = " +
                                std::to_string(config_.max_grid_cells));
  }
  EnsureCovers(min_i, min_j, max_i, max_j);

  // All hits first, so that per-scan counting knows which cells this scan hits.
  std::vector<CellIndex> ends;
  ends.reserve(endpoints_m.size());
  for (const auto& endpoint : endpoints_m) {
    ends.push_back(CellOf(endpoint));
    AddHit(ends.back().i, ends.back().j, scan_id);
  }
  const double inf = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < endpoints_m.size(); ++k) {
    // Amanatides-Woo traversal of the cells between the origin and the endpoint.
    const Eigen::Vector2d& endpoint = endpoints_m[k];
    const CellIndex end = ends[k];
    int i = start.i;
    int j = start.j;
    const double dx = endpoint.x() - origin_m.x();
    const double dy = endpoint.y() - origin_m.y();
    const int step_i = dx > 0 ? 1 : -1;
    const int step_j = dy > 0 ? 1 : -1;
    const double next_x = (i + (step_i > 0 ? 1 : 0)) * cell_size_m_;
    const double next_y = (j + (step_j > 0 ? 1 : 0)) * cell_size_m_;
    double t_max_x = dx != 0.0 ? (next_x - origin_m.x()) / dx : inf;
    double t_max_y = dy != 0.0 ? (next_y - origin_m.y()) / dy : inf;
    const double t_delta_x = dx != 0.0 ? cell_size_m_ / std::abs(dx) : inf;
    const double t_delta_y = dy != 0.0 ? cell_size_m_ / std::abs(dy) : inf;
    // Rounding can miss the end cell by one step; never walk further than the Manhattan distance.
    int steps_left = std::abs(end.i - i) + std::abs(end.j - j);
    while ((i != end.i || j != end.j) && steps_left-- > 0) {
      AddMiss(i, j, scan_id);
      if (t_max_x < t_max_y) {
        t_max_x += t_delta_x;
        i += step_i;
      } else {
        t_max_y += t_delta_y;
        j += step_j;
      }
    }
  }
}

void StabilityGrid::InsertKeypoint(const GridKeypoint& keypoint) {
  const CellIndex cell = CellOf(keypoint.position_m);
  const int index = static_cast<int>(keypoints_.size());
  keypoints_.push_back(keypoint);
  auto [it, inserted] = history_of_cell_.emplace(Key(cell), static_cast<int>(histories_.size()));
  if (inserted) histories_.push_back({cell, {}});
  History& history = histories_[it->second];

  const auto matches = [&](const Cluster& cluster) {
    if (config_.cluster_match == MappingConfig::ClusterMatch::kLatestMember) {
      return SymmetricChi2Below(keypoints_[cluster.members.back()].descriptor, keypoint.descriptor,
                                config_.descriptor_match_chi2);
    }
    return std::any_of(cluster.members.begin(), cluster.members.end(), [&](int member) {
      return SymmetricChi2Below(keypoints_[member].descriptor, keypoint.descriptor,
                                config_.descriptor_match_chi2);
    });
  };
  std::size_t target = history.clusters.size();
  for (std::size_t c = 0; c < history.clusters.size(); ++c) {
    if (matches(history.clusters[c])) {
      target = c;
      break;
    }
  }
  if (target == history.clusters.size()) {
    history.clusters.push_back({{index}});
    return;
  }
  history.clusters[target].members.push_back(index);
  // Keep decreasing size: bubble the grown cluster up past smaller ones (ties keep their order).
  while (target > 0 &&
         history.clusters[target - 1].members.size() < history.clusters[target].members.size()) {
    std::swap(history.clusters[target - 1], history.clusters[target]);
    --target;
  }
}

double StabilityGrid::Stability(const CellIndex& cell) const {
  const auto it = history_of_cell_.find(Key(cell));
  if (it == history_of_cell_.end() || histories_[it->second].clusters.empty()) return 0.0;
  const CellCounts counts = Counts(cell);
  const int total = counts.hits + counts.misses;
  if (total == 0) return 0.0;
  const double density = static_cast<double>(counts.hits) / total;
  const double occurrences =
      static_cast<double>(histories_[it->second].clusters.front().members.size());
  return density * occurrences / std::max(counts.scans_hit, config_.min_scan_count);
}

std::vector<StabilityGrid::Selected> StabilityGrid::SelectStable() const {
  std::vector<Selected> selected;
  for (const History& history : histories_) {
    if (history.clusters.empty()) continue;
    const double stability = Stability(history.cell);
    if (stability < config_.min_stability) continue;
    const Cluster& largest = history.clusters.front();
    selected.push_back(
        {keypoints_[largest.members.back()], stability, static_cast<int>(largest.members.size())});
  }
  return selected;
}

std::vector<std::vector<GridKeypoint>> StabilityGrid::Clusters(const CellIndex& cell) const {
  std::vector<std::vector<GridKeypoint>> clusters;
  const auto it = history_of_cell_.find(Key(cell));
  if (it == history_of_cell_.end()) return clusters;
  for (const Cluster& cluster : histories_[it->second].clusters) {
    std::vector<GridKeypoint> members;
    for (const int member : cluster.members) members.push_back(keypoints_[member]);
    clusters.push_back(std::move(members));
  }
  return clusters;
}

template <typename Visit>
void StabilityGrid::ForEachTiledCell(const Visit& visit) const {
  for (int tj = 0; tj < tiles_high_; ++tj) {
    for (int row = 0; row < kTileSide; ++row) {
      const int j = (tile_origin_j_ + tj) * kTileSide + row;
      for (int ti = 0; ti < tiles_wide_; ++ti) {
        const std::vector<CellCounts>& tile = tiles_[TileSlot(ti, tj, tiles_wide_)];
        if (tile.empty()) continue;
        for (int column = 0; column < kTileSide; ++column) {
          visit((tile_origin_i_ + ti) * kTileSide + column, j,
                tile[static_cast<std::size_t>(row) * kTileSide + static_cast<std::size_t>(column)]);
        }
      }
    }
  }
}

std::vector<CellIndex> StabilityGrid::HitCells() const {
  std::vector<CellIndex> cells;
  cells.reserve(static_cast<std::size_t>(hit_cells_));
  ForEachTiledCell([&cells](int i, int j, const CellCounts& counts) {
    if (counts.hits > 0) cells.push_back({i, j});
  });
  return cells;
}

std::vector<CellIndex> StabilityGrid::ObservedCells() const {
  std::vector<CellIndex> cells;
  cells.reserve(static_cast<std::size_t>(observed_cells_));
  ForEachTiledCell([&cells](int i, int j, const CellCounts& counts) {
    if (counts.hits > 0 || counts.misses > 0) cells.push_back({i, j});
  });
  return cells;
}

}  // namespace keyplace
