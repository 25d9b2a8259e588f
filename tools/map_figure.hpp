#pragma once
// Pictures of a map: registered scan points, stable keypoints and submap origins (cairo).

#include <cstddef>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/mapping/global_map.hpp"

namespace keyplace::cli {

struct MapFigureOptions {
  std::string title;
  double pixels_per_m = 20.0;  // reduced automatically so the larger side fits max_side_px
  int max_side_px = 2400;
  std::size_t first_scan = 0;  // file scan index of scans[0] (map scan indices are file indices)
};

/// Draws the map; the format follows the extension of `path` (.png or .svg). `poses` are the
/// T_world_robot of `scans` (may be empty to draw keypoints only). Written atomically.
void DrawMapFigure(const std::string& path, const GlobalMap& map, const std::vector<LogScan>& scans,
                   const std::vector<Pose2>& poses, const MapFigureOptions& options);

}  // namespace keyplace::cli
