#include "keyplace/eval/global_localization.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "common/seconds_since.hpp"
#include "eval/parallel_progress.hpp"
#include "keyplace/localization/query_builder.hpp"

namespace keyplace {
namespace {

// The evaluated scan of a query submap (its latest scan with a truth pose) and the sorted truth
// indices of its scans.
void SetTruth(const SubmapQueryBuilder& builder, const GroundTruth& truth, LocalizationQuery& query,
              std::size_t& evaluated_position) {
  for (std::size_t k = builder.size(); k-- > 0;) {
    if (truth.Has(static_cast<std::size_t>(builder.scan_id(k)))) {
      evaluated_position = k;
      break;
    }
  }
  query.evaluated_scan = builder.scan_id(evaluated_position);
  for (std::size_t k = 0; k < builder.size(); ++k) {
    const auto scan = static_cast<std::size_t>(builder.scan_id(k));
    if (truth.Has(scan)) query.truth_scans.push_back(truth.TruthScan(scan));
  }
  std::sort(query.truth_scans.begin(), query.truth_scans.end());
  query.truth = truth.Pose(static_cast<std::size_t>(query.evaluated_scan));
}

// A record of `query` with its answer.
LocalizationRecord Record(const LocalizationQuery& query, PlaceMatch match) {
  LocalizationRecord record;
  record.start_scan = query.start_scan;
  record.evaluated_scan = query.evaluated_scan;
  record.scans = query.scans;
  record.truth = query.truth;
  record.build_seconds = query.build_seconds;
  record.match = std::move(match);
  record.verified_correct =
      record.match.verified && IsCorrectPose(record.match.estimated_pose, record.truth);
  record.correct = record.match.found && record.verified_correct;
  return record;
}

PlaceExclusion SelfMatches(const LocalizationQuery& query, SelfMatchRule rule) {
  return [&query, rule](const Place& place) {
    return IsSelfMatch(rule, query.truth_scans, place.scan_indices);
  };
}

}  // namespace

std::vector<int> QueryStarts(const GroundTruth& truth, int n_pos) {
  if (n_pos < 1) throw std::invalid_argument("n_pos must be >= 1");
  std::vector<int> eligible;
  for (std::size_t k = 0; k < truth.truth_index_of_scan.size(); ++k) {
    if (truth.Has(k)) eligible.push_back(static_cast<int>(k));
  }
  if (eligible.empty()) throw std::invalid_argument("no query scan has a ground-truth pose");
  // More queries than scans would repeat starts (the same query counted twice): cap instead.
  const std::size_t count = std::min(static_cast<std::size_t>(n_pos), eligible.size());
  std::vector<int> starts;
  starts.reserve(count);
  for (std::size_t i = 0; i < count; ++i) starts.push_back(eligible[i * eligible.size() / count]);
  return starts;
}

std::vector<LocalizationQuery> BuildSubmapQueries(
    const LogInputs& inputs, const GroundTruth& truth, const MappingConfig& mapping,
    const std::vector<int>& starts, PlaceRecognitionConfig::QueryKeypoints query_keypoints,
    const QueryProgress& progress) {
  const std::vector<LogScan>& scans = inputs.log.scans;
  std::vector<LocalizationQuery> queries(starts.size());
  // Algorithm 4 stops at the first start whose submap the log ends before completing: the
  // smallest such index. Once one is known, later starts are skipped; all are dropped at the end.
  std::atomic<std::size_t> first_incomplete{starts.size()};
  ParallelProgress done(progress, starts.size());
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, starts.size()),
      [&](const tbb::blocked_range<std::size_t>& range) {
        SubmapQueryBuilder builder(mapping);  // reset for every query: none depends on another
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          if (i > first_incomplete.load()) return;  // so are the rest of the range
          const auto start = std::chrono::steady_clock::now();
          builder.Reset();
          bool complete = false;
          for (auto k = static_cast<std::size_t>(starts[i]); k < scans.size() && !complete; ++k) {
            complete = builder.AddScan(scans[k], inputs.poses[k], inputs.keypoints[k],
                                       static_cast<int>(k));
          }
          if (!complete) {
            std::size_t known = first_incomplete.load();
            while (i < known && !first_incomplete.compare_exchange_weak(known, i)) {
            }
            return;
          }
          LocalizationQuery& query = queries[i];
          query.start_scan = starts[i];
          query.scans = static_cast<int>(builder.size());
          std::size_t evaluated_position = 0;  // the start scan has a truth pose
          SetTruth(builder, truth, query, evaluated_position);
          query.query = builder.Query(evaluated_position, query_keypoints);
          query.build_seconds = SecondsSince(start);
          done.ItemDone();
        }
      });
  queries.resize(first_incomplete.load());
  return queries;
}

