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
  std::vector<int> truth_scans;  // sorted truth-log indices of its scans (self-match rule)
  Pose2 truth;                   // true pose of evaluated_scan
  double build_seconds = 0.0;
};

/// Progress: (queries done, queries in all).
using QueryProgress = std::function<void(std::size_t, std::size_t)>;

/// The start scans of n_pos queries: equally spaced over the scans that have a truth pose.
std::vector<int> QueryStarts(const GroundTruth& truth, int n_pos);

/// The submap queries of Algorithm 4 from `starts`, built with the map's mapping configuration.
/// Stops at the first start whose submap the log ends before completing (as the paper does).
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
  double build_seconds = 0.0;
};

/// The score answers are ranked by for the precision-recall curve.
enum class RankBy { kConfidence, kGamma, kConsensus, kScore };
RankBy ParseRankBy(const std::string& name);  // confidence | gamma | consensus | score
std::string ToString(RankBy rank_by);
double RankScore(RankBy rank_by, const PlaceMatch& match);

/// The figures of a set of records.
struct LocalizationSummary {
  std::size_t n_pos = 0;  // queries evaluated
  std::size_t n_acc = 0;  // accepted answers
  std::size_t n_cor = 0;  // correct accepted answers
  std::size_t n_verified = 0;
  std::size_t n_ambiguous = 0;
  std::size_t n_ambiguous_wrong = 0;
  double precision = 0.0;   // n_cor / n_acc (0 when nothing was accepted)
  double recall = 0.0;      // n_cor / n_pos
  double scans_mean = 0.0;  // scans of the correctly answered queries
  double scans_mean_all_queries = 0.0;
  double seconds_per_query_mean = 0.0;  // recognition
  double seconds_submap_building_mean = 0.0;
  RankBy rank_by = RankBy::kConfidence;
  std::vector<PrPoint> curve;  // ranked by rank_by
  double p_gl = 0.0;
  double p_cl = 0.0;
};
LocalizationSummary Summarize(const std::vector<LocalizationRecord>& records, RankBy rank_by);

/// Recognises every query with `recognizer`, skipping the places `rule` calls self-matches.
std::vector<LocalizationRecord> EvaluateQueries(const std::vector<LocalizationQuery>& queries,
                                                const PlaceRecognizer& recognizer,
                                                SelfMatchRule rule,
                                                const QueryProgress& progress = {});

/// The places of the TIP-FLIRT baseline: every scan of a log with corrected poses, all its FLIRT
/// keypoints in the robot frame.
std::vector<Place> ScanPlaces(const LogInputs& map_log);

}  // namespace keyplace
