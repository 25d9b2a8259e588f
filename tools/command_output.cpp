#include "command_output.hpp"

#include <cstdio>
#include <ostream>

#include <fmt/core.h>

#include "io/atomic_file.hpp"
#include "keyplace/mapping/map_server.hpp"

namespace keyplace::cli {

void PrintLogWarnings(const CarmenLog& log) {
  for (const std::string& warning : log.warnings)
    fmt::print(stderr, "keyplace: warning: {}\n", warning);
}

void PrintInputsWarnings(const LogInputs& inputs) {
  PrintLogWarnings(inputs.log);
  for (const std::string& warning : inputs.cache_warnings) {
    fmt::print(stderr, "keyplace: warning: cache entry {}\n", warning);
  }
  if (inputs.poses_from_cache || inputs.keypoints_from_cache) {
    fmt::print(stderr, "keyplace: {} of {} read from the cache\n",
               inputs.poses_from_cache && inputs.keypoints_from_cache
                   ? "poses and keypoints"
                   : (inputs.poses_from_cache ? "poses" : "keypoints"),
               inputs.source_log);
  }
}

void WriteJson(const std::string& path, const nlohmann::json& json) {
  WriteFileAtomically(path, [&](std::ostream& out) { out << json.dump(2) << '\n'; });
}

void WriteGrid(const std::string& yaml_path, const OccupancyGrid& grid,
               const OccupancyGridConfig& config) {
  WriteMapServerMap(grid, config, yaml_path);
  fmt::print("occupancy grid written to {} and {} ({} x {} cells of {} m, origin {:.3f} {:.3f})\n",
             yaml_path, MapServerImagePath(yaml_path), grid.width, grid.height, grid.resolution_m,
             grid.origin_m.x(), grid.origin_m.y());
}

void PrintGridAgreement(const GridAgreement& agreement) {
  fmt::print(
      "grid vs corrected-pose grid: {:.1f} % of its {} occupied cells within {} m of an occupied "
      "reference cell, {:.1f} % of the reference's {} matched, {:.2f} % in free reference space\n",
      100.0 * agreement.occupied_matched, agreement.occupied, agreement.tolerance_m,
      100.0 * agreement.reference_matched, agreement.occupied_reference,
      100.0 * agreement.occupied_on_free);
}

nlohmann::json GridAgreementJson(const GridAgreement& agreement) {
  return {{"tolerance_m", agreement.tolerance_m},
          {"occupied", agreement.occupied},
          {"occupied_reference", agreement.occupied_reference},
          {"occupied_matched", agreement.occupied_matched},
          {"reference_matched", agreement.reference_matched},
          {"occupied_on_free", agreement.occupied_on_free}};
}

nlohmann::json ConfigJson(const Config& config) {
  nlohmann::json json = nlohmann::json::object();
  for (const auto& [key, value] : ConfigKeyValues(config)) {
    nlohmann::json* node = &json;
    std::size_t start = 0;
    for (std::size_t dot = key.find('.'); dot != std::string::npos; dot = key.find('.', start)) {
      node = &(*node)[key.substr(start, dot - start)];
      start = dot + 1;
    }
    (*node)[key.substr(start)] = value;
  }
  return json;
}

}  // namespace keyplace::cli
