#include "keyplace/eval/relocalization.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "common/quantile.hpp"
#include "eval/parallel_progress.hpp"
#include "keyplace/eval/global_localization.hpp"
#include "keyplace/eval/localization.hpp"
#include "keyplace/localization/relocalizer.hpp"

namespace keyplace {
namespace {

constexpr double kRadPerDeg = M_PI / 180.0;

bool Within(const Pose2& a, const Pose2& b, double max_m, double max_deg) {
  const Pose2 difference = Between(a, b);
  return TranslationNorm(difference) <= max_m && std::abs(difference.theta) <= max_deg * kRadPerDeg;
}

// The map's scans a query at truth index t may be matched with: under protocol (a) those of
// submaps sharing no scan with the query's neighbourhood [t - B, t + B], B = the mean submap
// length (a query submap is built like the map's).
class RevisitChecker {
 public:
  RevisitChecker(const GlobalMap& map, const RelocalizationOptions& options) : options_(options) {
    std::size_t scans = 0;
    for (const Submap& submap : map.submaps) {
      if (submap.scan_indices.empty()) continue;
      const auto [low, high] =
          std::minmax_element(submap.scan_indices.begin(), submap.scan_indices.end());
      for (const Pose2& pose : submap.poses) scans_.push_back({pose, *low, *high});
      scans += submap.scan_indices.size();
    }
    if (!map.submaps.empty()) {
      neighbourhood_ = static_cast<int>(
          std::ceil(static_cast<double>(scans) / static_cast<double>(map.submaps.size())));
    }
  }

  bool IsRevisit(const Pose2& truth, int truth_index) const {
    for (const MapScan& scan : scans_) {
      if (options_.exclude_shared_scans && truth_index >= 0 &&
          scan.last_scan >= truth_index - neighbourhood_ &&
          scan.first_scan <= truth_index + neighbourhood_) {
        continue;
      }
      if (Within(scan.pose, truth, options_.revisit_m, options_.revisit_deg)) return true;
    }
    return false;
  }

 private:
  struct MapScan {
    Pose2 pose;
    int first_scan = 0;  // of its submap
    int last_scan = 0;
  };
  const RelocalizationOptions& options_;
  std::vector<MapScan> scans_;
  int neighbourhood_ = 0;
};

// The scan nearest to k (either side, within max_gap scans of [begin, end)) that has a truth pose:
// a raw log has scans without a corrected twin (FR101: one in 16). Odometry carries a fix there.
std::optional<std::size_t> NearestScanWithTruth(const GroundTruth& truth, std::size_t k,
                                                std::size_t begin, std::size_t end, int max_gap) {
  for (std::size_t gap = 0; gap <= static_cast<std::size_t>(std::max(max_gap, 0)); ++gap) {
    if (k + gap < end && truth.Has(k + gap)) return k + gap;
    if (gap <= k && k - gap >= begin && truth.Has(k - gap)) return k - gap;
  }
  return std::nullopt;
}

class StartRun {
 public:
  StartRun(Relocalizer& relocalizer, const LogInputs& inputs, const GroundTruth& truth,
           const RevisitChecker& revisits, const RelocalizationOptions& options)
      : relocalizer_(relocalizer),
        inputs_(inputs),
        truth_(truth),
        revisits_(revisits),
        options_(options) {}

  StartRecord Run(int start_scan) {
    relocalizer_.Reset();
    record_ = StartRecord{};
    record_.start_scan = start_scan;
    FindRevisit();
    const std::size_t scans = inputs_.log.scans.size();
    double travelled_m = 0.0;
    double fixed_at_m = 0.0;
    double seconds_sum = 0.0;
    const long long searches_before = relocalizer_.map_search().searches();
    const double search_s_before = relocalizer_.map_search().search_s();
    std::size_t k = static_cast<std::size_t>(start_scan);
    for (; k < scans; ++k) {
      if (k > static_cast<std::size_t>(start_scan)) {
        travelled_m += TranslationNorm(Between(inputs_.poses[k - 1], inputs_.poses[k]));
      }
      if (!record_.fixed && travelled_m > options_.give_up_m) break;
      if (record_.fixed && travelled_m > fixed_at_m + options_.follow_m) break;
      const auto begin = std::chrono::steady_clock::now();
      const RelocalizationUpdate update =
          relocalizer_.AddScan(inputs_.log.scans[k], inputs_.poses[k], inputs_.keypoints[k],
                               options_.exclude_shared_scans ? TruthIndex(k) : -1);
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
      seconds_sum += seconds;
      record_.update_seconds_max = std::max(record_.update_seconds_max, seconds);
      Record(update, k, travelled_m);
      if (update.new_fix && !record_.fixed) {
        record_.fixed = true;
        fixed_at_m = travelled_m;
      }
    }
    record_.end_scan = static_cast<int>(k);
    const int fed = record_.end_scan - start_scan;
    if (fed > 0) record_.update_seconds_mean = seconds_sum / fed;
    record_.map_searches = static_cast<int>(relocalizer_.map_search().searches() - searches_before);
    record_.map_search_seconds = relocalizer_.map_search().search_s() - search_s_before;
    return record_;
  }

