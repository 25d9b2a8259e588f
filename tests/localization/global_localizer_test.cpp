#include "keyplace/localization/global_localizer.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/eval/localization.hpp"
#include "keyplace/localization/relocalizer.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "place/submap_query.hpp"
#include "support/bundled_map.hpp"
#include "support/sanitizers.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

using Bundled = testing::BundledMap;
const Bundled& BundledLog() { return testing::BundledFr079(); }

std::vector<int> SortedScans(const std::vector<int>& scans) {
  std::vector<int> sorted = scans;
  std::sort(sorted.begin(), sorted.end());
  return sorted;
}

// The batch pipeline `keyplace localize` ran before the localizer existed (Algorithm 4 by hand:
// BuildSubmap from the start scan, MakeSubmapQuery, Recognize), as the oracle.
PlaceMatch BatchAnswer(const Bundled& b, const PlaceRecognizer& recognizer, int start_scan,
                       bool* complete) {
  const ScanSequence sequence{b.inputs.log.scans, b.inputs.poses, b.inputs.keypoints};
  LocalMapper mapper(b.map.config);
  const std::optional<Submap> submap =
      BuildSubmap(sequence, static_cast<std::size_t>(start_scan), mapper);
  *complete = submap.has_value();
  if (!submap) return {};
  const PlaceQuery query = MakeSubmapQuery(*submap, sequence, submap->scan_indices.back(),
                                           recognizer.config().query_keypoints);
  const std::vector<int> scans = SortedScans(submap->scan_indices);
  return recognizer.Recognize(query, [&](const Place& place) {
    return IsSelfMatch(SelfMatchRule::kSameScans, scans, place.scan_indices);
  });
}

// Every second of the 500 starts of Algorithm 4 (the other half adds time, not cases: the same
// code runs from neighbouring starts).
TEST(GlobalLocalizer, StreamingGivesTheBatchAnswerOnEverySecondQueryOfTheBundledLog) {
  const Bundled& b = BundledLog();
  LocalizerConfig complete_queries_only;
  complete_queries_only.query_every_m = 0.0;
  GlobalLocalizer localizer(b.map, complete_queries_only);
  localizer.set_exclusion([](const Place& place, const std::vector<int>& query_scans) {
    return IsSelfMatch(SelfMatchRule::kSameScans, SortedScans(query_scans), place.scan_indices);
  });
  const std::size_t n_scans = b.inputs.log.scans.size();
  const int n_pos = 500;
  int compared = 0;
  int found = 0;
  for (int i = 0; i < n_pos; i += 2) {
    const int start = static_cast<int>(static_cast<std::size_t>(i) * n_scans / n_pos);
    bool complete = false;
    const PlaceMatch batch = BatchAnswer(b, localizer.recognizer(), start, &complete);
    localizer.Reset();
    std::optional<LocalizationResult> streamed;
    for (std::size_t k = static_cast<std::size_t>(start); k < n_scans && !streamed; ++k) {
      streamed = localizer.AddScan(b.inputs.log.scans[k], b.inputs.poses[k], b.inputs.keypoints[k],
                                   static_cast<int>(k));
    }
    ASSERT_EQ(streamed.has_value(), complete) << "start " << start;
    if (!complete) break;  // the log ends before the query submap is complete
    const PlaceMatch& m = streamed->match;
    ASSERT_EQ(m.verified, batch.verified) << "start " << start;
    EXPECT_EQ(m.found, batch.found) << "start " << start;
    EXPECT_EQ(m.ambiguous, batch.ambiguous) << "start " << start;
    EXPECT_EQ(m.place_id, batch.place_id) << "start " << start;
    EXPECT_EQ(m.consensus, batch.consensus) << "start " << start;
    EXPECT_EQ(m.gamma, batch.gamma) << "start " << start;
    EXPECT_EQ(m.confidence, batch.confidence) << "start " << start;
    EXPECT_EQ(m.candidates, batch.candidates) << "start " << start;
    EXPECT_EQ(m.estimated_pose.x, batch.estimated_pose.x) << "start " << start;
    EXPECT_EQ(m.estimated_pose.y, batch.estimated_pose.y) << "start " << start;
    EXPECT_EQ(m.estimated_pose.theta, batch.estimated_pose.theta) << "start " << start;
    if (m.verified) {
      EXPECT_EQ(streamed->submap_id, m.place_id);
      // The robot pose is the latest scan's, and T_world_odom carries odometry into the map.
      const Pose2 recomposed = streamed->T_world_odom *
                               b.inputs.poses[static_cast<std::size_t>(streamed->scan_ids.back())];
      EXPECT_NEAR(recomposed.x, streamed->T_world_robot.x, 1e-9);
      EXPECT_NEAR(recomposed.y, streamed->T_world_robot.y, 1e-9);
    }
    found += m.found ? 1 : 0;
    ++compared;
  }
  // Almost every start of the log completes a query, and most are answered (recall ~0.9).
  EXPECT_GT(compared, 240);
  EXPECT_GT(found, compared / 2);
}

