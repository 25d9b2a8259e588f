#pragma once
// The global map M: the list of submaps of a log (paper Section 3.2), with what made it.

#include <cstddef>
#include <string>
#include <vector>

#include "keyplace/common/result_fields.hpp"
#include "keyplace/mapping/mapping_config.hpp"
#include "keyplace/mapping/submap.hpp"

namespace keyplace {

struct GlobalMap {
  std::vector<Submap> submaps;
  MappingConfig config;
  std::string source_log;        // file name of the log the map was built from
  std::string source_hash;       // "crc32:<hex>:<bytes>" of that file
  std::string pose_source;       // corrected | odometry | icp
  std::size_t source_scans = 0;  // scans in the log
  // FLIRT keypoints of all the scans of the log: the denominator of the compression ratio.
  std::size_t source_keypoints = 0;
  // The whole configuration that made the map, as YAML (keyplace dump-config); empty when the
  // maker did not record it (maps from older versions).
  std::string configuration;

  std::size_t KeypointCount() const;
};

/// Mapping quality criteria of Section 5.1.
struct MappingStats {
  double compression = 0.0;           // stable keypoints in the map / keypoints of all scans
  double scans_per_submap = 0.0;      // mean
  double keypoints_per_submap = 0.0;  // mean
  double distribution = 0.0;          // mean delta
  std::size_t submaps = 0;
  std::size_t forced_submaps = 0;  // closed by max_scans_per_submap
  // How far each submap reaches in space (SubmapPathM, SubmapExtentM): medians and largest.
  double median_path_m = 0.0;
  double median_extent_m = 0.0;
  double max_path_m = 0.0;
  double max_extent_m = 0.0;
  // Submaps whose path reached the map's MappingConfig::max_path_m (closed by the bound, unless
  // the paper's criteria were met on the same scan).
  std::size_t path_bound_submaps = 0;
  std::size_t stable_keypoints = 0;
  std::size_t source_keypoints = 0;
  // The whole configuration that made the map, as YAML (keyplace dump-config); empty when the
  // maker did not record it (maps from older versions).
  std::string configuration;
};

MappingStats ComputeStats(const GlobalMap& map);

/// The mapping criteria's figures (all but the configuration), named as the keys of the JSON of
/// `keyplace map`, `info` and `slam` and the attributes of Python's MappingStats.
const ResultFields<MappingStats>& MappingStatsFields();

/// Path length of the robot over a submap's poses, and the largest distance of one of its robot
/// positions from the first (its extent).
double SubmapPathM(const Submap& submap);
double SubmapExtentM(const Submap& submap);

}  // namespace keyplace