 private:
  // The first scan before the give-up distance whose true pose the map has seen: whether the
  // start can be fixed at all, whatever the localizer does; and the path left after it.
  void FindRevisit() {
    double travelled_m = 0.0;
    double fed_m = 0.0;  // to the last scan a start without a fix is fed
    for (auto k = static_cast<std::size_t>(record_.start_scan); k < inputs_.log.scans.size(); ++k) {
      if (k > static_cast<std::size_t>(record_.start_scan)) {
        travelled_m += TranslationNorm(Between(inputs_.poses[k - 1], inputs_.poses[k]));
      }
      if (travelled_m > options_.give_up_m) break;
      fed_m = travelled_m;
      if (!record_.revisit && truth_.Has(k) &&
          revisits_.IsRevisit(truth_.Pose(k), truth_.TruthScan(k))) {
        record_.revisit = true;
        record_.distance_to_revisit_m = travelled_m;
      }
    }
    if (record_.revisit) record_.room_after_revisit_m = fed_m - record_.distance_to_revisit_m;
  }

  // The scan a fix at scan k is checked at: scans fed so far, and a few ahead (odometry carries
  // the fix there as well).
  std::optional<std::size_t> CheckedScan(std::size_t k) const {
    return NearestScanWithTruth(truth_, k, static_cast<std::size_t>(record_.start_scan),
                                inputs_.log.scans.size(), options_.truth_max_gap_scans);
  }

  int TruthIndex(std::size_t k) const { return truth_.Has(k) ? truth_.TruthScan(k) : -1; }

  void Record(const RelocalizationUpdate& update, std::size_t k, double travelled_m) {
    if (update.lost) RecordLost(k);
    if (update.status == FixStatus::kFixed) previous_T_world_odom_ = update.T_world_odom;
    if (!update.answer && !update.map_search_answer) return;
    for (const std::optional<LocalizationResult>* answer :
         {&update.answer, &update.map_search_answer}) {
      if (!*answer) continue;
      ++record_.answers;
      if ((*answer)->found) ++record_.answers_accepted;
      if (!(*answer)->found && (*answer)->weak_T_world_odom) ++record_.answers_weak;
    }
    if (update.status != FixStatus::kFixed) return;
    const bool first = !record_.fixed && update.new_fix;
    if (first) {
      record_.scans_to_fix = static_cast<int>(k) - record_.start_scan + 1;
      record_.distance_to_fix_m = travelled_m;
    }
    const std::optional<std::size_t> checked = CheckedScan(k);
    if (!checked) return;
    FixEvent fix;
    fix.scan = static_cast<int>(k);
    fix.T_world_robot = update.T_world_odom * inputs_.poses[*checked];
    fix.truth = truth_.Pose(*checked);
    fix.confidence = update.confidence;
    fix.initial_pose = InitialPoseOf(update);
    fix.correct = Within(fix.T_world_robot, fix.truth, options_.correct_m, options_.correct_deg);
    fix.checked_scan = static_cast<int>(*checked);
    fix.first = first;
    if (first) {
      record_.first_fix_checked = true;
      record_.first_fix_correct = fix.correct;
    }
    if (!fix.correct) ++record_.wrong_fixes;
    record_.fixes.push_back(fix);
  }

  void RecordLost(std::size_t k) {
    ++record_.lost;
    const std::optional<std::size_t> checked = CheckedScan(k);
    if (!checked || !previous_T_world_odom_) return;
    const Pose2 track = *previous_T_world_odom_ * inputs_.poses[*checked];
    if (Within(track, truth_.Pose(*checked), options_.correct_m, options_.correct_deg)) {
      ++record_.lost_on_correct_track;
    } else {
      ++record_.lost_on_wrong_track;
    }
  }

  Relocalizer& relocalizer_;
  const LogInputs& inputs_;
  const GroundTruth& truth_;
  const RevisitChecker& revisits_;
  const RelocalizationOptions& options_;
  StartRecord record_;
  std::optional<Pose2> previous_T_world_odom_;
};

}  // namespace

std::vector<StartRecord> RunRelocalization(const GlobalMap& map, const LogInputs& inputs,
                                           const GroundTruth& truth, const LocalizerConfig& config,
                                           const RelocalizationOptions& options,
                                           const StartProgress& progress) {
  Relocalizer prototype(map, config);
  if (options.exclude_shared_scans) {
    prototype.set_exclusion([](const Place& place, const std::vector<int>& query_scans) {
      return IsSelfMatch(SelfMatchRule::kSharedScan, query_scans, place.scan_indices);
    });
  }
  const RevisitChecker revisits(map, options);
  const std::vector<int> starts = QueryStarts(truth, options.starts);
  std::vector<StartRecord> records(starts.size());
  ParallelProgress done(progress, starts.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, starts.size()),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      // A copy shares the prototype's recognizer (read-only) and has its own
                      // query and fix; every start resets them.
                      Relocalizer relocalizer = prototype;
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        StartRun run(relocalizer, inputs, truth, revisits, options);
                        records[i] = run.Run(starts[i]);
                        done.ItemDone();
                      }
                    });
  return records;
}

