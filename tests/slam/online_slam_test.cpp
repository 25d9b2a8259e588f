// The whole online pipeline on a simulated square-loop world: a square corridor with clutter,
// driven 1.4 times round with drifting odometry. ICP is switched off (every correction is
// "too large", so the pose is the odometry prediction), so the drift stays in the estimate until
// a loop removes it.

#include "keyplace/slam/online_slam.hpp"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/eval/loop_overlap.hpp"
#include "keyplace/features/flirt.hpp"
#include "registration/synthetic_scene.hpp"

namespace keyplace {
namespace {

using testing::CastScan;
using testing::Polygon;
using testing::ScanOptions;
using testing::Segment;

// Corridor between the squares of half-sides 8 m and 4.5 m (3.5 m wide), clutter boxes along both
// walls at random positions and sizes (seeded), so that every place looks different.
std::vector<Segment> SquareCorridorWorld() {
  std::vector<Segment> world = Polygon({{-8, -8}, {8, -8}, {8, 8}, {-8, 8}});
  const std::vector<Segment> inner = Polygon({{-4.5, -4.5}, {4.5, -4.5}, {4.5, 4.5}, {-4.5, 4.5}});
  world.insert(world.end(), inner.begin(), inner.end());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> size(0.2, 0.6);
  std::uniform_real_distribution<double> gap(0.6, 1.6);
  std::uniform_real_distribution<double> turn(-0.6, 0.6);
  for (int side = 0; side < 4; ++side) {
    const double c = std::cos(side * M_PI / 2), s = std::sin(side * M_PI / 2);
    for (double wall : {-7.6, -4.9}) {  // outer wall (inside) and inner wall (outside)
      double u = -6.5;
      while (u < 6.5) {
        const double w = size(rng), h = size(rng), a = turn(rng);
        std::vector<Eigen::Vector2d> box;
        for (const auto& corner : {Eigen::Vector2d(-w / 2, -h / 2), Eigen::Vector2d(w / 2, -h / 2),
                                   Eigen::Vector2d(w / 2, h / 2), Eigen::Vector2d(-w / 2, h / 2)}) {
          const Eigen::Vector2d local(u + std::cos(a) * corner.x() - std::sin(a) * corner.y(),
                                      wall + std::sin(a) * corner.x() + std::cos(a) * corner.y());
          box.emplace_back(c * local.x() - s * local.y(), s * local.x() + c * local.y());
        }
        const std::vector<Segment> box_segments = Polygon(box);
        world.insert(world.end(), box_segments.begin(), box_segments.end());
        u += gap(rng);
      }
    }
  }
  return world;
}

// True poses along the corridor centre line (half-side 6.25 m), counter-clockwise from (0, -6.25)
// heading +x; 0.15 m steps, turning on the spot at the corners.
std::vector<Pose2> SquareLoopPath(double laps) {
  const double half = 6.25, step = 0.15;
  std::vector<Pose2> path;
  Pose2 pose(0.0, -half, 0.0);
  const double side = 2 * half;
  double travelled = 0.0, along_side = half;  // start in the middle of the first side
  const double total = laps * 4 * side;
  while (travelled < total) {
    path.push_back(pose);
    if (along_side + step > side) {
      const double rest = side - along_side;
      pose = pose * Pose2(rest, 0.0, 0.0);
      for (int k = 1; k <= 3; ++k) path.push_back(pose * Pose2(0.0, 0.0, k * M_PI / 6));
      pose = pose * Pose2(step - rest, 0.0, M_PI / 2);
      along_side = step - rest;
    } else {
      pose = pose * Pose2(step, 0.0, 0.0);
      along_side += step;
    }
    travelled += step;
  }
  return path;
}

struct SimulatedRun {
  std::vector<Pose2> truth;
  std::vector<LogScan> scans;
};

SimulatedRun Simulate(double laps) {
  SimulatedRun run;
  run.truth = SquareLoopPath(laps);
  const std::vector<Segment> world = SquareCorridorWorld();
  ScanOptions options;
  options.beams = 360;
  options.max_range_m = 15.0;
  options.range_noise_m = 0.005;
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 1.0);
  Pose2 odometry = run.truth.front();
  for (std::size_t i = 0; i < run.truth.size(); ++i) {
    if (i > 0) {
      const Pose2 step = Between(run.truth[i - 1], run.truth[i]);
      // Drift: 3 % too long, heading bias 0.4 deg per metre, small noise.
      const double d = TranslationNorm(step);
      odometry = odometry * Pose2(1.03 * step.x + 0.002 * noise(rng), step.y + 0.002 * noise(rng),
                                  step.theta + d * 0.4 * M_PI / 180 + 0.001 * noise(rng));
    }
    LogScan scan{CastScan(world, run.truth[i], options, &rng)};
    scan.odometry_pose = odometry;
    scan.timestamp_s = scan.logger_timestamp_s = 0.1 * static_cast<double>(i);
    scan.logged_laser_pose = odometry;
    run.scans.push_back(std::move(scan));
  }
  return run;
}

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

SlamConfig SimulationConfig() {
  SlamConfig config;
  config.odometry.max_correction_translation_m = 1e-12;  // no ICP: odometry drift stays
  config.odometry.max_correction_rotation_rad = 1e-12;
  return config;
}

TEST(OnlineSlam, ClosesTheSquareLoopAndRemovesTheDrift) {
  const SimulatedRun run = Simulate(1.4);
  const FlirtExtractor extractor;
  OnlineSlam slam(SimulationConfig());
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

TEST(OnlineSlam, RejectsInvalidConfig) {
  SlamConfig config;
  config.optimize_every_loops = 0;
  EXPECT_THROW(OnlineSlam{config}, std::invalid_argument);
  config = SlamConfig();
  config.loop_sigma_m = 0.0;
  EXPECT_THROW(Validate(config), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
