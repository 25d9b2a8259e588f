// EvaluateMerge: the error of a merge against the corrected poses, on hand-made maps whose drift
// and transform errors are known.

#include "keyplace/eval/merge_evaluation.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace keyplace {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;

// The true path: scan k at (k, 0) heading along x, for scans 0..19 (both sessions walk it).
Pose2 TruePose(int scan) { return {static_cast<double>(scan), 0.0, 0.0}; }

GroundTruth Truth(int scans, const std::vector<int>& without) {
  GroundTruth truth;
  truth.truth_log = "corrected.log";
  for (int k = 0; k < scans; ++k) {
    bool has = true;
    for (const int w : without) has = has && w != k;
    truth.truth_index_of_scan.push_back(has ? static_cast<int>(truth.truth_poses.size()) : -1);
    if (has) truth.truth_poses.push_back(TruePose(k));
  }
  return truth;
}

// One submap per scan list; the poses are `T_map_world` * (true pose), optionally drifted by a
// heading error that grows by `drift_rad` per scan from the map's first scan (about that scan).
GlobalMap Map(const std::vector<std::vector<int>>& submap_scans, int first_id, double drift_rad) {
  GlobalMap map;
  map.source_log = "raw.log";
  map.source_hash = "crc32:1:2";
  const int first_scan = submap_scans.front().front();
  const Pose2 T_map_world = TruePose(first_scan).inverse();
  int id = first_id;
  for (const std::vector<int>& scans : submap_scans) {
    Submap submap;
    submap.id = id++;
    for (const int scan : scans) {
      // Drift: the path bends by drift_rad per scan (heading and position both follow it).
      Pose2 pose;
      for (int k = first_scan; k < scan; ++k) pose = pose * Pose2(1.0, 0.0, drift_rad);
      submap.scan_indices.push_back(scan);
      submap.poses.push_back(T_map_world * TruePose(first_scan) * pose);
    }
    map.submaps.push_back(submap);
  }
  return map;
}

SubmapRecognition Recognition(int submap_a, int submap_b, const Pose2& T_a_b, bool agrees) {
  SubmapRecognition recognition;
  recognition.submap_a = submap_a;
  recognition.submap_b = submap_b;
  recognition.T_a_b = T_a_b;
  recognition.agrees = agrees;
  return recognition;
}

TEST(MergeEvaluation, TheTrueTransformHasNoErrorAtTheOriginsNorWhereTheMapsMeet) {
  // A: scans 0..9 from scan 0; B: scans 10..19 from scan 10, no drift: B's frame is (10, 0, 0).
  const GlobalMap a = Map({{0, 1, 2}, {3, 4, 5}, {6, 7, 8, 9}}, 0, 0.0);
  const GlobalMap b = Map({{10, 11, 12}, {13, 14}, {15, 16, 17, 18, 19}}, 0, 0.0);
  MergeResult result;
  result.T_a_b = Pose2(10.0, 0.0, 0.0);
  result.recognitions = {Recognition(2, 0, result.T_a_b, true),
                         Recognition(1, 2, Pose2(9.0, 0.0, 0.0), false)};
  const MergeEvaluation evaluation = EvaluateMerge(a, b, result, Truth(20, {}), "crc32:1:2");
  EXPECT_EQ(evaluation.at_origins.scan_a, 0);
  EXPECT_EQ(evaluation.at_origins.scan_b, 10);
  EXPECT_NEAR(evaluation.at_origins.true_T_a_scan_b.x, 10.0, 1e-12);
  EXPECT_NEAR(evaluation.at_origins.error.translation_m, 0.0, 1e-12);
  EXPECT_NEAR(evaluation.at_origins.error.rotation_deg, 0.0, 1e-12);
  // Only the agreeing recognition is evaluated, at the first scans of its submaps.
  ASSERT_EQ(evaluation.at_recognitions.size(), 1U);
  EXPECT_EQ(evaluation.at_recognitions[0].submap_a, 2);
  EXPECT_EQ(evaluation.at_recognitions[0].submap_b, 0);
  EXPECT_EQ(evaluation.at_recognitions[0].scan_a, 6);
  EXPECT_EQ(evaluation.at_recognitions[0].scan_b, 10);
  EXPECT_NEAR(evaluation.at_recognitions_stats.translation_max_m, 0.0, 1e-12);
  EXPECT_EQ(evaluation.at_recognitions_stats.count, 1U);
}