// With retrieval `words` and one place retrieved, the words alone miss most places; a belief at the
// true map <- odometry transform (the bundled log's odometry is its corrected poses: identity)
// makes every query also pair the places near the robot, and many answers come back. A belief
// elsewhere brings none back.
TEST(GlobalLocalizer, BeliefsMakeTheQueriesAlsoPairThePlacesNearThem) {
  const Bundled& b = BundledLog();
  const auto right_answers = [&](const std::vector<Pose2>& beliefs) {
    LocalizerConfig config;
    config.query_every_m = 0.0;
    config.place.retrieval = PlaceRecognitionConfig::Retrieval::kWords;
    config.place.retrieval_places = 1;
    GlobalLocalizer localizer(b.map, config);
    localizer.set_exclusion([](const Place& place, const std::vector<int>& query_scans) {
      return IsSelfMatch(SelfMatchRule::kSameScans, SortedScans(query_scans), place.scan_indices);
    });
    localizer.set_beliefs(beliefs);
    int right = 0;
    for (std::size_t k = 0; k < b.inputs.log.scans.size(); ++k) {
      const std::optional<LocalizationResult> answer = localizer.AddScan(
          b.inputs.log.scans[k], b.inputs.poses[k], b.inputs.keypoints[k], static_cast<int>(k));
      if (!answer || !answer->found) continue;
      const Pose2 error = Between(b.inputs.poses[k], answer->T_world_robot);
      if (std::hypot(error.x, error.y) < 0.5) ++right;
    }
    return right;
  };
  const int words_alone = right_answers({});
  const int near_truth = right_answers({Pose2()});
  // Measured: 118 right answers with the words alone, 163 with the belief (exact: 220).
  EXPECT_GT(near_truth, words_alone + 30) << "words alone " << words_alone;
  EXPECT_EQ(right_answers({Pose2(500.0, 500.0, 0.0)}), words_alone);
}

// With retrieval `auto` a query pairs every place while the caller searches, and the places the
// words retrieve and those near the beliefs while it tracks a fix (set_beliefs, tracking): each
// answer of the bundled log is that of a localizer of retrieval exact, or words, with the same
// beliefs (place id, candidates, consensus, pose). The first third of the log, every second scan.
TEST(GlobalLocalizer, WithRetrievalAutoATrackingQueryIsAnsweredByTheWordsASearchingOneByAll) {
  const Bundled& b = BundledLog();
  const auto answers = [&](PlaceRecognitionConfig::Retrieval retrieval, bool tracking) {
    LocalizerConfig config;
    config.query_every_m = 0.0;
    config.place.retrieval = retrieval;
    config.place.retrieval_places = 5;
    GlobalLocalizer localizer(b.map, config);
    localizer.set_exclusion([](const Place& place, const std::vector<int>& query_scans) {
      return IsSelfMatch(SelfMatchRule::kSameScans, SortedScans(query_scans), place.scan_indices);
    });
    localizer.set_beliefs({Pose2(0.5, -0.5, 0.02)}, tracking);
    std::vector<std::vector<double>> fields;
    for (std::size_t k = 0; k < b.inputs.log.scans.size() / 3; k += 2) {
      const std::optional<LocalizationResult> answer = localizer.AddScan(
          b.inputs.log.scans[k], b.inputs.poses[k], b.inputs.keypoints[k], static_cast<int>(k));
      if (!answer) continue;
      const PlaceMatch& m = answer->match;
      fields.push_back({static_cast<double>(m.place_id), static_cast<double>(m.candidates),
                        static_cast<double>(m.consensus), m.estimated_pose.x, m.estimated_pose.y,
                        m.estimated_pose.theta});
    }
    return fields;
  };
  using Retrieval = PlaceRecognitionConfig::Retrieval;
  const auto tracking = answers(Retrieval::kAuto, true);
  const auto searching = answers(Retrieval::kAuto, false);
  ASSERT_GT(tracking.size(), 30u) << tracking.size();
  EXPECT_EQ(tracking, answers(Retrieval::kWords, true));
  EXPECT_EQ(searching, answers(Retrieval::kExact, false));
  EXPECT_NE(tracking, searching);
  // An exact localizer pairs every place whether it tracks or not.
  EXPECT_EQ(answers(Retrieval::kExact, true), searching);
}

