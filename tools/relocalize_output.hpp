#pragma once
// What `keyplace relocalize` prints and writes: the summary, one TSV row per start, the JSON
// figures (keys read by scripts) and the figure of starts, paths and fixes.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/eval/relocalization.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/mapping/scan_sources.hpp"

namespace keyplace::cli {

struct RelocalizeReport {
  std::string map_path;
  std::string log_path;
  std::size_t first_scan = 0;
  std::size_t end_scan = 0;
  PoseSource pose_source = PoseSource::kCorrected;
  bool query_log_is_map_log = false;
  RelocalizationOptions options;
  std::vector<StartRecord> records;
  RelocalizationSummary summary;
  // FLIRT time per scan of the query log; none when its keypoints came from --cache.
  std::optional<double> seconds_keypoints_per_scan;
  double seconds_total = 0.0;
};

void PrintRelocalizeReport(const RelocalizeReport& report, const GlobalMap& map);
void WriteStartsTsv(const std::string& path, const std::vector<StartRecord>& records);
void WriteFixesTsv(const std::string& path, const std::vector<StartRecord>& records);
nlohmann::json RelocalizeJson(const RelocalizeReport& report);
/// The map's scans, each start's true path to its first fix and its fixes (tools/).
void DrawRelocalization(const std::string& path, const RelocalizeReport& report,
                        const GlobalMap& map, const LogInputs& inputs, const GroundTruth& truth);

}  // namespace keyplace::cli
