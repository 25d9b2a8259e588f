// The honest protocols of keyplace localize (issue 14): file-absolute truth indices, whether the
// queries meet the map's own log (TruthIsMapLog), revisitable queries and the reliability diagram
// of the confidence, on hand-made cases.

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "io/file_fingerprint.hpp"
#include "keyplace/eval/global_localization.hpp"
#include "keyplace/eval/ground_truth.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

double Deg(double degrees) { return degrees * M_PI / 180.0; }

// A corrected log of `n` scans at x = 0, 1, 2, ... (in memory, no file).
CarmenLog StraightLog(std::size_t n) {
  CarmenLog log;
  log.path = "/data/monday.log";
  log.corrected = true;
  for (std::size_t k = 0; k < n; ++k) {
    LogScan scan;
    scan.corrected_pose = Pose2(static_cast<double>(k), 0.0, 0.0);
    scan.line = k + 1;
    log.scans.push_back(scan);
  }
  return log;
}

TEST(GroundTruth, OwnPosesOfACutLogNameScansOfTheFile) {
  const CarmenLog log = StraightLog(5);  // scans 700..704 of the file
  const GroundTruth truth = TruthFromOwnPoses(log, 700, "crc32:0000abcd:123");
  EXPECT_EQ(truth.truth_log_hash, "crc32:0000abcd:123");
  ASSERT_EQ(truth.Count(), 5u);
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_EQ(truth.TruthScan(k), static_cast<int>(700 + k));
    EXPECT_EQ(truth.Pose(k).x, static_cast<double>(k));  // the pose of the cut log's scan k
  }
  // No cut: the scan's own index.
  EXPECT_EQ(TruthFromOwnPoses(log, 0, "crc32:0000abcd:123").TruthScan(3), 3);
  // A log without a file has no fingerprint; one whose file is gone is an error naming it.
  CarmenLog in_memory = log;
  in_memory.path.clear();
  EXPECT_TRUE(TruthFromOwnPoses(in_memory).truth_log_hash.empty());
  EXPECT_THROW(TruthFromOwnPoses(log), std::runtime_error);
}

TEST(GroundTruth, HashOfTheLogFileAndQueryIndicesOfACut) {
  const std::string path = testing::SourceDir() + "/data/fr079-corrected.log.gz";
  LogInputOptions options;
  options.first_scan = 300;
  options.end_scan = 340;
  options.keypoints = false;
  const LogInputs inputs = PrepareLogInputs(path, options);
  // Computed from the path when not given, equal to what the map records.
  const GroundTruth truth = TruthFromOwnPoses(inputs.log, inputs.first_scan);
  EXPECT_EQ(truth.truth_log_hash, FileFingerprint(path));
  EXPECT_EQ(truth.truth_log_hash, inputs.source_hash);
  EXPECT_EQ(truth.TruthScan(0), 300);
  EXPECT_EQ(truth.TruthScan(39), 339);
  const GroundTruth loaded =
      LoadGroundTruth(inputs.log, inputs.first_scan, inputs.file_scans, "", "", "crc32:1:2");
  EXPECT_EQ(loaded.truth_log_hash, "crc32:1:2");
  EXPECT_EQ(loaded.TruthScan(10), 310);
  // The query starts are positions in the cut log; their truth scans are file scans.
  const std::vector<int> starts = QueryStarts(truth, 4);
  EXPECT_EQ(starts, (std::vector<int>{0, 10, 20, 30}));
  // More queries than scans with a truth pose: every scan once, none repeated.
  std::vector<int> all(40);
  for (int k = 0; k < 40; ++k) all[static_cast<std::size_t>(k)] = k;
  EXPECT_EQ(QueryStarts(truth, 500), all);
}

TEST(TruthIsMapLog, ByFingerprintElseByFileName) {
  GlobalMap map;
  map.source_log = "fr079-corrected.log.gz";
  map.source_hash = "crc32:11111111:500";
  GroundTruth truth;
  truth.truth_log = "/somewhere/else/fr079-corrected.log.gz";
  truth.truth_log_hash = "crc32:11111111:500";
  EXPECT_TRUE(TruthIsMapLog(map, truth));

  // Same name, other contents (Tuesday's run saved under Monday's name): another recording.
  truth.truth_log_hash = "crc32:22222222:500";
  EXPECT_FALSE(TruthIsMapLog(map, truth));
  // Renamed copy of the same file: the same log.
  truth.truth_log = "/tmp/copy.log.gz";
  truth.truth_log_hash = map.source_hash;
  EXPECT_TRUE(TruthIsMapLog(map, truth));

  // A map from before fingerprints were recorded: the file names decide.
  map.source_hash.clear();
  truth.truth_log = "/data/fr079-corrected.log.gz";
  truth.truth_log_hash = "crc32:22222222:500";
  EXPECT_TRUE(TruthIsMapLog(map, truth));
  truth.truth_log = "/data/intel-corrected.log.gz";
  EXPECT_FALSE(TruthIsMapLog(map, truth));
}

