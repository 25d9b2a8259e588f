// Submap completion bounded in space (MappingConfig::max_path_m): in an open hall seen with
// sparse scans the paper's criteria alone let a submap grow for tens of metres.

#include <algorithm>
#include <vector>

#include <gtest/gtest.h>

#include "../registration/synthetic_scene.hpp"
#include "keyplace/features/flirt.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/mapping/global_mapper.hpp"

namespace keyplace {
namespace {

using testing::Segment;

// A 60 m x 30 m hall with a few pillars far apart: long ranges, few corners.
std::vector<Segment> OpenHall() {
  std::vector<Segment> world =
      testing::Polygon({{-30.0, -15.0}, {30.0, -15.0}, {30.0, 15.0}, {-30.0, 15.0}});
  for (const double x : {-20.0, -8.0, 4.0, 16.0}) {
    for (const double y : {-7.0, 7.0}) {
      const std::vector<Segment> pillar = testing::Polygon(
          {{x - 0.4, y - 0.4}, {x + 0.4, y - 0.4}, {x + 0.4, y + 0.4}, {x - 0.4, y + 0.4}});
      world.insert(world.end(), pillar.begin(), pillar.end());
    }
  }
  return world;
}

struct HallWalk {
  std::vector<LogScan> scans;
  std::vector<Pose2> poses;
  std::vector<std::vector<Keypoint>> keypoints;
};

// The robot crosses the hall along x, one 181-beam front scan (1 deg) every `step_m`, as a
// GMapping log keeps them.
HallWalk WalkThroughHall(double step_m) {
  const std::vector<Segment> world = OpenHall();
  testing::ScanOptions options = testing::FrontLaser(181, 0.0);
  options.max_range_m = 50.0;
  const FlirtExtractor extractor;
  HallWalk walk;
  for (double x = -45.0; x <= 45.0; x += step_m) {
    walk.poses.emplace_back(x, 0.5 * std::sin(0.2 * x), 0.0);
    LogScan scan;
    static_cast<LaserScan&>(scan) = testing::CastScan(world, walk.poses.back(), options);
    walk.keypoints.push_back(extractor.Extract(scan, walk.poses.back()));
    walk.scans.push_back(std::move(scan));
  }
  return walk;
}

double LargestPathM(const GlobalMap& map) {
  double largest = 0.0;
  for (const Submap& submap : map.submaps) largest = std::max(largest, SubmapPathM(submap));
  return largest;
}

TEST(SpatialBound, SparseScansInAnOpenHallCloseSubmapsWithinThePathBound) {
  const HallWalk walk = WalkThroughHall(1.0);
  const ScanSequence sequence{walk.scans, walk.poses, walk.keypoints};
  MappingConfig config;
  const GlobalMap map = BuildGlobalMap(sequence, config);
  ASSERT_GE(map.submaps.size(), 4u);
  for (const Submap& submap : map.submaps) {
    // The scan that reaches the bound closes the submap: at most one step beyond it.
    EXPECT_LE(SubmapPathM(submap), config.max_path_m + 1.1) << submap.id;
    EXPECT_LE(SubmapExtentM(submap), SubmapPathM(submap) + 1e-9) << submap.id;
    EXPECT_FALSE(submap.forced);
  }
  const MappingStats stats = ComputeStats(map);
  EXPECT_GT(stats.path_bound_submaps, 0u);
  EXPECT_LE(stats.max_path_m, config.max_path_m + 1.1);

  // The paper's criteria alone (no bound) let a submap span much more of this hall.
  config.max_path_m = 0.0;
  const GlobalMap unbounded = BuildGlobalMap(sequence, config);
  EXPECT_GT(LargestPathM(unbounded), 2.0 * 8.0);
  EXPECT_EQ(ComputeStats(unbounded).path_bound_submaps, 0u);
}

TEST(SpatialBound, TheBoundClosesAtTheFirstScanThatReachesIt) {
  const HallWalk walk = WalkThroughHall(0.5);
  MappingConfig config;
  config.max_path_m = 3.0;
  config.min_stable_keypoints = 1000;  // the paper's criteria can never close a submap here
  LocalMapper mapper(config);
  double previous_path_m = 0.0;
  std::size_t closed_after = 0;
  for (std::size_t k = 0; k < walk.scans.size(); ++k) {
    const bool complete =
        mapper.AddScan(static_cast<int>(k), walk.scans[k], walk.poses[k], walk.keypoints[k]);
    EXPECT_GE(mapper.path_m(), previous_path_m);
    EXPECT_LE(mapper.extent_m(), mapper.path_m() + 1e-9);
    previous_path_m = mapper.path_m();
    EXPECT_EQ(complete, mapper.path_m() >= 3.0) << k;
    if (complete) {
      closed_after = k + 1;
      break;
    }
  }
  ASSERT_GT(closed_after, 0u);
  EXPECT_TRUE(mapper.path_limited());
  EXPECT_FALSE(mapper.forced());
  const Submap submap = mapper.Snapshot();
  EXPECT_EQ(submap.poses.size(), closed_after);
  EXPECT_NEAR(SubmapPathM(submap), mapper.path_m(), 1e-12);
  EXPECT_NEAR(SubmapExtentM(submap), mapper.extent_m(), 1e-12);
  // Reset starts a new path.
  mapper.Reset();
  EXPECT_EQ(mapper.path_m(), 0.0);
  EXPECT_FALSE(mapper.path_limited());
}

TEST(SpatialBound, MapsWrittenBeforeTheBoundKeepTheirCompletion) {
  MappingConfig stored;
  ApplyStoredKeyValues({{"min_overlap", "0.75"}}, stored);
  EXPECT_EQ(stored.max_path_m, 0.0);
  MappingConfig current;
  ApplyStoredKeyValues({{"max_path_m", "6.5"}}, current);
  EXPECT_EQ(current.max_path_m, 6.5);
  MappingConfig invalid;
  EXPECT_THROW(ApplyKeyValues({{"max_path_m", "-1"}}, invalid), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
