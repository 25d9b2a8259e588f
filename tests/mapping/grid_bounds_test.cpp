// Mapping on hostile input (issue 18): far or non-finite coordinates never become an index or an
// allocation size; a pose jump closes the submap instead of growing its grid.

#include <sys/resource.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/mapping/local_mapper.hpp"
#include "keyplace/mapping/stability_grid.hpp"
#include "support/sanitizers.hpp"

namespace keyplace {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// A scan of the square room |x|, |y| <= half_side_m from a laser at `laser` (in the room).
LaserScan RoomScan(const Pose2& laser, double half_side_m = 10.0, int beams = 180) {
  LaserScan scan;
  scan.max_range_m = 50.0;
  for (int k = 0; k < beams; ++k) {
    const double angle = -M_PI + 2.0 * M_PI * k / beams;
    const double world_angle = angle + laser.theta;
    const Eigen::Vector2d direction(std::cos(world_angle), std::sin(world_angle));
    double range = 1e9;
    for (int axis = 0; axis < 2; ++axis) {
      for (const double wall : {-half_side_m, half_side_m}) {
        if (std::abs(direction[axis]) < 1e-12) continue;
        const double t = (wall - laser.translation()[axis]) / direction[axis];
        if (t > 0) range = std::min(range, t);
      }
    }
    scan.ranges_m.push_back(range);
    scan.angles_rad.push_back(angle);
    scan.valid.push_back(1);
  }
  return scan;
}

// Expects `call` to throw std::invalid_argument whose message contains every fragment.
template <typename Call>
void ExpectInvalid(Call call, std::initializer_list<std::string> fragments) {
  try {
    call();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& error) {
    const std::string message = error.what();
    for (const auto& fragment : fragments) {
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "message '" << message << "' lacks '" << fragment << "'";
    }
  }
}

TEST(StabilityGridBounds, PointsWithoutACellAreRejected) {
  const StabilityGrid grid{MappingConfig{}};
  const auto cell = grid.TryCellOf({-0.05, 0.15});
  ASSERT_TRUE(cell.has_value());
  EXPECT_EQ(cell->i, -1);
  EXPECT_EQ(cell->j, 1);
  for (const Eigen::Vector2d& point : {Eigen::Vector2d(kNaN, 0.0), Eigen::Vector2d(0.0, kInf),
                                       Eigen::Vector2d(3e8, 0.0), Eigen::Vector2d(0.0, -1e300)}) {
    EXPECT_FALSE(grid.TryCellOf(point).has_value()) << point.transpose();
    EXPECT_THROW(grid.CellOf(point), std::invalid_argument) << point.transpose();
  }
}

TEST(StabilityGridBounds, FarEndpointsAreRejectedAndTheGridIsUnchanged) {
  StabilityGrid grid{MappingConfig{}};
  const LaserScan scan = RoomScan(Pose2());
  grid.InsertRays({0.0, 0.0}, scan.ValidEndpoints(), 0);
  const std::int64_t cells = grid.allocated_cell_count();
  const std::int64_t hits = grid.hit_cell_count();
  ASSERT_GT(cells, 0);
  ASSERT_LE(cells, MappingConfig{}.max_grid_cells);
  // Beyond the index range (formerly an unchecked int conversion), not finite, and within the
  // index range but beyond max_grid_cells (formerly a multi-gigabyte allocation).
  ExpectInvalid([&] { grid.InsertRays({0.0, 0.0}, {{3e8, 0.0}}, 1); }, {"no cell"});
  ExpectInvalid([&] { grid.InsertRays({0.0, 0.0}, {{1.0, kNaN}}, 1); }, {"no cell"});
  ExpectInvalid([&] { grid.InsertRays({kNaN, 0.0}, {{1.0, 1.0}}, 1); }, {"no cell"});
  ExpectInvalid([&] { grid.InsertRays({0.0, 0.0}, {{1e5, 0.0}}, 1); }, {"max_grid_cells"});
  EXPECT_EQ(grid.allocated_cell_count(), cells);
  EXPECT_EQ(grid.hit_cell_count(), hits);
  GridKeypoint keypoint;
  keypoint.position_m = {kNaN, 0.0};
  EXPECT_THROW(grid.InsertKeypoint(keypoint), std::invalid_argument);
}

TEST(StabilityGridBounds, CellsToCoverPredictsTheGrowth) {
  StabilityGrid grid{MappingConfig{}};
  EXPECT_EQ(grid.CellsToCover({0, 0}, {0, 0}), 129 * 129);  // one cell and a 64-cell margin
  grid.InsertRays({0.05, 0.05}, {{0.05, 0.05}}, 0);
  EXPECT_EQ(grid.allocated_cell_count(), 129 * 129);
  EXPECT_EQ(grid.CellsToCover({10, -10}, {20, 10}), 129 * 129);  // already covered
  EXPECT_EQ(grid.CellsToCover({0, 0}, {1000, 0}), (1000 + 129) * 129);
  const int far = StabilityGrid::kMaxCellIndex;
  EXPECT_EQ(grid.CellsToCover({-far, -far}, {far, far}),
            (2 * std::int64_t{far} + 129) * (2 * std::int64_t{far} + 129));
}

class PoseJumpTest : public ::testing::TestWithParam<double> {};

// One odometry glitch: the robot stays in its room, but one scan's pose jumps by x_m.
TEST_P(PoseJumpTest, AJumpClosesTheSubmapWithoutGrowingTheGrid) {
  LocalMapper mapper;
  for (int k = 0; k < 5; ++k) {
    const Pose2 pose(0.1 * k, 0.0, 0.0);
    ASSERT_FALSE(mapper.AddScan(k, RoomScan(pose), pose, {}));
  }
  const std::int64_t cells = mapper.grid().allocated_cell_count();
  const std::int64_t hits = mapper.grid().hit_cell_count();
  const Pose2 glitch(GetParam(), 0.0, 0.0);
  EXPECT_TRUE(mapper.AddScan(5, RoomScan(Pose2(0.5, 0.0, 0.0)), glitch, {}));
  EXPECT_TRUE(mapper.complete());
  EXPECT_TRUE(mapper.forced());
  EXPECT_TRUE(mapper.grid_limited());
  EXPECT_EQ(mapper.grid().allocated_cell_count(), cells);
  EXPECT_EQ(mapper.grid().hit_cell_count(), hits);
  const Submap submap = mapper.Snapshot();
  ASSERT_EQ(submap.scan_indices.size(), 6u);  // the scan's pose is kept, its data is not
  EXPECT_EQ(submap.last_scan(), 5);
  EXPECT_TRUE(submap.forced);
  // The next submap starts with the next scan, from scratch.
  mapper.Reset();
  EXPECT_FALSE(mapper.grid_limited());
  const Pose2 back(0.6, 0.0, 0.0);
  EXPECT_FALSE(mapper.AddScan(6, RoomScan(back), back, {}));
  EXPECT_LE(mapper.grid().allocated_cell_count(), cells);
}

INSTANTIATE_TEST_SUITE_P(Jumps, PoseJumpTest, ::testing::Values(1e5, -3e8, 1e300));

TEST(LocalMapperBounds, NonFiniteInputIsAnErrorNamingTheScanAndChangesNothing) {
  LocalMapper mapper;
  const Pose2 pose(0.0, 0.0, 0.0);
  ASSERT_FALSE(mapper.AddScan(0, RoomScan(pose), pose, {}));
  const std::int64_t cells = mapper.grid().allocated_cell_count();
  ExpectInvalid([&] { mapper.AddScan(1, RoomScan(pose), Pose2(kNaN, 0.0, 0.0), {}); },
                {"scan 1", "pose", "not finite"});
  LaserScan nan_angle = RoomScan(pose);
  nan_angle.angles_rad[7] = kNaN;  // e.g. a field of view of inf
  ExpectInvalid([&] { mapper.AddScan(2, nan_angle, pose, {}); }, {"scan 2", "beam 7"});
  LaserScan bad_mounting = RoomScan(pose);
  bad_mounting.T_robot_laser = Pose2(0.0, kInf, 0.0);
  ExpectInvalid([&] { mapper.AddScan(3, bad_mounting, pose, {}); }, {"scan 3", "mounting"});
  Keypoint keypoint;
  keypoint.position_m = {kNaN, 1.0};
  ExpectInvalid([&] { mapper.AddScan(4, RoomScan(pose), pose, {keypoint}); },
                {"scan 4", "keypoint"});
  EXPECT_EQ(mapper.scan_count(), 1u);
  EXPECT_EQ(mapper.grid().allocated_cell_count(), cells);
  EXPECT_FALSE(mapper.complete());
  const Pose2 next(0.1, 0.0, 0.0);
  EXPECT_FALSE(mapper.AddScan(5, RoomScan(next), next, {}));
  EXPECT_EQ(mapper.scan_count(), 2u);
}

TEST(LocalMapperBounds, AScanThatCannotFitOnItsOwnIsAnError) {
  MappingConfig small;
  small.max_grid_cells = 10000;  // less than one cell with its margin (129 x 129)
  LocalMapper mapper(small);
  const Pose2 pose;
  ExpectInvalid([&] { mapper.AddScan(0, RoomScan(pose), pose, {}); },
                {"scan 0", "max_grid_cells = 10000"});
  EXPECT_EQ(mapper.scan_count(), 0u);
  // A beam that ends 1e9 m away (a log's max range of 1e300) cannot fit either.
  LocalMapper defaults;
  LaserScan far = RoomScan(pose);
  far.max_range_m = 1e300;
  far.ranges_m[3] = 1e9;
  ExpectInvalid([&] { defaults.AddScan(0, far, pose, {}); }, {"scan 0", "farthest beam"});
  EXPECT_EQ(defaults.scan_count(), 0u);
}

// 60 scans in a 20 m room, the robot creeping along x; scan 30's pose jumps by 1e5 m.
struct GlitchLog {
  std::vector<LogScan> scans;
  std::vector<Pose2> poses;
  std::vector<std::vector<Keypoint>> keypoints;
  GlitchLog() {
    for (int k = 0; k < 60; ++k) {
      const Pose2 truth(-6.0 + 0.2 * k, 0.0, 0.0);
      scans.emplace_back();
      static_cast<LaserScan&>(scans.back()) = RoomScan(truth);
      poses.push_back(k == 30 ? Pose2(truth.x + 1e5, truth.y, truth.theta) : truth);
    }
    keypoints.resize(scans.size());
  }
};

MappingConfig OverlapOnly() {
  MappingConfig config;
  config.use_distribution = false;
  config.min_stable_keypoints = 0;
  return config;
}

TEST(GlobalMapperBounds, AnOdometryGlitchEndsOneSubmapAndMappingGoesOn) {
  const GlitchLog log;
  const GlobalMap map = BuildGlobalMap({log.scans, log.poses, log.keypoints}, OverlapOnly());
  int expected_first = 0;
  int glitch_submaps = 0;
  for (const Submap& submap : map.submaps) {
    EXPECT_EQ(submap.first_scan(), expected_first);
    expected_first = submap.last_scan() + 1;
    if (submap.first_scan() <= 30 && 30 <= submap.last_scan()) {
      // Closed by the glitch scan, or, when the glitch scan began it, by the scan after.
      ++glitch_submaps;
      EXPECT_EQ(submap.last_scan(), submap.first_scan() == 30 ? 31 : 30);
      EXPECT_TRUE(submap.forced);
    }
  }
  EXPECT_EQ(glitch_submaps, 1);
  EXPECT_GT(expected_first, 40);  // mapping went on after the glitch
}

// Maps the glitch log with at most 2 GiB of address space; the exit status of a death test.
[[noreturn]] void MapGlitchLogIn2GiB() {
  rlimit limit{};
  limit.rlim_cur = limit.rlim_max = rlim_t{2} << 30;
  if (setrlimit(RLIMIT_AS, &limit) != 0) std::exit(2);
  const GlitchLog log;
  const GlobalMap map = BuildGlobalMap({log.scans, log.poses, log.keypoints}, OverlapOnly());
  std::exit(map.submaps.size() > 2 ? 0 : 3);
}

// Formerly the glitch grew one submap's grid to 1e6 x 330 cells (6.6 GB): the child process died
// of std::bad_alloc.
TEST(GlobalMapperBoundsDeathTest, AnOdometryGlitchNeedsNoGigabytes) {
  if (testing::kAddressSanitizer) GTEST_SKIP() << testing::kAddressSpaceLimitUnderAsan;
  ::testing::FLAGS_gtest_death_test_style = "threadsafe";
  EXPECT_EXIT(MapGlitchLogIn2GiB(), ::testing::ExitedWithCode(0), "");
}

}  // namespace
}  // namespace keyplace
