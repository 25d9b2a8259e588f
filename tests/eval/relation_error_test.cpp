#include "keyplace/eval/relation_error.hpp"

#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace keyplace {
namespace {

std::vector<TimedPose> Trajectory(const std::vector<Pose2>& poses, double t0, double dt) {
  std::vector<TimedPose> out;
  for (std::size_t i = 0; i < poses.size(); ++i) out.push_back({t0 + dt * i, poses[i]});
  return out;
}

TEST(RelationErrorTest, PerfectTrajectoryHasZeroErrorInAnyFrame) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  std::vector<Pose2> truth;
  for (int i = 0; i < 50; ++i) truth.emplace_back(u(rng), u(rng), u(rng));
  std::vector<Relation> relations;
  for (int k = 0; k < 100; ++k) {
    const int a = static_cast<int>(rng() % 50);
    const int b = static_cast<int>(rng() % 50);
    relations.push_back({1000.0 + 0.5 * a, 1000.0 + 0.5 * b, Between(truth[a], truth[b]), 0});
  }
  // The same trajectory expressed in another world frame.
  const Pose2 T_other_world(5.0, -2.0, 1.0);
  std::vector<Pose2> moved;
  for (const Pose2& p : truth) moved.push_back(T_other_world * p);
  const RelationErrorReport report = EvaluateRelations(Trajectory(moved, 1000.0, 0.5), relations);
  EXPECT_EQ(report.matched, 100u);
  EXPECT_EQ(report.unmatched, 0u);
  EXPECT_NEAR(report.all.translation_mean_m, 0.0, 1e-9);
  EXPECT_NEAR(report.all.rotation_mean_deg, 0.0, 1e-7);
  EXPECT_EQ(report.local.count + report.loop.count, 100u);
}

TEST(RelationErrorTest, KnownErrorsAndLocalLoopSplit) {
  // Three poses on a line; the estimate of pose 2 is 0.3 m too far and turned by 10 deg.
  const std::vector<Pose2> truth = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  std::vector<Pose2> estimate = truth;
  estimate[2] = Pose2(2.3, 0.0, 10.0 * M_PI / 180.0);
  const std::vector<TimedPose> trajectory = {
      {100.0, estimate[0]}, {102.0, estimate[1]}, {110.0, estimate[2]}};
  const std::vector<Relation> relations = {
      {100.0, 102.0, Between(truth[0], truth[1]), 1},  // local (2 s), exact
      {102.0, 110.0, Between(truth[1], truth[2]), 2},  // loop (8 s)
      {110.0, 100.0, Between(truth[2], truth[0]), 3},  // loop, reversed
      {100.0, 999.0, Pose2(), 4},                      // after the last scan
  };
  const RelationErrorReport report = EvaluateRelations(trajectory, relations);
  EXPECT_EQ(report.relations, 4u);
  EXPECT_EQ(report.matched, 3u);
  EXPECT_EQ(report.unmatched, 0u);
  EXPECT_EQ(report.outside_span, 1u);
  EXPECT_EQ(report.local.count, 1u);
  EXPECT_EQ(report.loop.count, 2u);
  EXPECT_NEAR(report.local.translation_mean_m, 0.0, 1e-12);
  // Relation 2: |t - t*| = 0.3 m, rotation 10 deg.
  EXPECT_NEAR(report.items[1].error.translation_m, 0.3, 1e-12);
  EXPECT_NEAR(report.items[1].error.rotation_deg, 10.0, 1e-9);
  // Relation 3 (2 -> 0): estimated delta = est2^-1 * est0; true = (-2, 0, 0).
  const Pose2 estimated = Between(estimate[2], estimate[0]);
  EXPECT_NEAR(report.items[2].error.translation_m, std::hypot(estimated.x + 2.0, estimated.y),
              1e-12);
  EXPECT_NEAR(report.loop.rotation_mean_deg, 10.0, 1e-9);
  EXPECT_NEAR(report.loop.rotation_std_deg, 0.0, 1e-9);
  const double t2 = report.items[2].error.translation_m;
  EXPECT_NEAR(report.loop.translation_mean_m, (0.3 + t2) / 2.0, 1e-12);
  EXPECT_NEAR(report.loop.translation_std_m, std::abs(0.3 - t2) / 2.0, 1e-12);  // population
  EXPECT_NEAR(report.all.translation_mean_m, (0.3 + t2) / 3.0, 1e-12);

  RelationErrorConfig wide;
  wide.local_max_dt_s = 100.0;
  EXPECT_EQ(EvaluateRelations(trajectory, relations, wide).local.count, 3u);
  RelationErrorConfig bad;
  bad.local_max_dt_s = -1.0;
  EXPECT_THROW(EvaluateRelations(trajectory, relations, bad), std::invalid_argument);
}

