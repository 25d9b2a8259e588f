#pragma once
// What `keyplace localize` prints and writes: the summary beside the paper's Tables III-X, the
// per-query TSV, the precision-recall curve TSV and the JSON figures.

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "keyplace/eval/evaluation_config.hpp"
#include "keyplace/eval/global_localization.hpp"
#include "keyplace/eval/localization.hpp"
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
  SelfMatchRule self_match = SelfMatchRule::kSameScans;  // the rule in force
  bool truth_is_map_log = true;                          // TruthIsMapLog
  std::size_t first_scan = 0;                            // --scans: the queries' part of the log
  std::size_t file_scans = 0;
  std::size_t skipped_lines = 0;  // malformed lines skipped with --skip-bad-lines
  EvaluationConfig evaluation;    // revisit_radius_m, revisit_angle_deg
  PlaceRecognitionConfig place;
  LocalizationSummary summary;
  double preparation_seconds = 0.0;
  bool preparation_from_cache = false;  // the query log's poses or keypoints came from --cache
};

/// Warns on stderr when the map was not built from corrected poses, and when the truth log has
/// the map's log file name but other contents (`truth_is_map_log`: TruthIsMapLog), so that the
/// queries count as another recording.
void WarnAboutMapSource(const std::string& map_path, const GlobalMap& map,
                        const std::string& truth_log_path, bool truth_is_map_log);

void PrintLocalizeReport(const LocalizeReport& report);
/// start_scan and evaluated_scan as scans of the file: `first_scan` is the query log's --scans
/// start (records number the scans of the cut log).
void WriteQueriesTsv(const std::string& path, const std::vector<LocalizationRecord>& records,
                     std::size_t first_scan);
void WriteCurveTsv(const std::string& path, const std::vector<PrPoint>& curve);
void WriteReliabilityTsv(const std::string& path, const std::vector<ReliabilityBin>& bins);
/// The figures; the caller adds what it alone knows (map path, config, total time).
nlohmann::json LocalizeJson(const LocalizeReport& report,
                            const std::vector<LocalizationRecord>& records);

}  // namespace keyplace::cli
