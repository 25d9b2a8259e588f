#include "keyplace/mapping/occupancy_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/ray_cells.hpp"

namespace keyplace {
namespace {

double LogOdds(double probability) { return std::log(probability / (1.0 - probability)); }

// One beam to trace: from the laser to its end (clipped to the trace range); `hit` when the
// beam really ended there.
struct Ray {
  Eigen::Vector2d from_m;
  Eigen::Vector2d to_m;
  bool hit = false;
};

std::vector<Ray> RaysOf(const LaserScan& scan, const Pose2& T_world_laser,
                        const OccupancyGridConfig& config) {
  std::vector<Ray> rays;
  rays.reserve(scan.size());
  const Eigen::Vector2d origin_m = T_world_laser.translation();
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan.valid[i] == 0) continue;  // no return: nothing known along it for sure
    const double range_m = std::min(scan.ranges_m[i], config.max_trace_range_m);
    const double bearing_rad = scan.angles_rad[i];
    const Eigen::Vector2d end_laser(range_m * std::cos(bearing_rad),
                                    range_m * std::sin(bearing_rad));
    rays.push_back({origin_m, T_world_laser * end_laser, scan.ranges_m[i] <= range_m});
  }
  return rays;
}

struct Extent {
  Eigen::Vector2d min_m{std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity()};
  Eigen::Vector2d max_m = -min_m;
  void Add(const Eigen::Vector2d& point_m) {
    min_m = min_m.cwiseMin(point_m);
    max_m = max_m.cwiseMax(point_m);
  }
};

// The empty grid covering `extent` plus one cell on each side; throws when it is too large.
OccupancyGrid EmptyGridCovering(const Extent& extent, const OccupancyGridConfig& config) {
  OccupancyGrid grid;
  grid.resolution_m = config.resolution_m;
  if (!(extent.min_m.allFinite() && extent.max_m.allFinite())) return grid;  // no beam at all
  const Eigen::Vector2d size_cells = (extent.max_m - extent.min_m) / config.resolution_m;
  const double cells = (std::floor(size_cells.x()) + 3.0) * (std::floor(size_cells.y()) + 3.0);
  if (!(cells <= static_cast<double>(config.max_cells))) {
    std::ostringstream message;
    message.precision(3);
    message << "occupancy grid: the scans span " << extent.max_m.x() - extent.min_m.x() << " m x "
            << extent.max_m.y() - extent.min_m.y() << " m, " << cells << " cells of "
            << config.resolution_m << " m, more than grid.max_cells = " << config.max_cells
            << " (a pose glitch, or raise grid.resolution_m)";
    throw std::invalid_argument(message.str());
  }
  grid.width = static_cast<int>(std::floor(size_cells.x())) + 3;
  grid.height = static_cast<int>(std::floor(size_cells.y())) + 3;
  grid.origin_m = extent.min_m - Eigen::Vector2d::Constant(config.resolution_m);
  const std::size_t count =
      static_cast<std::size_t>(grid.width) * static_cast<std::size_t>(grid.height);
  grid.log_odds.assign(count, 0.0F);
  grid.observed.assign(count, 0);
  return grid;
}

// Adds one scan's rays. Each cell changes at most once per scan, and a cell the scan hit is not
// also freed by it: the beams to a wall graze its neighbouring wall cells, which must stay
// occupied. `stamp` holds 2s+1 for cells hit by scan s and 2s+2 for cells freed by it.
class ScanInserter {
 public:
  ScanInserter(OccupancyGrid& grid, const OccupancyGridConfig& config)
      : grid_(grid),
        stamp_(grid.log_odds.size(), 0),
        hit_(static_cast<float>(LogOdds(config.hit_probability))),
        miss_(static_cast<float>(LogOdds(config.miss_probability))),
        min_(static_cast<float>(LogOdds(config.min_probability))),
        max_(static_cast<float>(LogOdds(config.max_probability))) {}

