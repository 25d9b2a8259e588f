#pragma once
// Global mapping (paper Algorithm 2) and single-submap construction from any start scan.

#include <functional>
#include <optional>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/features/keypoint.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/mapping/local_mapper.hpp"

namespace keyplace {

/// Everything mapping reads about the scans of a log, by scan index (views, no copies).
struct ScanSequence {
  const std::vector<LogScan>& scans;
  const std::vector<Pose2>& poses;                      // T_world_robot of every scan
  const std::vector<std::vector<Keypoint>>& keypoints;  // FLIRT keypoints (laser frame)

  std::size_t size() const { return scans.size(); }
};

/// Algorithm 1 from `first_scan` with `mapper` (reset first). Returns the completed submap, or
/// nullopt when the sequence ends before the submap is complete.
std::optional<Submap> BuildSubmap(const ScanSequence& sequence, std::size_t first_scan,
                                  LocalMapper& mapper);

struct GlobalMappingTimings {
  std::vector<double> submap_seconds;  // time to build each submap (keypoints given)
  double seconds_total = 0.0;
};

/// Algorithm 2: consecutive submaps from scan 0 until one cannot be completed. `progress` (may be
/// empty) is called with the next scan index after each submap.
GlobalMap BuildGlobalMap(const ScanSequence& sequence, const MappingConfig& config,
                         GlobalMappingTimings* timings = nullptr,
                         const std::function<void(std::size_t)>& progress = {});

}  // namespace keyplace
