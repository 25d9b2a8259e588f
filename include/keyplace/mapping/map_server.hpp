#pragma once
// Occupancy grids in the ROS map_server format: a binary PGM image and a YAML file naming it,
// with its resolution, origin and thresholds, as map_server (ROS 1) and nav2_map_server load them
// (docs/NAVIGATION.md).

#include <cstdint>
#include <string>
#include <vector>

#include "keyplace/mapping/occupancy_grid.hpp"

namespace keyplace {

// Pixel values of a trinary map_server image (negate 0): map_server reads a pixel v as occupancy
// (255 - v) / 255 and calls it occupied above occupied_thresh, free below free_thresh. The YAML
// always carries map_saver's thresholds 0.65 and 0.196, which decode these three values as
// written: 0 (1.0) occupied, 254 (0.004) free, 205 (0.196: neither) unknown. The grid's own
// thresholds (grid.occupied_thresh, grid.free_thresh) decide which value a cell gets; writing
// them into the YAML instead could make map_server read unknown pixels as free.
inline constexpr std::uint8_t kMapServerOccupied = 0;
inline constexpr std::uint8_t kMapServerFree = 254;
inline constexpr std::uint8_t kMapServerUnknown = 205;
inline constexpr double kMapServerOccupiedThresh = 0.65;
inline constexpr double kMapServerFreeThresh = 0.196;

/// The trinary image of the grid as the PGM holds it: width x height pixels, row-major, the top
/// (largest y) row first, each kMapServerOccupied, kMapServerFree or kMapServerUnknown by the
/// grid's state under `config`'s thresholds.
std::vector<std::uint8_t> MapServerImage(const OccupancyGrid& grid,
                                         const OccupancyGridConfig& config);

/// The image file of a map_server YAML path: the same path with the extension ".pgm".
std::string MapServerImagePath(const std::string& yaml_path);

/// Writes the grid as `yaml_path` and its image (MapServerImagePath), each atomically, the image
/// first. The image's top row is the grid's top (largest y) row, as map_server expects; `origin`
/// is the lower-left corner of the bottom-left pixel, yaw 0. Throws std::runtime_error naming the
/// file that cannot be written, std::invalid_argument for an empty grid.
void WriteMapServerMap(const OccupancyGrid& grid, const OccupancyGridConfig& config,
                       const std::string& yaml_path);

/// A map_server map as its YAML and image give it.
struct MapServerMap {
  std::string image_path;  // resolved against the YAML file's directory
  double resolution_m = 0.0;
  double origin_x_m = 0.0;
  double origin_y_m = 0.0;
  double origin_yaw_rad = 0.0;
  int negate = 0;
  double occupied_thresh = 0.0;
  double free_thresh = 0.0;
  std::string mode = "trinary";
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  // row-major, top row first (as in the image)

  /// The occupancy map_server gives pixel (column, image_row): (255 - v) / 255, or v / 255 when
  /// negate is 1; occupied above occupied_thresh, free below free_thresh.
  double Occupancy(int column, int image_row) const;
};

/// Reads a map_server YAML and its binary PGM (P5, 8-bit) image. Throws std::invalid_argument
/// naming the file and the key or the image field that is missing or wrong, std::runtime_error
/// naming the file that cannot be opened.
MapServerMap ReadMapServerMap(const std::string& yaml_path);

}  // namespace keyplace
