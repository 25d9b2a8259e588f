// The whole online pipeline on a simulated square-loop world: a square corridor with clutter,
// driven 1.4 times round with drifting odometry. ICP is switched off (every correction is
// "too large", so the pose is the odometry prediction), so the drift stays in the estimate until
// a loop removes it.

#include "keyplace/slam/online_slam.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/eval/loop_overlap.hpp"
#include "keyplace/features/flirt.hpp"
#include "support/square_loop_run.hpp"

namespace keyplace {
namespace {

using testing::Simulate;
using testing::SimulatedRun;
using testing::SimulationConfig;

double AlignedMaxError(const std::vector<Pose2>& estimate, const std::vector<Pose2>& truth) {
  // Errors relative to the first pose (both trajectories start at their first pose).
  double worst = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Pose2 e = Between(truth.front(), truth[i]);
    const Pose2 p = Between(estimate.front(), estimate[i]);
    worst = std::max(worst, (e.translation() - p.translation()).norm());
  }
  return worst;
}

// FLIRT keypoints of every scan of a run (extracted once per test, shared by its SLAM runs).
std::vector<std::vector<Keypoint>> KeypointsOf(const SimulatedRun& run) {
  const FlirtExtractor extractor;
  std::vector<std::vector<Keypoint>> keypoints;
  keypoints.reserve(run.scans.size());
  for (const LogScan& scan : run.scans) keypoints.push_back(extractor.Extract(scan));
  return keypoints;
}

TEST(OnlineSlam, ClosesTheSquareLoopAndRemovesTheDrift) {
  const SimulatedRun run = Simulate(1.4);
  const FlirtExtractor extractor;
  // Stable-keypoint loop queries, whose RANSAC transforms (~18 keypoints) the refinement must
  // improve on. All-scan queries' RANSAC transforms are already as good in this world (summed
  // errors 0.040 m against 0.043 m refined) and are covered by
  // LoopQueriesUseTheKeypointsOfAllScans.
  SlamConfig config = SimulationConfig();
  config.all_scan_loop_queries = false;
  OnlineSlam slam(config);
  for (std::size_t i = 0; i < run.scans.size(); ++i) {
    const std::vector<Keypoint> keypoints = extractor.Extract(run.scans[i]);
    slam.AddScan(static_cast<int>(i), run.scans[i], run.scans[i].odometry_pose, keypoints);
  }
  slam.Finish();
  const std::vector<OnlineSlam::ScanPose> trajectory = slam.Trajectory();
  ASSERT_EQ(trajectory.size(), run.truth.size());
  std::vector<Pose2> estimate, odometry;
  for (const auto& pose : trajectory) {
    estimate.push_back(pose.T_world_robot);
    odometry.push_back(pose.T_world_robot_icp);
  }
  const double before = AlignedMaxError(odometry, run.truth);
  const double after = AlignedMaxError(estimate, run.truth);
  std::size_t used = 0;
  for (const LoopClosure& loop : slam.loops()) used += slam.LoopUsed(loop) ? 1 : 0;
  EXPECT_GE(slam.map().submaps.size(), 10u);
  EXPECT_GE(used, 1u) << slam.loops().size() << " loops detected";
  EXPECT_GT(before, 2.0);
  EXPECT_LT(after, 1.0) << "before " << before;
  // Every loop is refined, and its transform (partner frame) matches the true relative pose of
  // the two submaps' first scans; the RANSAC estimate against the matched submap is worse.
  double refined_error_sum = 0.0, ransac_error_sum = 0.0;
  for (const LoopClosure& loop : slam.loops()) {
    const Submap& ref = slam.map().submaps[loop.reference_submap];
    const Submap& matched = slam.map().submaps[loop.matched_submap];
    const Submap& cur = slam.map().submaps[loop.query_submap];
    EXPECT_TRUE(loop.refined);
    EXPECT_LE(std::abs(loop.reference_submap - loop.matched_submap), 3);
    const Pose2 truth = Between(run.truth[ref.first_scan()], run.truth[cur.first_scan()]);
    const Pose2 truth_matched =
        Between(run.truth[matched.first_scan()], run.truth[cur.first_scan()]);
    const double error = TranslationNorm(Between(truth, loop.T_ref_cur));
    EXPECT_LT(error, 0.05) << "loop " << loop.query_submap << " -> " << loop.reference_submap;
    refined_error_sum += error;
    ransac_error_sum += TranslationNorm(Between(truth_matched, loop.T_matched_cur_ransac));
  }
  EXPECT_LT(refined_error_sum, ransac_error_sum);
  // Each loop's submaps largely agree where both looked under the loop transform, and do not
  // 0.7 m and 6 deg off it (the simulated corridors keep a shift along one axis aligned, hence
  // the diagonal).
  for (const LoopClosure& loop : slam.loops()) {
    const Submap& ref = slam.map().submaps[loop.reference_submap];
    const Submap& cur = slam.map().submaps[loop.query_submap];
    const OccupancySummary& ref_seen = slam.ObservedArea(loop.reference_submap);
    const OccupancySummary& cur_seen = slam.ObservedArea(loop.query_submap);
    EXPECT_GT(ref_seen.cells.size(), 5 * ref.occupancy.cells.size());
    EXPECT_GT(CommonAreaOverlap(ref.occupancy, cur.occupancy, ref_seen, cur_seen, loop.T_ref_cur),
              0.4);
    EXPECT_LT(CommonAreaOverlap(ref.occupancy, cur.occupancy, ref_seen, cur_seen,
                                Pose2(0.5, 0.5, 0.1) * loop.T_ref_cur),
              0.2);
  }
  // Every submap pose follows its node.
  for (const Submap& submap : slam.map().submaps) {
    const Pose2 node = slam.graph().node(submap.id);
    EXPECT_NEAR(submap.origin().x, node.x, 1e-9);
    EXPECT_NEAR(submap.origin().y, node.y, 1e-9);
  }
}

// A loop the estimate already meets within its sigmas is not optimised at once: it waits in the
// graph for the next loop that disagrees, or for Finish(). The first loop of the square removes
// the drift (optimised at once); later loops of the same corners agree with the corrected graph.
TEST(OnlineSlam, LoopsTheEstimateAlreadyMeetsWaitForTheNextOptimisation) {
  const SimulatedRun run = Simulate(1.4);
  const FlirtExtractor extractor;
  OnlineSlam slam(SimulationConfig());
  int first_loop_optimized = -1;
  for (std::size_t i = 0; i < run.scans.size(); ++i) {
    const SlamStep step = slam.AddScan(static_cast<int>(i), run.scans[i],
                                       run.scans[i].odometry_pose, extractor.Extract(run.scans[i]));
    if (step.loop >= 0 && first_loop_optimized < 0) first_loop_optimized = step.optimized ? 1 : 0;
  }
  const SlamStats before_finish = slam.stats();
  slam.Finish();
  const SlamStats& stats = slam.stats();
  ASSERT_GE(stats.loops_accepted, 3u);
  EXPECT_EQ(first_loop_optimized, 1);
  EXPECT_GE(stats.loops_deferred, 1u);
  // slam.optimize_every_loops 1: one optimisation per loop that was not deferred (+ Finish's).
  EXPECT_EQ(before_finish.optimizations + before_finish.loops_deferred, stats.loops_accepted);
  // Every deferred loop is in the final solution, and it still fits it.
  for (const LoopClosure& loop : slam.loops()) {
    if (!loop.accepted) continue;
    EXPECT_TRUE(slam.LoopUsed(loop));
    EXPECT_LT(slam.graph().WhitenedResidual(loop.edge), 3.0) << "loop " << loop.query_submap;
  }
}

// Issue 17: with slam.all_scan_loop_queries (the default) the loop detector queries with the
// keypoints of all the submap's scans, as `keyplace localize` does. With gamma_min 1 for
// stable-keypoint queries no loop can pass the stable query's gamma check; the all-scan query is
// held to place.min_gamma_all_scans instead.
TEST(OnlineSlam, LoopQueriesUseTheKeypointsOfAllScans) {
  const SimulatedRun run = Simulate(1.4);
  const std::vector<std::vector<Keypoint>> keypoints = KeypointsOf(run);
  std::size_t rejected_by_point_overlap = 0;
  auto loops_found = [&](bool all_scan_loop_queries, double min_gamma_all_scans,
                         PlaceRecognitionConfig::QueryKeypoints query_keypoints =
                             PlaceRecognitionConfig::QueryKeypoints::kAllScans,
                         double min_point_overlap = LoopRefinementConfig{}.min_point_overlap) {
    SlamConfig config = SimulationConfig();
    config.all_scan_loop_queries = all_scan_loop_queries;
    config.place.query_keypoints = query_keypoints;
    config.place.min_gamma = 1.0;
    config.place.min_gamma_all_scans = min_gamma_all_scans;
    config.loop_refinement.min_point_overlap = min_point_overlap;
    OnlineSlam slam(config);
    for (std::size_t i = 0; i < run.scans.size(); ++i) {
      slam.AddScan(static_cast<int>(i), run.scans[i], run.scans[i].odometry_pose, keypoints[i]);
    }
    slam.Finish();
    rejected_by_point_overlap = slam.stats().loops_rejected_by_point_overlap;
    return slam.loops().size();
  };
  EXPECT_EQ(loops_found(false, 0.0), 0U);  // stable-keypoint queries
  const std::size_t all_scan_loops = loops_found(true, 0.0);
  EXPECT_GE(all_scan_loops, 1U);
  // The dense point-overlap check drops every match when nothing can overlap enough.
  EXPECT_EQ(loops_found(true, 0.0, PlaceRecognitionConfig::QueryKeypoints::kAllScans, 1.0), 0U);
  EXPECT_GE(rejected_by_point_overlap, 1U);
  EXPECT_EQ(loops_found(true, 1.0), 0U);  // held to min_gamma_all_scans
  // With stable place queries (the paper preset) the loop detector queries with stable ones too.
  EXPECT_EQ(loops_found(true, 0.0, PlaceRecognitionConfig::QueryKeypoints::kStable), 0U);
  EXPECT_TRUE(SlamConfig{}.all_scan_loop_queries);
}

// Issue 17: a world where stable keypoints do not recur. With 4 cm range noise (a cheap
// scanner) keypoints jitter from scan to scan, and too few stay stable for a stable-keypoint
// query to pass the gamma check at the default gamma_min: that detector finds no loop, the drift
// stays. Queried with the keypoints of all the submap's scans (the default), the same run closes
// its loops, each at the true relative pose, and the drift goes. The counts belong to this
// world's seeds (measured: stable / all-scan loops 4 / 10 at 5 mm and 2 cm of noise, 0 / 3 at
// 4 cm, 0 / 0 at 6 cm): a change to FLIRT or to the place thresholds may move them.
TEST(OnlineSlam, AllScanLoopQueriesFindTheLoopsStableOnesMissInANoisyWorld) {
  const SimulatedRun run = Simulate(1.4, 0.04);
  const std::vector<std::vector<Keypoint>> keypoints = KeypointsOf(run);
  auto run_slam = [&](bool all_scan_loop_queries) {
    SlamConfig config = SimulationConfig();
    config.all_scan_loop_queries = all_scan_loop_queries;
    auto slam = std::make_unique<OnlineSlam>(config);
    for (std::size_t i = 0; i < run.scans.size(); ++i) {
      slam->AddScan(static_cast<int>(i), run.scans[i], run.scans[i].odometry_pose, keypoints[i]);
    }
    slam->Finish();
    return slam;
  };
  const auto drift = [&](const OnlineSlam& slam) {
    std::vector<Pose2> estimate;
    for (const auto& pose : slam.Trajectory()) estimate.push_back(pose.T_world_robot);
    return AlignedMaxError(estimate, run.truth);
  };
  const auto stable = run_slam(false);
  EXPECT_EQ(stable->loops().size(), 0U);
  EXPECT_GT(drift(*stable), 2.0);
  const auto all_scans = run_slam(true);
  EXPECT_GE(all_scans->loops().size(), 2U);
  for (const LoopClosure& loop : all_scans->loops()) {
    EXPECT_TRUE(all_scans->LoopUsed(loop));
    const Submap& ref = all_scans->map().submaps[loop.reference_submap];
    const Submap& cur = all_scans->map().submaps[loop.query_submap];
    const Pose2 truth = Between(run.truth[ref.first_scan()], run.truth[cur.first_scan()]);
    EXPECT_LT(TranslationNorm(Between(truth, loop.T_ref_cur)), 0.1)
        << "loop " << loop.query_submap << " -> " << loop.reference_submap;
  }
  EXPECT_LT(drift(*all_scans), 1.0) << "stable queries: " << drift(*stable);
}

// The stable keypoints of every submap, in order, as (x, y) of each: what the keypoints given to
// AddScan decide.
std::vector<std::pair<double, double>> SubmapKeypoints(const OnlineSlam& slam) {
  std::vector<std::pair<double, double>> positions;
  for (const Submap& submap : slam.map().submaps) {
    for (const StableKeypoint& keypoint : submap.keypoints) {
      positions.emplace_back(keypoint.position_m.x(), keypoint.position_m.y());
    }
  }
  return positions;
}

// Scan in, poses out: AddScan without keypoints extracts them as a log's are prepared (FLIRT in
// the odometry frame), so it builds the map and trajectory of the keypoints path exactly. A
// quarter lap, a few submaps; the keypoints of the identity frame would give other submaps.
TEST(OnlineSlam, ScanInEntryExtractsTheKeypointsOfTheOdometryFrame) {
  const SimulatedRun run = Simulate(0.25);
  const FlirtExtractor extractor;
  SlamConfig config = SimulationConfig();
  OnlineSlam given(config), scan_in(config), identity_frame(config);
  for (std::size_t i = 0; i < run.scans.size(); ++i) {
    const LogScan& scan = run.scans[i];
    const Pose2 T_odom_laser = scan.odometry_pose.value() * scan.T_robot_laser;
    given.AddScan(static_cast<int>(i), scan, scan.odometry_pose,
                  extractor.Extract(scan, T_odom_laser));
    scan_in.AddScan(static_cast<int>(i), scan, scan.odometry_pose);
    identity_frame.AddScan(static_cast<int>(i), scan, scan.odometry_pose, extractor.Extract(scan));
  }
  ASSERT_GE(given.map().submaps.size(), 2u);
  EXPECT_EQ(SubmapKeypoints(scan_in), SubmapKeypoints(given));
  EXPECT_NE(SubmapKeypoints(identity_frame), SubmapKeypoints(given));
  const std::vector<OnlineSlam::ScanPose> expected = given.Trajectory();
  const std::vector<OnlineSlam::ScanPose> trajectory = scan_in.Trajectory();
  ASSERT_EQ(trajectory.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(trajectory[i].T_world_robot.x, expected[i].T_world_robot.x) << "scan " << i;
    EXPECT_EQ(trajectory[i].T_world_robot.theta, expected[i].T_world_robot.theta) << "scan " << i;
    EXPECT_EQ(trajectory[i].submap, expected[i].submap) << "scan " << i;
  }
}

// Loop queries retrieve places by their words (place.retrieval auto); with one place retrieved the
// words alone miss loops here, and the submaps the estimate puts within loop_search_near_m of the
// query's origin, paired besides, bring them back (all of them: every place retrieved finds 10).
TEST(OnlineSlam, LoopQueriesAlsoPairTheSubmapsTheEstimatePutsNearby) {
  const SimulatedRun run = Simulate(1.4);
  const std::vector<std::vector<Keypoint>> keypoints = KeypointsOf(run);
  const auto loops_found = [&](int retrieval_places, double loop_search_near_m) {
    SlamConfig config = SimulationConfig();
    config.place.retrieval_places = retrieval_places;
    config.loop_search_near_m = loop_search_near_m;
    OnlineSlam slam(config);
    for (std::size_t i = 0; i < run.scans.size(); ++i) {
      slam.AddScan(static_cast<int>(i), run.scans[i], run.scans[i].odometry_pose, keypoints[i]);
    }
    slam.Finish();
    return slam.loops().size();
  };
  const std::size_t words_alone = loops_found(1, 0.0);
  const std::size_t with_nearby = loops_found(1, 3.0);
  // Measured: 3 loops with the words alone, 10 with the submaps nearby (as with every place
  // retrieved).
  EXPECT_GE(with_nearby, words_alone + 5) << "words alone " << words_alone;
}

TEST(OnlineSlam, RejectsInvalidConfig) {
  SlamConfig config;
  config.optimize_every_loops = 0;
  EXPECT_THROW(OnlineSlam{config}, std::invalid_argument);
  config = SlamConfig();
  config.loop_sigma_m = 0.0;
  EXPECT_THROW(Validate(config), std::invalid_argument);
  config = SlamConfig();
  config.defer_loop_residual_sigmas = -1.0;
  EXPECT_THROW(Validate(config), std::invalid_argument);
  config = SlamConfig();
  config.loop_search_near_m = -1.0;
  EXPECT_THROW(Validate(config), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