std::vector<LocalizationQuery> BuildScanQueries(const LogInputs& inputs, const GroundTruth& truth,
                                                const std::vector<int>& starts) {
  std::vector<LocalizationQuery> queries;
  for (const int start : starts) {
    const auto scan = static_cast<std::size_t>(start);
    LocalizationQuery query;
    query.start_scan = query.evaluated_scan = start;
    query.scans = 1;
    for (const Keypoint& keypoint : inputs.keypoints[scan]) {
      query.query.positions.push_back(inputs.log.scans[scan].T_robot_laser * keypoint.position_m);
      query.query.descriptors.push_back(keypoint.descriptor);
    }
    query.truth_scans = {truth.TruthScan(scan)};
    query.truth = truth.Pose(scan);
    queries.push_back(std::move(query));
  }
  return queries;
}

RankBy ParseRankBy(const std::string& name) {
  if (name == "confidence") return RankBy::kConfidence;
  if (name == "gamma") return RankBy::kGamma;
  if (name == "consensus") return RankBy::kConsensus;
  if (name == "score") return RankBy::kScore;
  throw std::invalid_argument("rank-by '" + name +
                              "': expected confidence, gamma, consensus or score");
}

std::string ToString(RankBy rank_by) {
  switch (rank_by) {
    case RankBy::kConfidence:
      return "confidence";
    case RankBy::kGamma:
      return "gamma";
    case RankBy::kConsensus:
      return "consensus";
    case RankBy::kScore:
      return "score";
  }
  return "?";
}

double RankScore(RankBy rank_by, const PlaceMatch& match) {
  switch (rank_by) {
    case RankBy::kGamma:
      return match.gamma;
    case RankBy::kConsensus:
      return match.consensus;
    case RankBy::kScore:
      return match.score;
    case RankBy::kConfidence:
      break;
  }
  return match.confidence;
}

std::vector<LocalizationRecord> EvaluateQueries(const std::vector<LocalizationQuery>& queries,
                                                const PlaceRecognizer& recognizer,
                                                SelfMatchRule rule, const QueryProgress& progress) {
  std::vector<LocalizationRecord> records(queries.size());
  ParallelProgress done(progress, queries.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size()),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const LocalizationQuery& query = queries[i];
                        records[i] = Record(
                            query, recognizer.Recognize(query.query, SelfMatches(query, rule)));
                        done.ItemDone();
                      }
                    });
  return records;
}

std::vector<std::vector<LocalizationRecord>> EvaluateQueriesAtThresholds(
    const std::vector<LocalizationQuery>& queries, const PlaceRecognizer& recognizer,
    SelfMatchRule rule, const std::vector<RecognitionThresholds>& thresholds,
    const QueryProgress& progress) {
  std::vector<std::vector<LocalizationRecord>> records(
      thresholds.size(), std::vector<LocalizationRecord>(queries.size()));
  ParallelProgress done(progress, queries.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size()),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const LocalizationQuery& query = queries[i];
                        std::vector<PlaceMatch> matches = recognizer.RecognizeAtThresholds(
                            query.query, thresholds, SelfMatches(query, rule));
                        for (std::size_t k = 0; k < thresholds.size(); ++k) {
                          records[k][i] = Record(query, std::move(matches[k]));
                        }
                        done.ItemDone();
                      }
                    });
  return records;
}

bool IsRevisitable(const LocalizationQuery& query, const std::vector<Submap>& map_scans,
                   SelfMatchRule rule, const EvaluationConfig& config) {
  const double max_angle_rad = config.revisit_angle_deg * M_PI / 180.0;
  for (const Submap& submap : map_scans) {
    const bool near = std::any_of(submap.poses.begin(), submap.poses.end(), [&](const Pose2& p) {
      return std::hypot(p.x - query.truth.x, p.y - query.truth.y) <= config.revisit_radius_m &&
             std::abs(WrapAngle(p.theta - query.truth.theta)) <= max_angle_rad;
    });
    // The rule is checked only for nearby places: it sorts both scan lists.
    if (near && !IsSelfMatch(rule, query.truth_scans, submap.scan_indices)) return true;
  }
  return false;
}

void MarkRevisitable(const std::vector<LocalizationQuery>& queries,
                     const std::vector<Submap>& map_scans, SelfMatchRule rule,
                     const EvaluationConfig& config, std::vector<LocalizationRecord>& records) {
  if (records.size() != queries.size()) {
    throw std::invalid_argument("MarkRevisitable: " + std::to_string(records.size()) +
                                " records for " + std::to_string(queries.size()) + " queries");
  }
  for (std::size_t i = 0; i < queries.size(); ++i) {
    records[i].revisitable = IsRevisitable(queries[i], map_scans, rule, config);
  }
}

std::vector<Submap> ScanPlacesAsSubmaps(const std::vector<Place>& places) {
  std::vector<Submap> submaps;
  submaps.reserve(places.size());
  for (const Place& place : places) {
    Submap submap;
    submap.id = place.id;
    submap.scan_indices = place.scan_indices;
    submap.poses = {place.T_world_place};
    submaps.push_back(std::move(submap));
  }
  return submaps;
}