TEST(MergeEvaluation, AWrongTransformIsMeasuredWithItsLeverArm) {
  const GlobalMap a = Map({{0, 1, 2}, {3, 4, 5}}, 0, 0.0);
  const GlobalMap b = Map({{10, 11}, {12, 13}}, 0, 0.0);
  // B's frame 0.2 m off sideways and turned by 2 degrees about B's origin.
  MergeResult result;
  const double turn = 2.0 / kDegPerRad;
  result.T_a_b = Pose2(10.0, 0.2, turn);
  // A recognition of B's submap at scan 12 (2 m from B's origin): its own transform is right.
  result.recognitions = {Recognition(1, 1, Pose2(10.0, 0.0, 0.0), true)};
  const MergeEvaluation evaluation = EvaluateMerge(a, b, result, Truth(20, {}));
  EXPECT_NEAR(evaluation.at_origins.error.translation_m, 0.2, 1e-12);
  EXPECT_NEAR(evaluation.at_origins.error.rotation_deg, 2.0, 1e-9);
  // At scan 12 the turn adds (2 sin(turn), 2 (cos(turn) - 1)) to the sideways 0.2 m.
  ASSERT_EQ(evaluation.at_recognitions.size(), 1U);
  const double dx = 2.0 * (std::cos(turn) - 1.0);
  const double dy = 0.2 + 2.0 * std::sin(turn);
  EXPECT_NEAR(evaluation.at_recognitions[0].error.translation_m, std::hypot(dx, dy), 1e-12);
  EXPECT_NEAR(evaluation.at_recognitions[0].error.rotation_deg, 2.0, 1e-9);
  EXPECT_NEAR(evaluation.at_recognitions[0].recognition_error.translation_m, 0.0, 1e-12);
  EXPECT_NEAR(evaluation.recognitions_alone_stats.rotation_max_deg, 0.0, 1e-9);
}

TEST(MergeEvaluation, DriftSeparatesTheOriginsFromWhereTheMapsMeet) {
  // B drifts: its heading bends by 0.5 degrees per scan. A recognition at scan 18 gives the
  // transform that is right there; at B's origin that transform is off by the drift.
  const double drift = 0.5 / kDegPerRad;
  const GlobalMap a = Map({{0, 1, 2, 3}, {16, 17, 18, 19}}, 0, 0.0);
  const GlobalMap b = Map({{10, 11, 12}, {18, 19}}, 0, drift);
  // Where B's map puts scan 18, and the transform that moves it onto the truth.
  const Pose2 P_b_18 = b.submaps[1].poses[0];
  const Pose2 T_a_b = TruePose(18) * P_b_18.inverse();
  MergeResult result;
  result.T_a_b = T_a_b;
  result.recognitions = {Recognition(1, 1, T_a_b, true)};
  const MergeEvaluation evaluation = EvaluateMerge(a, b, result, Truth(20, {}));
  // Where they meet: exact. At the origins: off by B's drift over 8 scans (4 degrees).
  ASSERT_EQ(evaluation.at_recognitions.size(), 1U);
  EXPECT_NEAR(evaluation.at_recognitions[0].error.translation_m, 0.0, 1e-9);
  EXPECT_NEAR(evaluation.at_origins.error.rotation_deg, 4.0, 1e-9);
  EXPECT_GT(evaluation.at_origins.error.translation_m, 0.1);
  // The truth at the origins does not depend on the estimate: (10, 0, 0).
  EXPECT_NEAR(evaluation.at_origins.true_T_a_scan_b.x, 10.0, 1e-12);
  EXPECT_NEAR(evaluation.at_origins.true_T_a_scan_b.y, 0.0, 1e-12);
}

TEST(MergeEvaluation, ScansWithoutTruthAreSkippedAndCounted) {
  // Scan 0 and 10 (the origins) have no truth: the first scans that do are used, through the
  // maps' own poses of them. B's submap {12, 13} has none at all.
  const GlobalMap a = Map({{0, 1, 2}, {3, 4}}, 0, 0.0);
  const GlobalMap b = Map({{10, 11}, {12, 13}}, 0, 0.0);
  MergeResult result;
  result.T_a_b = Pose2(10.0, 0.0, 0.0);
  result.recognitions = {Recognition(0, 0, result.T_a_b, true),
                         Recognition(1, 1, result.T_a_b, true)};
  const MergeEvaluation evaluation = EvaluateMerge(a, b, result, Truth(20, {0, 10, 12, 13}));
  EXPECT_EQ(evaluation.at_origins.scan_a, 1);
  EXPECT_EQ(evaluation.at_origins.scan_b, 11);
  EXPECT_NEAR(evaluation.at_origins.error.translation_m, 0.0, 1e-12);
  EXPECT_EQ(evaluation.at_recognitions.size(), 1U);
  EXPECT_EQ(evaluation.recognitions_without_truth, 1U);
}

TEST(MergeEvaluation, RefusesMapsOfAnotherLogAndMapsWithoutTruth) {
  const GlobalMap a = Map({{0, 1}}, 0, 0.0);
  const GlobalMap b = Map({{10, 11}}, 0, 0.0);
  MergeResult result;
  try {
    EvaluateMerge(a, b, result, Truth(20, {}), "crc32:9:9");
    FAIL() << "a map of another log was evaluated";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("map A was made from raw.log"), std::string::npos)
        << error.what();
  }
  try {
    EvaluateMerge(a, b, result, Truth(20, {10, 11}));
    FAIL() << "a map without truth was evaluated";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("map B"), std::string::npos) << error.what();
  }
  // The same check alone, before a merge: the maps' log, or no fingerprint to compare, pass.
  EXPECT_THROW(CheckMergeTruthSource(a, b, "crc32:9:9"), std::invalid_argument);
  EXPECT_NO_THROW(CheckMergeTruthSource(a, b, "crc32:1:2"));
  EXPECT_NO_THROW(CheckMergeTruthSource(a, b, ""));
  // A recognition naming a submap the maps do not hold.
  result.recognitions = {Recognition(5, 0, Pose2(), true)};
  EXPECT_THROW(EvaluateMerge(a, b, result, Truth(20, {})), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
