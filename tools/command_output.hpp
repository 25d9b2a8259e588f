#pragma once
// What several commands print and write alike: the log's warnings, JSON files, map_server grids,
// the grid agreement and the configuration as JSON.

#include <string>

#include <nlohmann/json.hpp>

#include "keyplace/config/config.hpp"
#include "keyplace/eval/grid_agreement.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/mapping/scan_sources.hpp"

namespace keyplace::cli {

/// Prints the reader's warnings about a log (a dropped cut-off last line, skipped lines) to
/// stderr, one "keyplace: warning: ..." line each.
void PrintLogWarnings(const CarmenLog& log);

/// PrintLogWarnings of the inputs' log, the damaged cache entries and, when the cache gave the
/// poses or keypoints, one line saying so.
void PrintInputsWarnings(const LogInputs& inputs);

/// Writes `json` (pretty-printed) to `path` atomically.
void WriteJson(const std::string& path, const nlohmann::json& json);

/// Writes `grid` as a map_server map at `yaml_path` and prints where, its size and resolution.
void WriteGrid(const std::string& yaml_path, const OccupancyGrid& grid,
               const OccupancyGridConfig& config);

/// One line: how well a grid agrees with the corrected-pose grid (slam --grid --truth).
void PrintGridAgreement(const GridAgreement& agreement);
nlohmann::json GridAgreementJson(const GridAgreement& agreement);

/// The whole configuration as nested JSON objects (section -> key -> text value).
nlohmann::json ConfigJson(const Config& config);

}  // namespace keyplace::cli
