// The loop evaluation of a SLAM run on hand-made submaps (square blocks of 0.1 m cells) and
// loops whose overlaps, ground-truth errors and counts are worked out by hand in the comments.

#include "keyplace/eval/slam_loop_evaluation.hpp"

#include <cmath>
#include <optional>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace keyplace {
namespace {

constexpr double kDeg = 180.0 / M_PI;

OccupancySummary Block(int x0, int y0, int w, int h) {
  OccupancySummary grid;
  grid.cell_size_m = 0.1;
  for (int i = 0; i < w; ++i) {
    for (int j = 0; j < h; ++j) grid.cells.emplace_back(x0 + i, y0 + j);
  }
  return grid;
}

OccupancySummary Union(OccupancySummary a, const OccupancySummary& b) {
  a.cells.insert(a.cells.end(), b.cells.begin(), b.cells.end());
  return a;
}

OnlineSlam::ScanPose ScanAt(int scan_index, double x) {
  OnlineSlam::ScanPose pose;
  pose.scan_index = scan_index;
  pose.T_world_robot_icp = Pose2(x, 0.0, 0.0);
  pose.T_world_robot = Pose2(-x, 7.0, 1.0);  // not what the propagation may use
  return pose;
}

TEST(TruthOfEveryScan, PropagatesAlongTheProcessingOrderAndIndexesByScan) {
  // Processing order: scans 4, 3, 2, 1, 0, at ICP x = 0, 1, 2, 3, 4 m. Only scan 4 (position 0)
  // has a corrected pose, (10, 5, 0); max gap 2 positions.
  const std::vector<OnlineSlam::ScanPose> trajectory{ScanAt(4, 0.0), ScanAt(3, 1.0), ScanAt(2, 2.0),
                                                     ScanAt(1, 3.0), ScanAt(0, 4.0)};
  const std::vector<int> corrected_of{-1, -1, -1, -1, 0};
  const std::vector<Pose2> corrected{Pose2(10.0, 5.0, 0.0)};
  const auto truth = TruthOfEveryScan(trajectory, corrected_of, corrected, 2);
  ASSERT_EQ(truth.size(), 5u);
  EXPECT_FALSE(truth[0]);  // position 4: gap 4
  EXPECT_FALSE(truth[1]);  // position 3: gap 3
  ASSERT_TRUE(truth[2]);
  EXPECT_NEAR(truth[2]->T_world_robot.x, 12.0, 1e-12);
  EXPECT_NEAR(truth[2]->T_world_robot.y, 5.0, 1e-12);
  EXPECT_EQ(truth[2]->gap, 2);
  ASSERT_TRUE(truth[3]);
  EXPECT_NEAR(truth[3]->T_world_robot.x, 11.0, 1e-12);
  EXPECT_EQ(truth[3]->gap, 1);
  ASSERT_TRUE(truth[4]);
  EXPECT_NEAR(truth[4]->T_world_robot.x, 10.0, 1e-12);
  EXPECT_EQ(truth[4]->gap, 0);
  // No corrected poses at all: nothing, one entry per scan.
  const auto none = TruthOfEveryScan(trajectory, corrected_of, {}, 2);
  ASSERT_EQ(none.size(), 5u);
  for (const auto& t : none) EXPECT_FALSE(t);
}

// Five submaps, submap i starting at scan 10 i. Occupied: the 1 m block [0, 1)^2 (100 cells),
// except submap 2, which also holds [3, 4) x [0, 2) (200 cells) in a part only it observed.
// Observed: [-0.5, 1.5)^2, for submap 2 also [2.5, 4.5) x [-0.5, 2.5).
struct Fixture {
  GlobalMap map;
  std::vector<OccupancySummary> observed;
  std::vector<std::optional<PropagatedTruth>> truth_of_scan =
      std::vector<std::optional<PropagatedTruth>>(50);
  std::vector<LoopClosure> loops;

