#include "keyplace/eval/map_localization.hpp"

#include <chrono>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/seconds_since.hpp"

namespace keyplace {
namespace {

// A QueryProgress reporting as `stage` of `progress` (nothing when `progress` is empty).
QueryProgress AsStage(const StageProgress& progress, const std::string& stage) {
  if (!progress) return {};
  return [progress, stage](std::size_t done, std::size_t total) { progress(stage, done, total); };
}

}  // namespace

std::vector<LocalizationRecord> EvaluateLocalizationQueries(
    const std::vector<LocalizationQuery>& queries, std::vector<Place> places,
    const std::vector<Submap>& map_scans, const PlaceRecognitionConfig& place, SelfMatchRule rule,
    const EvaluationConfig& evaluation, const StageProgress& progress) {
  const PlaceRecognizer recognizer(std::move(places), place);
  std::vector<LocalizationRecord> records =
      EvaluateQueries(queries, recognizer, rule, AsStage(progress, "localize"));
  MarkRevisitable(queries, map_scans, rule, evaluation, records);
  return records;
}

MapLocalization LocalizeLogAgainstMap(const LogInputs& inputs, const GroundTruth& truth,
                                      const GlobalMap& map, const PlaceRecognitionConfig& place,
                                      const EvaluationConfig& evaluation,
                                      const MapLocalizationOptions& options,
                                      const StageProgress& progress) {
  if (options.n_pos < 1) {
    throw std::invalid_argument("n_pos must be at least 1, got " + std::to_string(options.n_pos));
  }
  Validate(place);
  Validate(evaluation);
  MapLocalization result;
  result.truth_is_map_log = TruthIsMapLog(map, truth);
  // Scan indices of two files name different scans: no map place is a self-match.
  result.self_match = result.truth_is_map_log ? options.self_match : SelfMatchRule::kNone;
  result.starts = QueryStarts(truth, options.n_pos);
  result.places = map.submaps.size();

  const auto start = std::chrono::steady_clock::now();
  const std::vector<LocalizationQuery> queries =
      BuildSubmapQueries(inputs, truth, map.config, result.starts, place.query_keypoints,
                         AsStage(progress, "query submaps"));
  result.seconds_queries = SecondsSince(start);

  const auto recognition_start = std::chrono::steady_clock::now();
  result.records = EvaluateLocalizationQueries(queries, PlacesFromMap(map), map.submaps, place,
                                               result.self_match, evaluation, progress);
  result.seconds_recognition = SecondsSince(recognition_start);
  result.summary = Summarize(result.records, options.rank_by);
  return result;
}

}  // namespace keyplace
