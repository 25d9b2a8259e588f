#include "keyplace/mapping/global_map.hpp"

namespace keyplace {

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
  for (const auto& submap : map.submaps) {
    scans += static_cast<double>(submap.scan_indices.size());
    distribution += submap.distribution;
    stats.forced_submaps += submap.forced ? 1 : 0;
  }
  const auto count = static_cast<double>(map.submaps.size());
  stats.scans_per_submap = scans / count;
  stats.keypoints_per_submap = static_cast<double>(stats.stable_keypoints) / count;
  stats.distribution = distribution / count;
  return stats;
}

}  // namespace keyplace
