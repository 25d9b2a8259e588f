#include "keyplace/eval/distractor_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "mapping/map_numbering.hpp"

namespace keyplace {
namespace {

// The smallest disc holding every pose and keypoint of a map (world frame) is what a copy must
// keep clear of its neighbours; the bounding box's centre and half diagonal bound it.
struct Extent {
  Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();
  double radius_m = 0.0;
};

Extent ExtentOf(const GlobalMap& map) {
  Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d high = -low;
  auto include = [&](const Eigen::Vector2d& point_m) {
    low = low.cwiseMin(point_m);
    high = high.cwiseMax(point_m);
  };
  for (const Submap& submap : map.submaps) {
    if (submap.poses.empty()) continue;  // no frame to place its keypoints in
    for (const Pose2& pose : submap.poses) include(pose.translation());
    for (const StableKeypoint& keypoint : submap.keypoints) {
      include(submap.origin() * keypoint.position_m);
    }
    for (const Eigen::Vector2i& cell : submap.occupancy.cells) {
      include(submap.origin() *
              ((cell.cast<double>().array() + 0.5).matrix() * submap.occupancy.cell_size_m));
    }
  }
  if (!(low.array() <= high.array()).all()) return {};
  return {0.5 * (low + high), 0.5 * (high - low).norm()};
}

// A distractor map with what every copy of it needs.
struct Source {
  const GlobalMap* map;
  Extent extent;
  MapNumbering numbering;
};

// Where the copies go: tile 0 holds the map, copy k tile k + 1 of a square lattice (row-major).
class Lattice {
 public:
  Lattice(const Eigen::Vector2d& map_centre_m, double tile_m, std::size_t copies)
      : centre_m_(map_centre_m),
        tile_m_(tile_m),
        side_(static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(copies + 1))))) {}

  Eigen::Vector2d TileCentre(std::size_t copy) const {
    const std::size_t tile = copy + 1;
    const std::size_t column = tile % side_;
    const std::size_t row = tile / side_;
    return centre_m_ +
           tile_m_ * Eigen::Vector2d(static_cast<double>(column), static_cast<double>(row));
  }

 private:
  Eigen::Vector2d centre_m_;
  double tile_m_;
  std::size_t side_;
};

// T_world_source: rotates the source about its centre by heading_rad and moves the centre to
// tile_centre_m.
Pose2 CopyTransform(const Extent& source, const Eigen::Vector2d& tile_centre_m,
                    double heading_rad) {
  const Pose2 rotation(0.0, 0.0, heading_rad);
  const Eigen::Vector2d moved = rotation * source.centre_m;
  return {tile_centre_m.x() - moved.x(), tile_centre_m.y() - moved.y(), heading_rad};
}

std::size_t CountCopies(const std::vector<Source>& sources, std::size_t distractors) {
  std::size_t copies = 0;
  for (std::size_t placed = 0; placed < distractors; ++copies) {
    placed += sources[copies % sources.size()].map->submaps.size();
  }
  return copies;
}

}  // namespace

GlobalMap EmbedAmongDistractors(const GlobalMap& map, const std::vector<GlobalMap>& sources,
                                const DistractorOptions& options) {
  if (!std::isfinite(options.margin_m) || options.margin_m < 0.0) {
    throw std::invalid_argument("distractors: margin_m must be finite and >= 0");
  }
  GlobalMap result = map;
  if (options.total_submaps <= map.submaps.size()) return result;
  const std::size_t distractors = options.total_submaps - map.submaps.size();
  std::vector<Source> used;
  const Extent map_extent = ExtentOf(map);
  double largest_radius_m = map_extent.radius_m;
  for (const GlobalMap& source : sources) {
    if (source.submaps.empty()) continue;
    used.push_back({&source, ExtentOf(source), NumberingOf(source)});
    largest_radius_m = std::max(largest_radius_m, used.back().extent.radius_m);
  }
  if (used.empty()) {
    throw std::invalid_argument("distractors: the distractor maps hold no submap");
  }
  const std::size_t copies = CountCopies(used, distractors);
  const Lattice lattice(map_extent.centre_m, 2.0 * largest_radius_m + options.margin_m, copies);
  std::mt19937_64 random(options.seed);
  std::uniform_real_distribution<double> heading(-M_PI, M_PI);

  result.submaps.reserve(options.total_submaps);
  const MapNumbering own = NumberingOf(map);
  int next_id = own.last_id + 2;
  int next_scan = std::max(own.last_scan + 1, options.first_scan);
  for (std::size_t copy = 0; copy < copies; ++copy) {
    const Source& source = used[copy % used.size()];
    const Pose2 T_world_source =
        CopyTransform(source.extent, lattice.TileCentre(copy), heading(random));
    const int first_id = next_id - source.numbering.first_id;
    const int first_scan = next_scan - source.numbering.first_scan;
    for (const Submap& original : source.map->submaps) {
      if (result.submaps.size() == options.total_submaps) break;
      Submap submap = original;
      submap.id = first_id + original.id;
      for (int& scan : submap.scan_indices) scan += first_scan;
      for (StableKeypoint& keypoint : submap.keypoints) keypoint.scan_index += first_scan;
      for (Pose2& pose : submap.poses) pose = T_world_source * pose;
      result.submaps.push_back(std::move(submap));
    }
    next_id = source.numbering.last_id + first_id + 2;
    next_scan = source.numbering.last_scan + first_scan + 1;
  }
  return result;
}

}  // namespace keyplace
