#pragma once
// What `keyplace localize` prints and writes: the summary beside the paper's Tables III-X, the
// per-query TSV, the precision-recall curve TSV and the JSON figures.

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "keyplace/eval/global_localization.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "keyplace/place/place_config.hpp"

namespace keyplace::cli {

struct LocalizeReport {
  std::string log_path;
  std::string map_description;
  PoseSource pose_source = PoseSource::kCorrected;
  std::size_t log_scans = 0;
  int n_requested = 0;
  std::string preset;
  bool baseline = false;
  bool exclude_shared_scans = false;
  PlaceRecognitionConfig place;
  LocalizationSummary summary;
  double preparation_seconds = 0.0;
};

/// Warns on stderr when the map was not built from corrected poses of the truth's log.
void WarnAboutMapSource(const std::string& map_path, const GlobalMap& map,
                        const std::string& truth_log_path);

void PrintLocalizeReport(const LocalizeReport& report);
void WriteQueriesTsv(const std::string& path, const std::vector<LocalizationRecord>& records);
void WriteCurveTsv(const std::string& path, const std::vector<PrPoint>& curve);
/// The figures; the caller adds what it alone knows (map path, config, total time).
nlohmann::json LocalizeJson(const LocalizeReport& report,
                            const std::vector<LocalizationRecord>& records);

}  // namespace keyplace::cli