std::size_t ResidentKiB() {
  std::ifstream statm("/proc/self/statm");
  std::size_t size_pages = 0;
  std::size_t resident_pages = 0;
  statm >> size_pages >> resident_pages;
  return resident_pages * static_cast<std::size_t>(sysconf(_SC_PAGESIZE)) / 1024;
}

TEST(GlobalLocalizer, MemoryStaysFlatOverAnEndlessStream) {
  const Bundled& b = BundledLog();
  // A small map (the submaps of the first 300 scans) keeps each recognition cheap; the stream is
  // the next 500 scans, driven again and again: a stream that never ends.
  GlobalMap map = b.map;
  map.submaps.erase(std::remove_if(map.submaps.begin(), map.submaps.end(),
                                   [](const Submap& s) { return s.last_scan() >= 300; }),
                    map.submaps.end());
  ASSERT_GT(map.submaps.size(), 20u);
  GlobalLocalizer localizer(map);
  // A bound the query can never exceed: the map's forced closure (max_scans_per_submap).
  const std::size_t bound = static_cast<std::size_t>(map.config.max_scans_per_submap);
  std::size_t answers = 0;
  std::size_t max_buffered = 0;
  std::size_t resident_after_warmup = 0;
  // Under ASan the resident size is not measured (below): two passes check the bound and leaks.
  const int passes = testing::kAddressSanitizer ? 2 : 8;
  for (int pass = 0; pass < passes; ++pass) {
    for (std::size_t k = 300; k < 800; ++k) {
      if (localizer.AddScan(b.inputs.log.scans[k], b.inputs.poses[k], b.inputs.keypoints[k])) {
        ++answers;
      }
      max_buffered = std::max(max_buffered, localizer.buffered_scans());
    }
    if (pass == 1) resident_after_warmup = ResidentKiB();
  }
  EXPECT_LE(max_buffered, bound);
  EXPECT_GT(answers, static_cast<std::size_t>(passes) * 10);
  // Keeping every scan would add ~50 MB over these 4000 scans (ranges, keypoints, descriptors).
  // ASan keeps freed blocks resident in its quarantine (up to 256 MiB) rather than reusing them,
  // so there the resident size measures the quarantine; LeakSanitizer checks for leaks instead.
  if (!testing::kAddressSanitizer) {
    EXPECT_LT(ResidentKiB(), resident_after_warmup + 4096)
        << "resident memory grew from " << resident_after_warmup << " KiB";
  }
}

TEST(GlobalLocalizer, LocalizeNowAnswersFromAnIncompleteQueryAndResetForgetsIt) {
  const Bundled& b = BundledLog();
  GlobalLocalizer localizer(b.map);
  EXPECT_FALSE(localizer.LocalizeNow().has_value());
  for (std::size_t k = 100; k < 104; ++k) {
    ASSERT_FALSE(
        localizer.AddScan(b.inputs.log.scans[k], b.inputs.poses[k], b.inputs.keypoints[k]));
  }
  const std::optional<LocalizationResult> now = localizer.LocalizeNow();
  ASSERT_TRUE(now.has_value());
  EXPECT_EQ(now->scans, 4u);
  EXPECT_EQ(localizer.buffered_scans(), 4u);  // answering now does not end the query
  localizer.Reset();
  EXPECT_EQ(localizer.buffered_scans(), 0u);
  EXPECT_FALSE(localizer.LocalizeNow().has_value());
}