std::vector<ReliabilityBin> ReliabilityDiagram(const std::vector<LocalizationRecord>& records) {
  const auto bins = static_cast<std::size_t>(std::lround(1.0 / kReliabilityBinWidth));
  std::vector<ReliabilityBin> diagram(bins);
  std::vector<std::size_t> correct(bins, 0);
  for (std::size_t b = 0; b < bins; ++b) {
    diagram[b].bin_low = static_cast<double>(b) / static_cast<double>(bins);
    diagram[b].bin_high = static_cast<double>(b + 1) / static_cast<double>(bins);
  }
  for (const LocalizationRecord& r : records) {
    if (!r.match.found) continue;
    const double confidence = std::clamp(r.match.confidence, 0.0, 1.0);
    // Times the bin count, not divided by the width: 0.3 / 0.1 falls just below 3. Confidence 1
    // belongs to the last bin.
    const std::size_t b =
        std::min(bins - 1, static_cast<std::size_t>(confidence * static_cast<double>(bins)));
    ++diagram[b].count;
    diagram[b].confidence_mean += r.match.confidence;
    if (r.correct) ++correct[b];
  }
  for (std::size_t b = 0; b < bins; ++b) {
    if (diagram[b].count == 0) continue;
    const auto count = static_cast<double>(diagram[b].count);
    diagram[b].confidence_mean /= count;
    diagram[b].precision = static_cast<double>(correct[b]) / count;
  }
  return diagram;
}

LocalizationSummary Summarize(const std::vector<LocalizationRecord>& records, RankBy rank_by) {
  LocalizationSummary s;
  s.n_pos = records.size();
  s.rank_by = rank_by;
  double scans_correct = 0.0;
  double scans_all = 0.0;
  double seconds = 0.0;
  double build_seconds = 0.0;
  std::vector<RankedAnswer> answers;
  for (const LocalizationRecord& r : records) {
    seconds += r.match.seconds;
    build_seconds += r.build_seconds;
    scans_all += r.scans;
    if (r.match.verified) ++s.n_verified;
    if (r.match.ambiguous) {
      ++s.n_ambiguous;
      if (!r.verified_correct) ++s.n_ambiguous_wrong;
    }
    if (r.match.found) ++s.n_acc;
    if (r.correct) {
      ++s.n_cor;
      scans_correct += r.scans;
    }
    if (r.revisitable) {
      ++s.n_revisitable;
      if (r.correct) ++s.n_cor_revisitable;
    }
    answers.push_back({r.match.verified, r.verified_correct, RankScore(rank_by, r.match)});
  }
  const auto n = static_cast<double>(s.n_pos);
  s.precision = s.n_acc > 0 ? static_cast<double>(s.n_cor) / static_cast<double>(s.n_acc) : 0.0;
  s.recall = s.n_pos > 0 ? static_cast<double>(s.n_cor) / n : 0.0;
  s.recall_revisitable = s.n_revisitable > 0 ? static_cast<double>(s.n_cor_revisitable) /
                                                   static_cast<double>(s.n_revisitable)
                                             : 0.0;
  s.scans_mean = s.n_cor > 0 ? scans_correct / static_cast<double>(s.n_cor) : 0.0;
  s.scans_mean_all_queries = s.n_pos > 0 ? scans_all / n : 0.0;
  s.seconds_per_query_mean = s.n_pos > 0 ? seconds / n : 0.0;
  s.seconds_submap_building_mean = s.n_pos > 0 ? build_seconds / n : 0.0;
  s.curve = PrecisionRecallCurve(answers, s.n_pos);
  s.p_gl = PrecisionAtMaxRecall(s.curve);
  s.p_cl = RecallAtPrecision(s.curve, 0.95);
  s.reliability = ReliabilityDiagram(records);
  return s;
}

std::vector<Place> ScanPlaces(const LogInputs& map_log) {
  std::vector<Place> places;
  places.reserve(map_log.log.scans.size());
  for (std::size_t k = 0; k < map_log.log.scans.size(); ++k) {
    const LogScan& scan = map_log.log.scans[k];
    if (!scan.corrected_pose) {
      throw std::invalid_argument(map_log.log.path + ":" + std::to_string(scan.line) +
                                  ": single-scan places need corrected poses");
    }
    Place place;
    place.id = static_cast<int>(map_log.first_scan + k);
    place.T_world_place = *scan.corrected_pose;
    for (const Keypoint& keypoint : map_log.keypoints[k]) {
      place.positions.push_back(scan.T_robot_laser * keypoint.position_m);
      place.descriptors.push_back(keypoint.descriptor);
    }
    place.scan_indices = {static_cast<int>(map_log.first_scan + k)};
    places.push_back(std::move(place));
  }
  return places;
}

}  // namespace keyplace