  Fixture() {
    for (int id = 0; id < 5; ++id) {
      Submap submap;
      submap.id = id;
      submap.scan_indices = {10 * id, 10 * id + 1};
      submap.poses = {Pose2(), Pose2()};
      submap.occupancy = Block(0, 0, 10, 10);
      observed.push_back(Block(-5, -5, 20, 20));
      if (id == 2) {
        submap.occupancy = Union(submap.occupancy, Block(30, 0, 10, 20));
        observed.back() = Union(observed.back(), Block(25, -5, 20, 30));
      }
      map.submaps.push_back(submap);
    }
    // Corrected origins: submaps 0..3 (gaps 0, 2, 3, 1 scans); submap 4 has none.
    truth_of_scan[0] = PropagatedTruth{Pose2(0.0, 0.0, 0.0), 0, 0};
    truth_of_scan[10] = PropagatedTruth{Pose2(-0.5, 0.0, 0.0), 12, 2};
    truth_of_scan[20] = PropagatedTruth{Pose2(0.1, 0.0, 0.05), 23, 3};
    truth_of_scan[30] = PropagatedTruth{Pose2(-0.7, 0.0, 0.0), 31, 1};

    LoopClosure a;  // 2 -> 0, correct: truth (0.1, 0, 0.05), estimate identity
    a.query_submap = 2;
    a.reference_submap = 0;
    a.matched_submap = 1;
    a.T_ref_cur = Pose2();
    a.T_matched_cur_ransac = Pose2(0.3, 0.0, 0.0);  // truth (0.6, 0, 0.05): 0.3 m off
    LoopClosure b;  // 3 -> 0, wrong: truth (-0.7, 0, 0), estimate (0.2, 0, 0)
    b.query_submap = 3;
    b.reference_submap = 0;
    b.matched_submap = 4;  // no truth: no RANSAC check
    b.T_ref_cur = Pose2(0.2, 0.0, 0.0);
    b.T_matched_cur_ransac = Pose2(1.0, 0.0, 0.0);
    LoopClosure c;  // 4 -> 1: submap 4 has no truth
    c.query_submap = 4;
    c.reference_submap = 1;
    c.matched_submap = 1;
    loops = {a, b, c};
  }