TEST(Relocalizer, ACopySharesTheRecognizerAndKeepsItsOwnQueryAndFix) {
  const Bundled& b = BundledLog();
  Relocalizer original(b.map);
  for (std::size_t k = 100; k < 104; ++k) {
    original.AddScan(b.inputs.log.scans[k], b.inputs.poses[k], b.inputs.keypoints[k]);
  }
  Relocalizer copy = original;  // what RunRelocalization gives each worker
  EXPECT_EQ(&copy.localizer().recognizer(), &original.localizer().recognizer());  // no rebuild
  EXPECT_EQ(copy.localizer().buffered_scans(), 4u);
  copy.Reset();
  EXPECT_EQ(copy.localizer().buffered_scans(), 0u);
  EXPECT_EQ(original.localizer().buffered_scans(), 4u);
  // Fed the same scans, the copy and the original give the same answers.
  original.Reset();
  int answers = 0;
  for (std::size_t k = 300; k < 600; ++k) {
    const RelocalizationUpdate a =
        original.AddScan(b.inputs.log.scans[k], b.inputs.poses[k], b.inputs.keypoints[k]);
    const RelocalizationUpdate c =
        copy.AddScan(b.inputs.log.scans[k], b.inputs.poses[k], b.inputs.keypoints[k]);
    ASSERT_EQ(a.answer.has_value(), c.answer.has_value()) << k;
    EXPECT_EQ(a.status, c.status) << k;
    if (!a.answer) continue;
    ++answers;
    EXPECT_EQ(a.answer->submap_id, c.answer->submap_id) << k;
    EXPECT_EQ(a.answer->confidence, c.answer->confidence) << k;
  }
  EXPECT_GT(answers, 3);
  EXPECT_EQ(original.status(), FixStatus::kFixed);
}

TEST(GlobalLocalizer, MaxQueryScansClosesAQueryThatNeverCompletes) {
  const Bundled& b = BundledLog();
  LocalizerConfig config;
  config.max_query_scans = 3;
  GlobalLocalizer localizer(b.map, config);
  std::optional<LocalizationResult> result;
  for (std::size_t k = 200; k < 203; ++k) {
    result = localizer.AddScan(b.inputs.log.scans[k], b.inputs.poses[k], b.inputs.keypoints[k]);
  }
  ASSERT_TRUE(result.has_value());
  EXPECT_EQ(result->scans, 3u);
  EXPECT_EQ(localizer.buffered_scans(), 0u);
  config.max_query_scans = 0;
  EXPECT_THROW(GlobalLocalizer(b.map, config), std::invalid_argument);
}

// query_every_m: the query as it stands answers every time the robot has travelled that far
// (or half the query's path at its last answer, when longer), growing until it completes; its
// answers share an id, the next query's differ. Off, only complete queries answer.
TEST(GlobalLocalizer, QueryEveryMetreAnswersBeforeTheQueryCompletes) {
  const Bundled& b = BundledLog();
  LocalizerConfig config;
  config.query_every_m = 1.0;
  GlobalLocalizer every_metre(b.map, config);
  config.query_every_m = 0.0;
  GlobalLocalizer complete_only(b.map, config);
  std::vector<LocalizationResult> answers;
  std::vector<std::size_t> complete_sizes;
  double path_m = 0.0;
  double query_start_m = 0.0;  // path at the query's first scan
  bool query_starts = true;
  std::vector<double> answer_paths_m;
  std::vector<double> query_paths_m;  // the query's own path at each answer
  for (std::size_t k = 100; k < 260; ++k) {
    if (k > 100) path_m += TranslationNorm(Between(b.inputs.poses[k - 1], b.inputs.poses[k]));
    if (query_starts) query_start_m = path_m;
    const auto& scan = b.inputs.log.scans[k];
    auto answer = every_metre.AddScan(scan, b.inputs.poses[k], b.inputs.keypoints[k]);
    query_starts = every_metre.buffered_scans() == 0;
    if (answer) {
      answers.push_back(*answer);
      answer_paths_m.push_back(path_m);
      query_paths_m.push_back(path_m - query_start_m);
    }
    if (auto complete = complete_only.AddScan(scan, b.inputs.poses[k], b.inputs.keypoints[k])) {
      complete_sizes.push_back(complete->scans);
    }
  }
  ASSERT_GE(complete_sizes.size(), 2u);
  ASSERT_GT(answers.size(), complete_sizes.size());
  // Every complete query is among the answers, with the answers before it growing within it.
  std::size_t completed = 0;
  int spaced_by_length = 0;
  for (std::size_t i = 0; i < answers.size(); ++i) {
    const bool last_of_query =
        i + 1 == answers.size() || answers[i + 1].query_id != answers[i].query_id;
    // A query's later answers pair only the descriptors its earlier ones did not (PairMemo); its
    // first pairs them all (or none, with fewer keypoints than mu: -1).
    const bool first_of_query = i == 0 || answers[i].query_id != answers[i - 1].query_id;
    if (first_of_query) {
      EXPECT_LE(answers[i].match.descriptors_remembered, 0) << i;
    } else {
      EXPECT_GT(answers[i].match.descriptors_remembered, 0) << i;
    }
    if (i > 0 && answers[i].query_id == answers[i - 1].query_id) {
      EXPECT_GT(answers[i].scans, answers[i - 1].scans) << i;
      // Answers before completion come a metre apart, or half the query's path at the last
      // answer when that is longer; completion answers at once.
      if (!last_of_query) {
        const double gap_m = std::max(1.0, 0.5 * query_paths_m[i - 1]);
        EXPECT_GE(answer_paths_m[i] - answer_paths_m[i - 1], gap_m - 1e-9) << i;
        EXPECT_LT(answer_paths_m[i] - answer_paths_m[i - 1], gap_m + 1.0) << i;
        if (gap_m > 1.0) ++spaced_by_length;
      }
    }
    if (last_of_query && completed < complete_sizes.size() && i + 1 < answers.size()) {
      EXPECT_EQ(answers[i].scans, complete_sizes[completed]) << i;
      EXPECT_GT(answers[i + 1].query_id, answers[i].query_id) << i;
      ++completed;
    }
  }
  EXPECT_GE(completed, 1u);
  EXPECT_GT(spaced_by_length, 0);
  config.query_every_m = -1.0;
  EXPECT_THROW(GlobalLocalizer(b.map, config), std::invalid_argument);
}