TEST(RelationErrorTest, ToleranceNearestStampAndDuplicates) {
  const std::vector<TimedPose> trajectory = {{976052858.40413, Pose2(0, 0, 0)},
                                             {976052858.404131, Pose2(1, 0, 0)},
                                             {976052858.40413, Pose2(5, 0, 0)},  // repeated stamp
                                             {976052858.50413, Pose2(2, 0, 0)}};
  const std::vector<Relation> relations = {
      {976052858.404130, 976052858.404131, Pose2(1, 0, 0), 1},
      {976052858.404132, 976052858.504180, Pose2(1, 0, 0), 2},  // 1 us and 50 us away
      {976052858.404130, 976052858.454130, Pose2(), 3}};        // 50 ms from any stamp
  RelationErrorConfig exact;
  exact.stamp_tolerance_s = 0.0;
  exact.min_matched_fraction = 0.0;
  const RelationErrorReport exact_report = EvaluateRelations(trajectory, relations, exact);
  EXPECT_EQ(exact_report.duplicate_timestamps, 1u);
  EXPECT_EQ(exact_report.matched, 1u);  // only equal values match at tolerance 0
  EXPECT_NEAR(exact_report.all.translation_mean_m, 0.0, 1e-12);  // the first pose of a stamp

  RelationErrorConfig tolerant;  // 0.1 ms
  tolerant.min_matched_fraction = 0.0;
  const RelationErrorReport report = EvaluateRelations(trajectory, relations, tolerant);
  EXPECT_EQ(report.matched, 2u);
  EXPECT_EQ(report.unmatched, 1u);
  EXPECT_EQ(report.outside_span, 0u);
  // Relation 2: a -> the pose at ...404131 (1 us, nearer than ...40413), b -> the last pose.
  EXPECT_NEAR(report.items[1].error.translation_m, 0.0, 1e-12);
}

// A log's stamps with 6 decimals, and relation files written with 6 and with 5 decimals.
TEST(RelationErrorTest, FiveAndSixDecimalRelationStampsBothMatchTheLog) {
  std::vector<TimedPose> trajectory;
  for (int i = 0; i < 200; ++i) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.6f", 1234.567891 + 0.0266617 * i);
    trajectory.push_back({std::stod(text), Pose2(0.1 * i, 0.02 * i, 0.01 * i)});
  }
  for (const char* format : {"%.6f", "%.5f"}) {
    std::vector<Relation> relations;
    for (int i = 0; i + 7 < 200; i += 3) {
      char a[32];
      char b[32];
      std::snprintf(a, sizeof(a), format, trajectory[i].timestamp_s);
      std::snprintf(b, sizeof(b), format, trajectory[i + 7].timestamp_s);
      relations.push_back(
          {std::stod(a), std::stod(b), Between(trajectory[i].pose, trajectory[i + 7].pose), 0});
    }
    const RelationErrorReport report = EvaluateRelations(trajectory, relations);
    EXPECT_EQ(report.matched, relations.size()) << format;
    EXPECT_TRUE(report.refusal.empty()) << format << ": " << report.refusal;
    EXPECT_NEAR(report.all.translation_mean_m, 0.0, 1e-9) << format;
  }
}

TEST(RelationErrorTest, TooFewMatchesAreRefusedRelationsOutsideTheLogAreNot) {
  std::vector<TimedPose> trajectory;
  trajectory.reserve(100);
  for (int i = 0; i < 100; ++i) trajectory.push_back({100.0 + 0.2 * i, Pose2(0.1 * i, 0, 0)});
  std::vector<Relation> relations;
  for (int i = 0; i + 1 < 100; ++i) {               // 99 inside the span, 5 of them on the stamps
    const double shift = i % 20 == 0 ? 0.0 : 0.05;  // 50 ms off: another log's scans
    relations.push_back({100.0 + 0.2 * i + shift, 100.2 + 0.2 * i + shift, Pose2(0.1, 0, 0), 0});
  }
  const RelationErrorReport refused = EvaluateRelations(trajectory, relations);
  EXPECT_EQ(refused.matched, 5u);
  EXPECT_EQ(refused.unmatched, 93u);
  EXPECT_EQ(refused.outside_span, 1u);
  EXPECT_NE(refused.refusal.find("only 5 of the 98 relations"), std::string::npos)
      << refused.refusal;
  EXPECT_NE(refused.refusal.find("within 0.1 ms, below 95 %"), std::string::npos)
      << refused.refusal;

  // A relation file of the whole log against a slice of it: the relations beyond the slice are
  // not held against it.
  std::vector<Relation> whole;
  for (int i = 0; i + 1 < 100; ++i) {
    whole.push_back({100.0 + 0.2 * i, 100.2 + 0.2 * i, Pose2(0.1, 0, 0), 0});
  }
  whole.push_back({90.0, 100.0, Pose2(), 0});
  whole.push_back({119.8, 130.0, Pose2(), 0});
  const RelationErrorReport slice = EvaluateRelations(trajectory, whole);
  EXPECT_EQ(slice.matched, 99u);
  EXPECT_EQ(slice.outside_span, 2u);
  EXPECT_TRUE(slice.refusal.empty()) << slice.refusal;
  EXPECT_NE(EvaluateRelations(trajectory, {}).refusal.find("no relation"), std::string::npos);
  EXPECT_NE(EvaluateRelations(trajectory, {{5.0, 6.0, Pose2(), 0}}).refusal.find("another log"),
            std::string::npos);
}

