#pragma once
// Paper Algorithm 4, once, for every command that evaluates global localization (`keyplace
// localize`, `keyplace sweep place`): n_pos query submaps from equally spaced start scans, built
// by the streaming localizer's SubmapQueryBuilder, recognised against the map with self-matches
// excluded, each answer checked against ground truth; precision, recall, P_GL / P_CL, timings.
// The queries are built once (they depend on the mapping configuration only) and can then be
// evaluated under many place-recognition configurations.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "keyplace/common/pose2.hpp"
#include "keyplace/common/result_fields.hpp"
#include "keyplace/eval/evaluation_config.hpp"
#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/eval/localization.hpp"
#include "keyplace/mapping/mapping_config.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "keyplace/place/place_config.hpp"
#include "keyplace/place/place_recognizer.hpp"

namespace keyplace {

/// One query of Algorithm 4, ready for recognition.
struct LocalizationQuery {
  int start_scan = 0;      // query-log scan the query submap starts at
  int evaluated_scan = 0;  // its latest scan with a truth pose: the pose estimated
  int scans = 0;           // scans in the query (1 for single-scan queries)
  PlaceQuery query;
  // Sorted truth-log file indices of its scans (GroundTruth::TruthScan): the self-match rule
  // compares them with the map's file scan indices.
  std::vector<int> truth_scans;
  Pose2 truth;  // true pose of evaluated_scan
  double build_seconds = 0.0;
};

/// Progress: (queries done, queries in all). The functions below work on their queries in
/// parallel (TBB; tbb::global_control bounds the threads) and call it from one thread at a time,
/// with queries done counting up.
using QueryProgress = std::function<void(std::size_t, std::size_t)>;

/// The start scans of n_pos queries: equally spaced over the scans that have a truth pose, all
/// distinct (fewer than n_pos when fewer scans have one).
std::vector<int> QueryStarts(const GroundTruth& truth, int n_pos);

/// The submap queries of Algorithm 4 from `starts`, built with the map's mapping configuration.
/// Stops at the first start whose submap the log ends before completing (as the paper does).
/// The queries, in the order of `starts`, do not depend on the thread count (build_seconds is
/// the time of each query's own build).
std::vector<LocalizationQuery> BuildSubmapQueries(
    const LogInputs& inputs, const GroundTruth& truth, const MappingConfig& mapping,
    const std::vector<int>& starts, PlaceRecognitionConfig::QueryKeypoints query_keypoints,
    const QueryProgress& progress = {});

/// Single-scan queries (the TIP-FLIRT baseline): each start scan's keypoints, robot frame.
std::vector<LocalizationQuery> BuildScanQueries(const LogInputs& inputs, const GroundTruth& truth,
                                                const std::vector<int>& starts);

/// One evaluated query.
struct LocalizationRecord {
  int start_scan = 0;
  int evaluated_scan = 0;
  int scans = 0;
  PlaceMatch match;
  Pose2 truth;
  bool correct = false;           // accepted and within 0.5 m / 10 deg
  bool verified_correct = false;  // best verified candidate within 0.5 m / 10 deg
  // A map scan lies near the true pose (IsRevisitable) in a place the self-match rule left in.
  bool revisitable = false;
  double build_seconds = 0.0;
};

/// The score answers are ranked by for the precision-recall curve.
enum class RankBy { kConfidence, kGamma, kConsensus, kScore };
RankBy ParseRankBy(const std::string& name);  // confidence | gamma | consensus | score
std::string ToString(RankBy rank_by);
double RankScore(RankBy rank_by, const PlaceMatch& match);

/// Accepted answers whose confidence falls in [bin_low, bin_high) (the last bin includes 1): a
/// calibrated confidence has precision close to confidence_mean in every bin.
struct ReliabilityBin {
  double bin_low = 0.0;
  double bin_high = 0.0;
  std::size_t count = 0;         // accepted answers in the bin
  double confidence_mean = 0.0;  // 0 when count is 0
  double precision = 0.0;        // correct / count; 0 when count is 0
};

/// Width of the reliability bins: 10 bins over [0, 1].
inline constexpr double kReliabilityBinWidth = 0.1;

/// The reliability diagram of the accepted answers of `records` by PlaceMatch::confidence.
std::vector<ReliabilityBin> ReliabilityDiagram(const std::vector<LocalizationRecord>& records);

/// The figures of a set of records.
struct LocalizationSummary {
  std::size_t n_pos = 0;  // queries evaluated
  std::size_t n_acc = 0;  // accepted answers
  std::size_t n_cor = 0;  // correct accepted answers
  std::size_t n_verified = 0;
  std::size_t n_ambiguous = 0;
  std::size_t n_ambiguous_wrong = 0;
  double precision = 0.0;  // n_cor / n_acc (0 when nothing was accepted)
  double recall = 0.0;     // n_cor / n_pos
  // Queries whose place the map has seen (LocalizationRecord::revisitable), and the correct
  // answers among them / n_revisitable (0 when there is none): misses of places seen once in the
  // query log do not count.
  std::size_t n_revisitable = 0;
  std::size_t n_cor_revisitable = 0;
  double recall_revisitable = 0.0;
  double scans_mean = 0.0;  // scans of the correctly answered queries
  double scans_mean_all_queries = 0.0;
  double seconds_per_query_mean = 0.0;  // recognition
  double seconds_submap_building_mean = 0.0;
  RankBy rank_by = RankBy::kConfidence;
  std::vector<PrPoint> curve;  // ranked by rank_by
  double p_gl = 0.0;
  double p_cl = 0.0;
  std::vector<ReliabilityBin> reliability;  // ReliabilityDiagram
};
LocalizationSummary Summarize(const std::vector<LocalizationRecord>& records, RankBy rank_by);

/// The summary's figures (all but the curve and the reliability bins), named as the keys of
/// `keyplace localize --json` and the attributes of Python's LocalizationEvaluation.
const ResultFields<LocalizationSummary>& LocalizationSummaryFields();

/// Recognises every query with `recognizer`, skipping the places `rule` calls self-matches. Each
/// record's `revisitable` is false; MarkRevisitable sets it. The queries are recognised in
/// parallel; the records, in the order of `queries`, do not depend on the thread count (except
/// the time fields of PlaceMatch).
std::vector<LocalizationRecord> EvaluateQueries(const std::vector<LocalizationQuery>& queries,
                                                const PlaceRecognizer& recognizer,
                                                SelfMatchRule rule,
                                                const QueryProgress& progress = {});

/// EvaluateQueries under each of `thresholds` at once (PlaceRecognizer::RecognizeAtThresholds:
/// the pairs found and each candidate verified once per query). records[k][i] equals what
/// EvaluateQueries gives for queries[i] with a recognizer of thresholds[k], but for the time
/// fields of PlaceMatch (the shared work's).
std::vector<std::vector<LocalizationRecord>> EvaluateQueriesAtThresholds(
    const std::vector<LocalizationQuery>& queries, const PlaceRecognizer& recognizer,
    SelfMatchRule rule, const std::vector<RecognitionThresholds>& thresholds,
    const QueryProgress& progress = {});

/// Whether the true pose of `query` has a scan of `map_scans` within
/// config.revisit_radius_m and config.revisit_angle_deg whose place `rule` does not exclude for
/// this query (the exclusion EvaluateQueries applies). `map_scans` are places with the world
/// poses of their scans: submaps (Submap::poses, the map's frame), or single scans.
bool IsRevisitable(const LocalizationQuery& query, const std::vector<Submap>& map_scans,
                   SelfMatchRule rule, const EvaluationConfig& config);

/// Sets records[i].revisitable = IsRevisitable(queries[i], ...); records[i] must answer
/// queries[i] (EvaluateQueries keeps the order). Throws std::invalid_argument on a size mismatch.
void MarkRevisitable(const std::vector<LocalizationQuery>& queries,
                     const std::vector<Submap>& map_scans, SelfMatchRule rule,
                     const EvaluationConfig& config, std::vector<LocalizationRecord>& records);

/// The single-scan places of ScanPlaces as one-scan submaps (their scan index and pose), for
/// IsRevisitable.
std::vector<Submap> ScanPlacesAsSubmaps(const std::vector<Place>& places);

/// The places of the TIP-FLIRT baseline: every scan of a log with corrected poses, all its FLIRT
/// keypoints in the robot frame; scan indices are those of the file (offset by
/// map_log.first_scan), like a map's.
std::vector<Place> ScanPlaces(const LogInputs& map_log);

}  // namespace keyplace