TEST(GlobalLocalizer, LocalizeScanFindsASingleScanAmongScanPlaces) {
  const Bundled& b = BundledLog();
  // Every 5th scan is a place; a scan between two places must be localized next to them.
  std::vector<Place> places;
  for (std::size_t k = 0; k < b.inputs.log.scans.size(); k += 5) {
    Place place;
    place.id = static_cast<int>(k);
    place.T_world_place = b.inputs.poses[k];
    for (const Keypoint& keypoint : b.inputs.keypoints[k]) {
      place.positions.push_back(b.inputs.log.scans[k].T_robot_laser * keypoint.position_m);
      place.descriptors.push_back(keypoint.descriptor);
    }
    place.scan_indices = {static_cast<int>(k)};
    places.push_back(std::move(place));
  }
  PlaceRecognitionConfig config;
  config.min_gamma = 0.0;
  const PlaceRecognizer recognizer(std::move(places), config);
  const std::size_t query = 502;
  const LocalizationResult result =
      LocalizeScan(recognizer, b.inputs.log.scans[query], b.inputs.keypoints[query]);
  ASSERT_TRUE(result.match.verified);
  EXPECT_TRUE(IsCorrectPose(result.T_world_robot, b.inputs.poses[query]));
  EXPECT_EQ(result.scans, 1u);
}

// The query carries the beams of its last kDenseQueryScans scans for the dense check, thinned to
// kDenseBeamsPerScan, in the query frame (the first scan's pose).
TEST(SubmapQueryBuilder, QueryCarriesTheLatestScansBeamsInItsFrame) {
  std::vector<double> ranges(361, 4.0);
  std::vector<double> angles;
  for (int k = 0; k < 361; ++k) angles.push_back(-M_PI / 2 + k * M_PI / 360);
  ranges[7] = 100.0;  // beyond max range: not a beam
  const LaserScan scan = MakeLaserScan(ranges, angles, 80.0, 0.0, Pose2(0.2, 0.0, 0.0));
  MappingConfig mapping;
  mapping.max_scans_per_submap = 1000;
  SubmapQueryBuilder builder(mapping);
  for (int k = 0; k < 14; ++k) builder.AddScan(scan, Pose2(0.1 * k, 0.0, 0.05 * k), {}, k);
  const PlaceQuery query = builder.Query(12, PlaceRecognitionConfig::QueryKeypoints::kAllScans);
  ASSERT_EQ(query.scans.size(), kDenseQueryScans);  // scans 3..12
  for (const QueryScanPoints& points : query.scans) {
    EXPECT_LE(points.endpoints_m.size(), kDenseBeamsPerScan);
    EXPECT_GE(points.endpoints_m.size(), kDenseBeamsPerScan / 2);
  }
  // Scan 12's laser sits at T_query_robot * (0.2, 0) and every endpoint 4 m from it.
  const Pose2 T_query_robot = Between(Pose2(0.0, 0.0, 0.0), Pose2(1.2, 0.0, 0.6));
  const Eigen::Vector2d laser = T_query_robot * Eigen::Vector2d(0.2, 0.0);
  EXPECT_NEAR((query.scans.back().origin_m - laser).norm(), 0.0, 1e-12);
  for (const Eigen::Vector2d& endpoint : query.scans.back().endpoints_m) {
    EXPECT_NEAR((endpoint - laser).norm(), 4.0, 1e-9);
  }
}

}  // namespace
}  // namespace keyplace