  void Insert(const std::vector<Ray>& rays, std::uint32_t scan) {
    const std::uint32_t hit_stamp = 2 * scan + 1;
    for (const Ray& ray : rays) {
      int column = 0;
      int row = 0;
      if (!ray.hit || !grid_.CellOf(ray.to_m, column, row)) continue;
      const std::size_t index = grid_.Index(column, row);
      if (stamp_[index] != hit_stamp) Update(index, hit_, hit_stamp);
    }
    for (const Ray& ray : rays) Trace(ray, hit_stamp + 1);
  }

 private:
  void Update(std::size_t index, float delta, std::uint32_t stamp) {
    grid_.log_odds[index] = std::clamp(grid_.log_odds[index] + delta, min_, max_);
    grid_.observed[index] = 1;
    stamp_[index] = stamp;
  }

  // Frees every cell the ray crosses before its end cell.
  void Trace(const Ray& ray, std::uint32_t miss_stamp) {
    const double resolution_m = grid_.resolution_m;
    const Eigen::Vector2d from = (ray.from_m - grid_.origin_m) / resolution_m;
    const Eigen::Vector2d to = (ray.to_m - grid_.origin_m) / resolution_m;
    ForEachCellBeforeEnd(from, to, [&](int column, int row) {
      // Ties in the traversal can end a step off the exact end cell: never leave the grid.
      if (column < 0 || row < 0 || column >= grid_.width || row >= grid_.height) return false;
      const std::size_t index = grid_.Index(column, row);
      if (stamp_[index] != miss_stamp && stamp_[index] != miss_stamp - 1) {
        Update(index, miss_, miss_stamp);
      }
      return true;
    });
  }

  OccupancyGrid& grid_;
  std::vector<std::uint32_t> stamp_;
  float hit_;
  float miss_;
  float min_;
  float max_;
};

}  // namespace

double OccupancyGrid::Probability(int column, int row) const {
  const std::size_t index = Index(column, row);
  if (observed[index] == 0) return 0.5;
  return 1.0 - 1.0 / (1.0 + std::exp(static_cast<double>(log_odds[index])));
}

CellState OccupancyGrid::State(int column, int row, const OccupancyGridConfig& config) const {
  if (observed[Index(column, row)] == 0) return CellState::kUnknown;
  const double probability = Probability(column, row);
  if (probability >= config.occupied_thresh) return CellState::kOccupied;
  if (probability <= config.free_thresh) return CellState::kFree;
  return CellState::kUnknown;
}

bool OccupancyGrid::CellOf(const Eigen::Vector2d& point_m, int& column, int& row) const {
  const Eigen::Vector2d cell = (point_m - origin_m) / resolution_m;
  if (!(cell.x() >= 0.0 && cell.y() >= 0.0 && cell.x() < width && cell.y() < height)) {
    return false;
  }
  column = static_cast<int>(cell.x());
  row = static_cast<int>(cell.y());
  return true;
}

OccupancyGrid BuildOccupancyGrid(const std::vector<const LaserScan*>& scans,
                                 const std::vector<Pose2>& T_world_robot,
                                 const OccupancyGridConfig& config) {
  Validate(config);
  if (scans.size() != T_world_robot.size()) {
    throw std::invalid_argument("occupancy grid: " + std::to_string(scans.size()) + " scans but " +
                                std::to_string(T_world_robot.size()) + " poses");
  }
  // Rays are made twice (extent, then insertion) instead of held: a long log has millions.
  const auto rays_of = [&](std::size_t i) {
    return RaysOf(*scans[i], T_world_robot[i] * scans[i]->T_robot_laser, config);
  };
  Extent extent;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    for (const Ray& ray : rays_of(i)) {
      extent.Add(ray.from_m);
      extent.Add(ray.to_m);
    }
  }
  OccupancyGrid grid = EmptyGridCovering(extent, config);
  if (grid.log_odds.empty()) return grid;
  ScanInserter inserter(grid, config);
  for (std::size_t i = 0; i < scans.size(); ++i) {
    inserter.Insert(rays_of(i), static_cast<std::uint32_t>(i));
  }
  return grid;
}

}  // namespace keyplace