RelocalizationSummary SummarizeRelocalization(const std::vector<StartRecord>& records,
                                              const RelocalizationOptions& options) {
  RelocalizationSummary s;
  s.starts = records.size();
  std::vector<double> distances;
  std::vector<double> after_revisit;
  std::vector<double> scans_to_fix;
  double seconds_sum = 0.0;
  double search_seconds_sum = 0.0;
  std::size_t updates = 0;
  for (const StartRecord& r : records) {
    s.starts_with_revisit += r.revisit ? 1 : 0;
    const bool room = r.revisit && r.room_after_revisit_m >= options.revisit_room_m;
    s.starts_with_room += room ? 1 : 0;
    if (r.fixed) {
      ++s.fixed;
      s.fixed_with_revisit += r.revisit ? 1 : 0;
      s.fixed_with_room += room ? 1 : 0;
      distances.push_back(r.distance_to_fix_m);
      if (r.revisit)
        after_revisit.push_back(std::max(0.0, r.distance_to_fix_m - r.distance_to_revisit_m));
      scans_to_fix.push_back(r.scans_to_fix);
      if (r.first_fix_checked && !r.first_fix_correct) ++s.wrong_first_fixes;
    }
    for (const FixEvent& fix : r.fixes) {
      ++s.fixes;
      if (fix.correct) continue;
      ++s.wrong_fixes;
      s.wrong_fix_confidence_max = std::max(s.wrong_fix_confidence_max, fix.confidence);
      if (fix.confidence >= options.confident) s.wrong_fix_confident = true;
    }
    s.lost_signals += static_cast<std::size_t>(r.lost);
    s.lost_on_correct_track += r.lost_on_correct_track;
    s.lost_on_wrong_track += r.lost_on_wrong_track;
    const int fed = r.end_scan - r.start_scan;
    seconds_sum += r.update_seconds_mean * fed;
    updates += static_cast<std::size_t>(std::max(fed, 0));
    s.update_seconds_max = std::max(s.update_seconds_max, r.update_seconds_max);
    s.map_searches += static_cast<std::size_t>(r.map_searches);
    search_seconds_sum += r.map_search_seconds;
  }
  if (s.starts_with_revisit > 0) {
    s.fixed_fraction = static_cast<double>(s.fixed_with_revisit) / s.starts_with_revisit;
  }
  if (s.starts_with_room > 0) {
    s.fixed_fraction_with_room = static_cast<double>(s.fixed_with_room) / s.starts_with_room;
  }
  if (s.fixes > 0) s.wrong_fix_rate = static_cast<double>(s.wrong_fixes) / s.fixes;
  s.distance_to_fix_median_m = Quantile(distances, 0.5);
  s.distance_to_fix_p90_m = Quantile(distances, 0.9);
  s.scans_to_fix_median = Quantile(scans_to_fix, 0.5);
  s.distance_after_revisit_median_m = Quantile(after_revisit, 0.5);
  s.distance_after_revisit_p90_m = Quantile(after_revisit, 0.9);
  if (updates > 0) {
    s.update_seconds_mean = seconds_sum / static_cast<double>(updates);
    s.update_seconds_mean_without_search =
        std::max(0.0, seconds_sum - search_seconds_sum) / static_cast<double>(updates);
  }
  if (s.map_searches > 0) {
    s.map_search_seconds_mean = search_seconds_sum / static_cast<double>(s.map_searches);
  }
  return s;
}

RelocalizationOptions RelocalizationOptionsFor(const EvaluationConfig& evaluation, int starts,
                                               bool shared_scan_rule, bool query_log_is_map_log) {
  if (starts < 1) {
    throw std::invalid_argument("relocalization: starts is " + std::to_string(starts) +
                                ", must be >= 1");
  }
  RelocalizationOptions options;
  options.starts = starts;
  options.give_up_m = evaluation.give_up_m;
  options.follow_m = evaluation.follow_m;
  options.revisit_m = evaluation.revisit_radius_m;
  options.revisit_deg = evaluation.revisit_angle_deg;
  options.revisit_room_m = evaluation.revisit_room_m;
  options.truth_max_gap_scans = evaluation.truth_max_gap_scans;
  options.exclude_shared_scans = shared_scan_rule && query_log_is_map_log;
  return options;
}

std::optional<FirstFix> FirstFixOf(const std::vector<StartRecord>& records) {
  for (const StartRecord& record : records) {
    for (const FixEvent& fix : record.fixes) {
      if (fix.first) return FirstFix{record.start_scan, fix};
    }
  }
  return std::nullopt;
}

}  // namespace keyplace