TEST(RelationErrorTest, DriftAgainstCorrectedPoses) {
  // Corrected: a square path. Raw estimate: the same path in another frame, with 2 raw scans
  // per corrected scan; the last corrected scan's estimate is 0.5 m off.
  std::vector<Pose2> corrected;
  for (int i = 0; i < 20; ++i) corrected.emplace_back(0.2 * i, 0.1 * (i % 3), 0.05 * i);
  const Pose2 T_raw_corrected(3.0, 1.0, 0.7);
  std::vector<Pose2> raw(40);
  std::vector<IndexPair> pairs;
  for (int i = 0; i < 20; ++i) {
    raw[2 * i + 1] = T_raw_corrected * corrected[i];
    pairs.push_back({static_cast<std::size_t>(2 * i + 1), static_cast<std::size_t>(i)});
  }
  const DriftReport exact = EvaluateDrift(raw, corrected, pairs);
  EXPECT_EQ(exact.pairs, 20u);
  EXPECT_EQ(exact.consecutive.count, 19u);
  EXPECT_NEAR(exact.consecutive.translation_mean_m, 0.0, 1e-9);
  EXPECT_NEAR(exact.ate_rmse_m, 0.0, 1e-9);
  EXPECT_NEAR(exact.ate_rotation_rmse_deg, 0.0, 1e-7);
  ASSERT_TRUE(exact.window_heading_max_deg.has_value());
  EXPECT_NEAR(*exact.window_heading_max_deg, 0.0, 1e-7);
  // Five steps need six pairs.
  const std::vector<IndexPair> five(pairs.begin(), pairs.begin() + 5);
  EXPECT_FALSE(EvaluateDrift(raw, corrected, five).window_heading_max_deg.has_value());
  const Pose2 T_corrected_raw = T_raw_corrected.inverse();
  EXPECT_NEAR(exact.T_corrected_estimate.theta, T_corrected_raw.theta, 1e-9);
  EXPECT_NEAR(exact.T_corrected_estimate.x, T_corrected_raw.x, 1e-9);

  raw[39] = raw[39] * Pose2(0.5, 0.0, 0.0);
  const DriftReport off = EvaluateDrift(raw, corrected, pairs);
  EXPECT_NEAR(off.consecutive.translation_max_m, 0.5, 1e-9);
  EXPECT_GT(off.ate_rmse_m, 0.05);
  EXPECT_LT(off.ate_max_m, 0.5);  // the alignment spreads the error

  // A heading slip of 30 deg at raw scan 21 that the later scans keep: every window across it
  // sees it: windows starting at raw 11..19 (pairs 5..9) end after it.
  std::vector<Pose2> slipped = raw;
  const Pose2 slipped_21 = raw[21] * Pose2(0.0, 0.0, 0.5236);
  for (std::size_t i = 21; i < slipped.size(); ++i) {
    slipped[i] = slipped_21 * Between(raw[21], raw[i]);
  }
  const DriftReport slip = EvaluateDrift(slipped, corrected, pairs);
  ASSERT_TRUE(slip.window_heading_max_deg.has_value());
  EXPECT_NEAR(*slip.window_heading_max_deg, 30.0, 0.01);
  EXPECT_GE(slip.window_start_raw_index, 11u);
  EXPECT_LE(slip.window_start_raw_index, 19u);

  pairs.push_back({40, 0});
  EXPECT_THROW(EvaluateDrift(raw, corrected, pairs), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
