#pragma once
// What `keyplace relocalize` prints and writes for a log without truth, relocalized as a robot
// would be (keyplace/localization/log_relocalization.hpp): the summary, one TSV row per scan and
// the JSON figures.

#include <string>

#include <nlohmann/json.hpp>

#include "keyplace/localization/log_relocalization.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/mapping/scan_sources.hpp"

namespace keyplace::cli {

void PrintLogRelocalization(const LogRelocalization& run, const LogInputs& inputs,
                            const std::string& map_path, const GlobalMap& map,
                            const std::string& log_path);
/// One row per scan: scan, stamp, odometry path, status, new fix, lost, answered, pose,
/// confidence, update time.
void WriteScanStatusTsv(const std::string& path, const LogRelocalization& run);
nlohmann::json LogRelocalizationJson(const LogRelocalization& run, const LogInputs& inputs,
                                     const std::string& map_path, const std::string& log_path);

}  // namespace keyplace::cli
