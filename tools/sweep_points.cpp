#include "sweep_points.hpp"

#include <algorithm>
#include <chrono>
#include <mutex>

#include <fmt/core.h>
#include <tbb/parallel_for.h>

#include "common/seconds_since.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "progress.hpp"

namespace keyplace::cli {

std::vector<double> MappingSweepRow(const LogInputs& inputs, const MappingConfig& config) {
  const LogMap result = MapLog(inputs, config);
  const MappingStats& stats = result.stats;
  return {static_cast<double>(stats.submaps),
          static_cast<double>(stats.forced_submaps),
          stats.compression,
          stats.scans_per_submap,
          stats.distribution,
          stats.keypoints_per_submap,
          static_cast<double>(stats.stable_keypoints),
          result.seconds_per_submap_mapping};
}

PlaceSweepSetting PreparePlaceSweepSetting(const LogInputs& inputs, const MappingConfig& mapping,
                                           int n_pos,
                                           PlaceRecognitionConfig::QueryKeypoints query_keypoints) {
  const GlobalMap map = BuildGlobalMap({inputs.log.scans, inputs.poses, inputs.keypoints}, mapping);
  // Map and queries number the scans of the cut log alike; the fingerprint is the one already read.
  const GroundTruth truth = TruthFromOwnPoses(inputs.log, 0, inputs.source_hash);
  PlaceSweepSetting prepared;
  prepared.submaps = map.submaps.size();
  prepared.places = PlacesFromMap(map);
  prepared.queries =
      BuildSubmapQueries(inputs, truth, mapping, QueryStarts(truth, n_pos), query_keypoints);
  return prepared;
}

std::vector<std::vector<double>> PlaceSweepRows(
    const PlaceSweepSetting& data, const PlaceRecognitionConfig& place,
    const std::vector<RecognitionThresholds>& thresholds, SelfMatchRule rule, RankBy rank_by,
    const std::function<void(double)>& fraction_done) {
  const PlaceRecognizer recognizer(data.places, place);
  const std::vector<std::vector<LocalizationRecord>> records = EvaluateQueriesAtThresholds(
      data.queries, recognizer, rule, thresholds, [&](std::size_t done, std::size_t total) {
        fraction_done(static_cast<double>(done) / static_cast<double>(total));
      });
  std::vector<std::vector<double>> rows;
  for (const std::vector<LocalizationRecord>& setting_records : records) {
    const LocalizationSummary s = Summarize(setting_records, rank_by);
    rows.push_back({static_cast<double>(s.n_pos), static_cast<double>(s.n_acc),
                    static_cast<double>(s.n_cor), s.precision, s.recall, s.scans_mean, s.p_gl,
                    s.p_cl, static_cast<double>(data.submaps), s.seconds_per_query_mean});
  }
  return rows;
}

std::map<std::vector<double>, PlaceSweepSetting> PreparePlaceSweepSettings(
    const LogInputs& inputs, const std::vector<std::vector<double>>& points,
    const std::function<MappingConfig(double, double)>& mapping_at, int n_pos,
    PlaceRecognitionConfig::QueryKeypoints query_keypoints) {
  std::vector<std::vector<double>> settings;
  for (const auto& point : points) {
    const std::vector<double> setting{point[0], point[1]};
    if (std::find(settings.begin(), settings.end(), setting) == settings.end()) {
      settings.push_back(setting);
    }
  }
  std::vector<PlaceSweepSetting> prepared(settings.size());
  const auto start = std::chrono::steady_clock::now();
  Progress progress("maps and queries", settings.size());
  std::mutex progress_mutex;
  std::size_t done = 0;
  tbb::parallel_for(std::size_t{0}, settings.size(), [&](std::size_t i) {
    prepared[i] = PreparePlaceSweepSetting(inputs, mapping_at(settings[i][0], settings[i][1]),
                                           n_pos, query_keypoints);
    const std::lock_guard<std::mutex> lock(progress_mutex);
    progress.Update(++done);
  });
  progress.Finish();
  if (!settings.empty()) {
    fmt::print("maps and query submaps for {} mapping settings in {:.1f} s\n", settings.size(),
               SecondsSince(start));
  }
  std::map<std::vector<double>, PlaceSweepSetting> by_setting;
  for (std::size_t i = 0; i < settings.size(); ++i) {
    by_setting.emplace(settings[i], std::move(prepared[i]));
  }
  return by_setting;
}

}  // namespace keyplace::cli