Submap MapSubmap(int id, std::vector<int> scans, std::vector<Pose2> poses) {
  Submap submap;
  submap.id = id;
  submap.scan_indices = std::move(scans);
  submap.poses = std::move(poses);
  return submap;
}

LocalizationQuery QueryAt(Pose2 truth, std::vector<int> truth_scans) {
  LocalizationQuery query;
  query.truth = truth;
  query.truth_scans = std::move(truth_scans);
  return query;
}

// Two submaps: A (scans 10, 11) at x = 0 and 1, B (scans 20, 21) at x = 10 and 11.
std::vector<Submap> TwoSubmaps() {
  return {MapSubmap(0, {10, 11}, {Pose2(0, 0, 0), Pose2(1, 0, 0)}),
          MapSubmap(1, {20, 21}, {Pose2(10, 0, 0), Pose2(11, 0, 0)})};
}

TEST(Revisitable, NearFarAndNearOnlyAnExcludedScan) {
  const std::vector<Submap> map = TwoSubmaps();
  const EvaluationConfig config;  // 1.5 m, 45 deg
  const LocalizationQuery near = QueryAt(Pose2(1.2, 0.3, Deg(20)), {50, 51});
  const LocalizationQuery far = QueryAt(Pose2(5.0, 5.0, 0.0), {60, 61});
  // Near B only, and built from B's own scans: B is its self-match under the paper's rule.
  const LocalizationQuery self = QueryAt(Pose2(10.5, 0.2, 0.0), {20, 21});
  for (const SelfMatchRule rule :
       {SelfMatchRule::kNone, SelfMatchRule::kSameScans, SelfMatchRule::kSharedScan}) {
    EXPECT_TRUE(IsRevisitable(near, map, rule, config));
    EXPECT_FALSE(IsRevisitable(far, map, rule, config));
  }
  EXPECT_FALSE(IsRevisitable(self, map, SelfMatchRule::kSameScans, config));
  EXPECT_FALSE(IsRevisitable(self, map, SelfMatchRule::kSharedScan, config));
  // Another recording (kNone): B's scans are other scans, B counts.
  EXPECT_TRUE(IsRevisitable(self, map, SelfMatchRule::kNone, config));
  // Sharing one scan with B: excluded only by the shared-scan rule.
  const LocalizationQuery shared = QueryAt(Pose2(10.5, 0.2, 0.0), {21, 22});
  EXPECT_TRUE(IsRevisitable(shared, map, SelfMatchRule::kSameScans, config));
  EXPECT_FALSE(IsRevisitable(shared, map, SelfMatchRule::kSharedScan, config));

  std::vector<LocalizationRecord> records(3);
  MarkRevisitable({near, far, self}, map, SelfMatchRule::kSameScans, config, records);
  EXPECT_TRUE(records[0].revisitable);
  EXPECT_FALSE(records[1].revisitable);
  EXPECT_FALSE(records[2].revisitable);
  std::vector<LocalizationRecord> too_few(2);
  EXPECT_THROW(MarkRevisitable({near, far, self}, map, SelfMatchRule::kSameScans, config, too_few),
               std::invalid_argument);
}

TEST(Revisitable, DistanceAndHeadingLimits) {
  const std::vector<Submap> map = {MapSubmap(0, {1}, {Pose2(0, 0, M_PI - 0.1)})};
  EvaluationConfig config;
  const auto at = [&](double x, double y, double theta) {
    return IsRevisitable(QueryAt(Pose2(x, y, theta), {7}), map, SelfMatchRule::kSameScans, config);
  };
  EXPECT_TRUE(at(0.0, 1.5, M_PI - 0.1));    // 1.5 m exactly
  EXPECT_FALSE(at(0.0, 1.51, M_PI - 0.1));  // just beyond
  EXPECT_TRUE(at(0, 0, -M_PI + 0.1));       // 0.2 rad across the wrap
  EXPECT_TRUE(at(0, 0, M_PI - 0.1 - Deg(44)));
  EXPECT_FALSE(at(0, 0, M_PI - 0.1 - Deg(46)));  // the other way round the corner
  config.revisit_angle_deg = 50.0;
  EXPECT_TRUE(at(0, 0, M_PI - 0.1 - Deg(46)));
  config.revisit_radius_m = 0.5;
  EXPECT_FALSE(at(0.0, 1.5, M_PI - 0.1));
}

