#include "keyplace/mapping/local_mapper.hpp"

#include <cmath>
#include <utility>

#include <gtest/gtest.h>

#include "keyplace/io/carmen_log.hpp"
#include "keyplace/mapping/global_mapper.hpp"

namespace keyplace {
namespace {

// A scan of a closed square room of side 2 * half_side_m centred at `centre` in the world, seen
// from a laser at `laser_in_world` (identity mounting).
LaserScan SquareRoomScan(const Pose2& laser_in_world, double half_side_m, int beams = 360) {
  LaserScan scan;
  scan.max_range_m = 50.0;
  for (int k = 0; k < beams; ++k) {
    const double angle = -M_PI + 2.0 * M_PI * k / beams;
    const double world_angle = angle + laser_in_world.theta;
    const Eigen::Vector2d direction(std::cos(world_angle), std::sin(world_angle));
    // Distance to the square |x| = half, |y| = half from the laser position.
    double range = 1e9;
    for (int axis = 0; axis < 2; ++axis) {
      for (const double wall : {-half_side_m, half_side_m}) {
        const double d = direction[axis];
        if (std::abs(d) < 1e-12) continue;
        const double t = (wall - laser_in_world.translation()[axis]) / d;
        if (t > 0) range = std::min(range, t);
      }
    }
    scan.ranges_m.push_back(range);
    scan.angles_rad.push_back(angle);
    scan.valid.push_back(1);
  }
  return scan;
}

TEST(DistributionDistance, HandComputedCases) {
  constexpr auto kCells = MappingConfig::DistributionNormalization::kCells;
  constexpr auto kPoints = MappingConfig::DistributionNormalization::kPoints;
  const std::vector<Eigen::Vector2d> laser = {{0.1, 0.1}, {0.6, 0.1}, {1.1, 0.1}, {1.6, 0.1}};
  // One keypoint cell among four laser cells: q = 1/4, p = 1:
  // 0.5 (3/4)^2 / (5/4) + 3 * 0.5 * 1/4 = 0.225 + 0.375.
  EXPECT_NEAR(DistributionDistance(laser, {{0.2, 0.2}}, 0.5, kCells), 0.6, 1e-12);
  EXPECT_NEAR(DistributionDistance(laser, laser, 0.5, kCells), 0.0, 1e-12);
  EXPECT_NEAR(DistributionDistance(laser, {{10.0, 10.0}}, 0.5, kCells), 1.0, 1e-12);
  EXPECT_NEAR(DistributionDistance(laser, {}, 0.5, kCells), 1.0, 1e-12);
  // Divided by the number of points: 8 laser points in 4 cells (q = 1/8 per cell), two
  // keypoints in one cell (p = 1/2): 0.5 (3/8)^2 / (5/8) + 3 * 0.5 / 8 = 0.1125 + 0.1875.
  std::vector<Eigen::Vector2d> doubled = laser;
  doubled.insert(doubled.end(), laser.begin(), laser.end());
  EXPECT_NEAR(DistributionDistance(doubled, {{0.2, 0.2}, {0.3, 0.3}}, 0.5, kPoints), 0.3, 1e-12);
  // Disjoint histograms reach the maximum 1 only when every point has a cell of its own.
  EXPECT_NEAR(DistributionDistance(laser, {{10.0, 10.0}}, 0.5, kPoints), 1.0, 1e-12);
}

class OverlapTest : public ::testing::TestWithParam<MappingConfig::OverlapCells> {};

TEST_P(OverlapTest, OverlapFallsAsTheRobotMovesAndCompletesBelowRhoMin) {
  MappingConfig config;
  config.use_distribution = false;
  config.min_stable_keypoints = 0;
  config.overlap_cells = GetParam();
  const auto cells = [&](const LocalMapper& m) {
    return GetParam() == MappingConfig::OverlapCells::kHit ? m.grid().hit_cell_count()
                                                           : m.grid().observed_cell_count();
  };
  LocalMapper mapper(config);
  double previous_overlap = 1.0;
  int completed_at = -1;
  std::int64_t initial_cells = 0;
  for (int k = 0; k < 60 && completed_at < 0; ++k) {
    // A corridor-like room: walk along x inside a long rectangle seen as a big square.
    const Pose2 pose(-8.0 + 0.25 * k, 0.3 * std::sin(0.3 * k), 0.05 * k);
    const LaserScan scan = SquareRoomScan(pose, 10.0);
    const bool complete = mapper.AddScan(k, scan, pose, {});
    EXPECT_LE(mapper.overlap(), previous_overlap + 1e-12);
    previous_overlap = mapper.overlap();
    // rho = a_int / a_uni with the first scan's cells inside the current ones.
    if (k == 0) initial_cells = cells(mapper);
    const double expected = static_cast<double>(initial_cells) / static_cast<double>(cells(mapper));
    EXPECT_DOUBLE_EQ(mapper.overlap(), expected);
    EXPECT_EQ(complete, expected < config.min_overlap) << k;
    if (complete) completed_at = k;
  }
  ASSERT_GT(completed_at, 0);
  EXPECT_LT(mapper.overlap(), 0.75);
  const Submap submap = mapper.Snapshot();
  EXPECT_EQ(static_cast<int>(submap.scan_indices.size()), completed_at + 1);
  EXPECT_EQ(submap.poses.size(), submap.scan_indices.size());
  EXPECT_FALSE(submap.forced);
  EXPECT_EQ(static_cast<std::int64_t>(submap.occupancy.cells.size()),
            mapper.grid().hit_cell_count());
}

INSTANTIATE_TEST_SUITE_P(BothOverlapReadings, OverlapTest,
                         ::testing::Values(MappingConfig::OverlapCells::kHit,
                                           MappingConfig::OverlapCells::kObserved));

TEST(LocalMapper, StaticRobotNeverCompletesUntilForced) {
  MappingConfig config;
  config.max_scans_per_submap = 7;
  LocalMapper mapper(config);
  const Pose2 pose(0.0, 0.0, 0.0);
  const LaserScan scan = SquareRoomScan(pose, 3.0);
  for (int k = 0; k < 6; ++k) EXPECT_FALSE(mapper.AddScan(k, scan, pose, {}));
  EXPECT_DOUBLE_EQ(mapper.overlap(), 1.0);
  EXPECT_TRUE(mapper.AddScan(6, scan, pose, {}));
  EXPECT_TRUE(mapper.forced());
}

TEST(LocalMapper, KeypointsAreStoredInTheFrameOfTheFirstPose) {
  MappingConfig config;
  config.min_stability = 0.0;
  LocalMapper mapper(config);
  const Pose2 first(2.0, 1.0, M_PI / 2.0);
  const Pose2 second(2.0, 2.0, M_PI / 2.0);  // 1 m ahead of the first pose
  Keypoint keypoint;
  keypoint.position_m = {1.0, 0.0};  // 1 m ahead of the laser
  keypoint.orientation_rad = 0.0;
  mapper.AddScan(10, SquareRoomScan(first, 5.0), first, {});
  mapper.AddScan(11, SquareRoomScan(second, 5.0), second, {keypoint});
  const Submap submap = mapper.Snapshot();
  ASSERT_EQ(submap.keypoints.size(), 1u);
  EXPECT_NEAR(submap.keypoints[0].position_m.x(), 2.0, 1e-9);  // 2 m ahead of the first pose
  EXPECT_NEAR(submap.keypoints[0].position_m.y(), 0.0, 1e-9);
  EXPECT_EQ(submap.keypoints[0].scan_index, 11);
  EXPECT_DOUBLE_EQ(submap.origin().x, 2.0);
}

TEST(GlobalMapper, SubmapsAreConsecutiveAndStopAtTheEnd) {
  MappingConfig config;
  config.use_distribution = false;
  config.min_stable_keypoints = 0;
  std::vector<LogScan> scans;
  std::vector<Pose2> poses;
  for (int k = 0; k < 80; ++k) {
    poses.emplace_back(-8.0 + 0.2 * k, 0.0, 0.0);
    LogScan scan;
    static_cast<LaserScan&>(scan) = SquareRoomScan(poses.back(), 10.0, 180);
    scans.push_back(std::move(scan));
  }
  const std::vector<std::vector<Keypoint>> keypoints(scans.size());
  const ScanSequence sequence{scans, poses, keypoints};
  GlobalMappingTimings timings;
  const GlobalMap map = BuildGlobalMap(sequence, config, &timings);
  ASSERT_GE(map.submaps.size(), 2u);
  EXPECT_EQ(timings.submap_seconds.size(), map.submaps.size());
  int expected_first = 0;
  for (const Submap& submap : map.submaps) {
    EXPECT_EQ(submap.id, &submap - map.submaps.data());
    EXPECT_EQ(submap.first_scan(), expected_first);
    expected_first = submap.last_scan() + 1;
    EXPECT_LT(submap.overlap, 0.75);
  }
  EXPECT_LE(expected_first, 80);
  // The scans after the last submap could not complete one on their own.
  LocalMapper mapper(config);
  EXPECT_FALSE(BuildSubmap(sequence, static_cast<std::size_t>(expected_first), mapper));
}

}  // namespace
}  // namespace keyplace