  LoopEvaluation Evaluate(const std::vector<bool>& used) const {
    return EvaluateLoops(
        loops, used, map, [this](int id) -> const OccupancySummary& { return observed[id]; },
        truth_of_scan);
  }
};

TEST(EvaluateLoops, OverlapsOfEveryLoop) {
  const Fixture f;
  const LoopEvaluation e = f.Evaluate({true, false, true});
  ASSERT_EQ(e.overlap.size(), 3u);
  // a: 100 common of 300 distinct cells; only submap 2 observed its second block, so over the
  // common area the submaps agree fully. 0.2 m cells: 25 of 75.
  EXPECT_NEAR(e.overlap[0], 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(e.overlap_coarse[0], 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(e.overlap_common[0], 1.0, 1e-12);
  // Against the matched submap 1 shifted by 3 cells: 70 common of 100 + 300 - 70.
  EXPECT_NEAR(e.overlap_matched_ransac[0], 70.0 / 330.0, 1e-12);
  // b: shifted by 2 cells, 80 of 120, also in the common area (both observed all of it); 0.2 m
  // cells: 20 of 30. Matched submap 4 shifted by 1 m: nothing.
  EXPECT_NEAR(e.overlap[1], 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(e.overlap_coarse[1], 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(e.overlap_common[1], 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(e.overlap_matched_ransac[1], 0.0, 1e-12);
  // c: the same block at the same place.
  EXPECT_NEAR(e.overlap[2], 1.0, 1e-12);
  EXPECT_NEAR(e.overlap_common[2], 1.0, 1e-12);
  EXPECT_NEAR(e.overlap_matched_ransac[2], 1.0, 1e-12);
  // Used loops: a and c.
  EXPECT_EQ(e.used, (std::vector<bool>{true, false, true}));
  EXPECT_EQ(e.used_count, 2u);
  ASSERT_EQ(e.overlap_used.size(), 2u);
  EXPECT_NEAR(e.overlap_used[0], 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(e.overlap_used[1], 1.0, 1e-12);
}

TEST(EvaluateLoops, GroundTruthCheckOfEveryLoop) {
  const Fixture f;
  const LoopEvaluation e = f.Evaluate({true, false, true});
  EXPECT_EQ(e.truth, (std::vector<int>{1, 0, -1}));
  EXPECT_NEAR(e.truth_error_m[0], 0.1, 1e-12);
  EXPECT_NEAR(e.truth_error_deg[0], 0.05 * kDeg, 1e-9);
  EXPECT_NEAR(e.truth_error_m[1], 0.9, 1e-12);
  EXPECT_NEAR(e.truth_error_deg[1], 0.0, 1e-12);
  EXPECT_EQ(e.truth_error_m[2], -1.0);
  EXPECT_EQ(e.truth_error_deg[2], -1.0);
  // RANSAC: a against submap 1 (0.3 m, 0.05 rad off); b's matched submap and c have no truth.
  EXPECT_NEAR(e.truth_error_ransac_m[0], 0.3, 1e-12);
  EXPECT_NEAR(e.truth_error_ransac_deg[0], 0.05 * kDeg, 1e-9);
  EXPECT_EQ(e.truth_error_ransac_m[1], -1.0);
  EXPECT_EQ(e.truth_error_ransac_m[2], -1.0);
  EXPECT_EQ(e.truth_evaluated, 2u);
  EXPECT_EQ(e.truth_correct, 1u);
  EXPECT_EQ(e.truth_wrong, 1u);
  EXPECT_DOUBLE_EQ(e.precision_truth(), 0.5);
  // Gaps of the checked origins: a 0 and 3, b 0 and 1 (submap 1's 2 is only used by RANSAC).
  EXPECT_DOUBLE_EQ(e.truth_mean_gap_scans, 1.0);
  // Paired means: only a has both checks.
  EXPECT_EQ(e.paired_loops, 1u);
  EXPECT_NEAR(e.paired_final_m, 0.1, 1e-12);
  EXPECT_NEAR(e.paired_final_deg, 0.05 * kDeg, 1e-9);
  EXPECT_NEAR(e.paired_ransac_m, 0.3, 1e-12);
  EXPECT_NEAR(e.paired_ransac_deg, 0.05 * kDeg, 1e-9);
}

TEST(EvaluateLoops, OverlapAsACorrectnessTest) {
  // Checked loops: a correct (1/3 all cells, 1 common area), b wrong (2/3, 2/3).
  const LoopEvaluation e = Fixture().Evaluate({true, false, true});
  ASSERT_EQ(e.overlap_tests.size(), 5u);
  for (std::size_t k = 0; k < 5; ++k) {
    const OverlapTest& t = e.overlap_tests[k];
    EXPECT_NEAR(t.threshold, 0.1 * static_cast<double>(k + 1), 1e-12);
    EXPECT_EQ(t.all_cells_correct, t.threshold < 1.0 / 3.0 ? 1u : 0u) << t.threshold;
    EXPECT_EQ(t.all_cells_wrong, 1u) << t.threshold;
    EXPECT_EQ(t.common_correct, 1u) << t.threshold;
    EXPECT_EQ(t.common_wrong, 1u) << t.threshold;
  }
}

TEST(EvaluateLoops, WithoutTruthAndWithBadInput) {
  Fixture f;
  f.truth_of_scan.clear();
  const LoopEvaluation e = f.Evaluate({false, false, false});
  EXPECT_EQ(e.truth, (std::vector<int>{-1, -1, -1}));
  EXPECT_EQ(e.truth_error_ransac_m, (std::vector<double>{-1.0, -1.0, -1.0}));
  EXPECT_EQ(e.truth_evaluated, 0u);
  EXPECT_EQ(e.paired_loops, 0u);
  EXPECT_EQ(e.used_count, 0u);
  EXPECT_TRUE(e.overlap_used.empty());
  EXPECT_DOUBLE_EQ(e.precision_truth(), 0.0);
  EXPECT_THROW(f.Evaluate({true}), std::invalid_argument);
  f.loops[1].reference_submap = 5;
  EXPECT_THROW(f.Evaluate({true, true, true}), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