TEST(Revisitable, SingleScanPlacesAsSubmaps) {
  Place a;
  a.id = 705;
  a.T_world_place = Pose2(2, 3, 0.5);
  a.scan_indices = {705};
  const std::vector<Submap> submaps = ScanPlacesAsSubmaps({a});
  ASSERT_EQ(submaps.size(), 1u);
  EXPECT_EQ(submaps[0].scan_indices, std::vector<int>{705});
  ASSERT_EQ(submaps[0].poses.size(), 1u);
  EXPECT_EQ(submaps[0].poses[0].y, 3.0);
  EXPECT_TRUE(IsRevisitable(QueryAt(Pose2(2, 3.5, 0.5), {1}), submaps, SelfMatchRule::kSameScans,
                            EvaluationConfig{}));
  EXPECT_FALSE(IsRevisitable(QueryAt(Pose2(2, 3.5, 0.5), {705}), submaps, SelfMatchRule::kSameScans,
                             EvaluationConfig{}));
}

LocalizationRecord Answer(bool found, bool correct, double confidence, bool revisitable = true) {
  LocalizationRecord r;
  r.match.verified = found;
  r.match.found = found;
  r.match.confidence = confidence;
  r.verified_correct = correct;
  r.correct = found && correct;
  r.revisitable = revisitable;
  return r;
}

TEST(Reliability, AcceptedAnswersBinnedByConfidence) {
  const std::vector<LocalizationRecord> records = {
      Answer(true, true, 0.05),  Answer(true, false, 0.15), Answer(true, true, 0.3),
      Answer(true, true, 0.95),  Answer(true, true, 1.0),   Answer(true, false, 0.92),
      Answer(false, false, 0.5),  // not accepted: in no bin
  };
  const std::vector<ReliabilityBin> bins = ReliabilityDiagram(records);
  ASSERT_EQ(bins.size(), 10u);
  for (std::size_t b = 0; b < 10; ++b) {
    EXPECT_DOUBLE_EQ(bins[b].bin_low, 0.1 * static_cast<double>(b)) << b;
    EXPECT_DOUBLE_EQ(bins[b].bin_high, 0.1 * static_cast<double>(b + 1)) << b;
  }
  EXPECT_EQ(bins[0].count, 1u);
  EXPECT_DOUBLE_EQ(bins[0].confidence_mean, 0.05);
  EXPECT_DOUBLE_EQ(bins[0].precision, 1.0);
  EXPECT_EQ(bins[1].count, 1u);
  EXPECT_DOUBLE_EQ(bins[1].precision, 0.0);
  EXPECT_EQ(bins[2].count, 0u);  // 0.3 is the low edge of bin 3, not the top of bin 2
  EXPECT_EQ(bins[3].count, 1u);
  EXPECT_EQ(bins[5].count, 0u);  // the unaccepted 0.5
  EXPECT_DOUBLE_EQ(bins[5].confidence_mean, 0.0);
  EXPECT_DOUBLE_EQ(bins[5].precision, 0.0);
  EXPECT_EQ(bins[9].count, 3u);  // 0.92, 0.95 and 1.0
  EXPECT_NEAR(bins[9].confidence_mean, (0.92 + 0.95 + 1.0) / 3.0, 1e-12);
  EXPECT_DOUBLE_EQ(bins[9].precision, 2.0 / 3.0);
  std::size_t total = 0;
  for (const ReliabilityBin& b : bins) total += b.count;
  EXPECT_EQ(total, 6u);

  const LocalizationSummary s = Summarize(records, RankBy::kConfidence);
  ASSERT_EQ(s.reliability.size(), 10u);
  EXPECT_EQ(s.reliability[9].count, 3u);
}

TEST(Summarize, RecallOverRevisitableQueries) {
  // 6 queries: 4 revisitable (2 answered correctly, 1 wrong, 1 unanswered), 2 not revisitable
  // (one of them answered correctly all the same).
  const std::vector<LocalizationRecord> records = {
      Answer(true, true, 0.9, true),  Answer(true, true, 0.8, true),
      Answer(true, false, 0.7, true), Answer(false, false, 0.0, true),
      Answer(true, true, 0.6, false), Answer(false, false, 0.0, false),
  };
  const LocalizationSummary s = Summarize(records, RankBy::kConfidence);
  EXPECT_EQ(s.n_pos, 6u);
  EXPECT_EQ(s.n_cor, 3u);
  EXPECT_DOUBLE_EQ(s.recall, 0.5);
  EXPECT_EQ(s.n_revisitable, 4u);
  EXPECT_EQ(s.n_cor_revisitable, 2u);
  EXPECT_DOUBLE_EQ(s.recall_revisitable, 0.5);
  // Nothing revisitable: 0, not a division by zero.
  const LocalizationSummary none = Summarize({Answer(true, true, 0.9, false)}, RankBy::kConfidence);
  EXPECT_EQ(none.n_revisitable, 0u);
  EXPECT_DOUBLE_EQ(none.recall_revisitable, 0.0);
}

}  // namespace
}  // namespace keyplace
