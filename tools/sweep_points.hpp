#pragma once
// The rows of the sweeps (keyplace sweep): the mapping criteria of one mapping setting, and the
// Algorithm 4 figures of one place-recognition setting on queries prepared once per mapping
// setting (eval/global_localization.hpp, as keyplace localize).

#include <cstddef>
#include <functional>
#include <map>
#include <vector>

#include "keyplace/eval/global_localization.hpp"
#include "keyplace/mapping/mapping_config.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "keyplace/place/place_recognizer.hpp"

namespace keyplace::cli {

/// submaps, forced_submaps, compression, scans_per_submap, distribution, keypoints_per_submap,
/// stable_keypoints, seconds_per_submap.
std::vector<double> MappingSweepRow(const LogInputs& inputs, const MappingConfig& config);

/// The map and the Algorithm 4 queries of one mapping setting (a corrected log is its own truth).
struct PlaceSweepSetting {
  std::vector<Place> places;
  std::vector<LocalizationQuery> queries;
  std::size_t submaps = 0;
};
PlaceSweepSetting PreparePlaceSweepSetting(const LogInputs& inputs, const MappingConfig& mapping,
                                           int n_pos,
                                           PlaceRecognitionConfig::QueryKeypoints query_keypoints);

/// PreparePlaceSweepSetting for every mapping setting (s_min, l_g: the first two values) of the
/// `points`, in parallel, with progress and a line on stdout; `mapping_at` gives the mapping
/// configuration of a setting. Keyed by {s_min, l_g}.
std::map<std::vector<double>, PlaceSweepSetting> PreparePlaceSweepSettings(
    const LogInputs& inputs, const std::vector<std::vector<double>>& points,
    const std::function<MappingConfig(double, double)>& mapping_at, int n_pos,
    PlaceRecognitionConfig::QueryKeypoints query_keypoints);

/// One row per threshold setting (n_pos, n_acc, n_cor, precision, recall, scans_mean, p_gl,
/// p_cl, submaps, seconds_per_query) of `place` with those thresholds: each query is recognised
/// once for all of them (EvaluateQueriesAtThresholds), so seconds_per_query is the shared
/// recognition's, the same in every row. `fraction_done` gets the share of the queries done.
std::vector<std::vector<double>> PlaceSweepRows(
    const PlaceSweepSetting& setting, const PlaceRecognitionConfig& place,
    const std::vector<RecognitionThresholds>& thresholds, SelfMatchRule rule, RankBy rank_by,
    const std::function<void(double)>& fraction_done);

}  // namespace keyplace::cli
