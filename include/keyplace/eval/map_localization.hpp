#pragma once
// `keyplace localize` against a map as one library call (paper Algorithm 4, Section 5.2): the
// query submaps of a log from n_pos equally spaced starts, recognised against the map with the
// self-match rule, marked revisitable or not, and summarised (precision, recall, P_GL / P_CL).
// The CLI and the Python module call it; global_localization.hpp holds the steps.

#include <cstddef>
#include <vector>

#include "keyplace/eval/evaluation_config.hpp"
#include "keyplace/eval/global_localization.hpp"
#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/eval/localization.hpp"
#include "keyplace/mapping/global_map.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "keyplace/place/place_config.hpp"
#include "keyplace/place/place_recognizer.hpp"

namespace keyplace {

struct MapLocalizationOptions {
  int n_pos = 500;  // queries (fewer when fewer scans have a truth pose)
  // The paper's kSameScans or kSharedScan; applied only when the truth is the map's own log
  // (TruthIsMapLog), otherwise no map place can be a self-match and kNone is used.
  SelfMatchRule self_match = SelfMatchRule::kSameScans;
  RankBy rank_by = RankBy::kConfidence;  // the score of the precision-recall curve
};

/// The outcome of LocalizeLogAgainstMap.
struct MapLocalization {
  std::vector<int> starts;  // QueryStarts(truth, n_pos): the requested query starts
  SelfMatchRule self_match = SelfMatchRule::kSameScans;  // the rule applied
  bool truth_is_map_log = true;
  std::size_t places = 0;                   // places of the recognizer (the map's submaps)
  std::vector<LocalizationRecord> records;  // one per query built, in start order
  LocalizationSummary summary;
  double seconds_queries = 0.0;      // building the query submaps
  double seconds_recognition = 0.0;  // index construction and recognition of every query
};

/// Recognises `queries` against `places` with `rule` and marks each record revisitable against
/// `map_scans` (the places with the world poses of their scans: EvaluateQueries, then
/// MarkRevisitable). `progress` gets the stage "localize".
std::vector<LocalizationRecord> EvaluateLocalizationQueries(
    const std::vector<LocalizationQuery>& queries, std::vector<Place> places,
    const std::vector<Submap>& map_scans, const PlaceRecognitionConfig& place, SelfMatchRule rule,
    const EvaluationConfig& evaluation, const StageProgress& progress = {});

/// Algorithm 4 of the scans of `inputs` (truth poses `truth`) against `map`: the query submaps
/// are built with the map's own mapping configuration (progress stage "query submaps"), then
/// EvaluateLocalizationQueries and Summarize. Throws std::invalid_argument for an invalid
/// `place` configuration or n_pos < 1.
MapLocalization LocalizeLogAgainstMap(const LogInputs& inputs, const GroundTruth& truth,
                                      const GlobalMap& map, const PlaceRecognitionConfig& place,
                                      const EvaluationConfig& evaluation,
                                      const MapLocalizationOptions& options = {},
                                      const StageProgress& progress = {});

}  // namespace keyplace
