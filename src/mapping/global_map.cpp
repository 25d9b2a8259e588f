#include "keyplace/mapping/global_map.hpp"

#include <algorithm>

namespace keyplace {
namespace {

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  if (values.size() % 2 == 1) return *middle;
  return 0.5 * (*middle + *std::max_element(values.begin(), middle));
}

}  // namespace

double SubmapPathM(const Submap& submap) {
  double path_m = 0.0;
  for (std::size_t i = 1; i < submap.poses.size(); ++i) {
    path_m += (submap.poses[i].translation() - submap.poses[i - 1].translation()).norm();
  }
  return path_m;
}

double SubmapExtentM(const Submap& submap) {
  double extent_m = 0.0;
  for (const Pose2& pose : submap.poses) {
    extent_m = std::max(extent_m, (pose.translation() - submap.origin().translation()).norm());
  }
  return extent_m;
}

std::size_t GlobalMap::KeypointCount() const {
  std::size_t count = 0;
  for (const auto& submap : submaps) count += submap.keypoints.size();
  return count;
}

MappingStats ComputeStats(const GlobalMap& map) {
  MappingStats stats;
  stats.submaps = map.submaps.size();
  stats.stable_keypoints = map.KeypointCount();
  stats.source_keypoints = map.source_keypoints;
  if (map.source_keypoints > 0) {
    stats.compression =
        static_cast<double>(stats.stable_keypoints) / static_cast<double>(map.source_keypoints);
  }
  if (map.submaps.empty()) return stats;
  double scans = 0.0;
  double distribution = 0.0;
  std::vector<double> paths_m;
  std::vector<double> extents_m;
  for (const auto& submap : map.submaps) {
    scans += static_cast<double>(submap.scan_indices.size());
    distribution += submap.distribution;
    stats.forced_submaps += submap.forced ? 1 : 0;
    paths_m.push_back(SubmapPathM(submap));
    extents_m.push_back(SubmapExtentM(submap));
    const bool bounded = map.config.max_path_m > 0.0 && paths_m.back() >= map.config.max_path_m;
    stats.path_bound_submaps += bounded ? 1 : 0;
  }
  stats.max_path_m = *std::max_element(paths_m.begin(), paths_m.end());
  stats.max_extent_m = *std::max_element(extents_m.begin(), extents_m.end());
  stats.median_path_m = Median(std::move(paths_m));
  stats.median_extent_m = Median(std::move(extents_m));
  const auto count = static_cast<double>(map.submaps.size());
  stats.scans_per_submap = scans / count;
  stats.keypoints_per_submap = static_cast<double>(stats.stable_keypoints) / count;
  stats.distribution = distribution / count;
  return stats;
}

}  // namespace keyplace
