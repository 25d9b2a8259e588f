// The figures of MappingStats (docs in keyplace/mapping/global_map.hpp).

#include "keyplace/mapping/global_map.hpp"

namespace keyplace {

const ResultFields<MappingStats>& MappingStatsFields() {
  using S = MappingStats;
  static const ResultFields<S> fields = [] {
    ResultFields<S> table;
    table
        .Number("compression", &S::compression, "",
                "stable keypoints in the map / keypoints of all scans")
        .Number("scans_per_submap", &S::scans_per_submap, "", "mean scans of a submap")
        .Number("keypoints_per_submap", &S::keypoints_per_submap, "",
                "mean stable keypoints of a submap")
        .Number("distribution", &S::distribution, "",
                "mean delta: how evenly the keypoints spread over the submaps")
        .Count("submaps", &S::submaps, "submaps in the map")
        .Count("forced_submaps", &S::forced_submaps, "submaps closed by max_scans_per_submap")
        .Number("median_path_m", &S::median_path_m, "m",
                "median robot path length over a submap's scans")
        .Number("max_path_m", &S::max_path_m, "m", "... the longest")
        .Number("median_extent_m", &S::median_extent_m, "m",
                "median largest distance of a submap's pose from its first")
        .Number("max_extent_m", &S::max_extent_m, "m", "... the largest")
        .Count("path_bound_submaps", &S::path_bound_submaps,
               "submaps whose path reached mapping.max_path_m")
        .Count("stable_keypoints", &S::stable_keypoints, "stable keypoints in the map")
        .Count("source_keypoints", &S::source_keypoints, "keypoints of all the mapped scans");
    return table;
  }();
  return fields;
}

}  // namespace keyplace
