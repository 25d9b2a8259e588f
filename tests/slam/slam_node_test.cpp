// The SLAM node without a middleware (issue 33): the bundled FR079 log streamed as driver
// messages, map -> odom composing with the odometry to the SLAM pose, /map going out at its
// period, ~save_map writing a map and grid that load, and an odometry jump absorbed rather than
// mapped.

#include "keyplace/slam/slam_node.hpp"

#include <cmath>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/config/config.hpp"
#include "keyplace/mapping/map_server.hpp"
#include "keyplace/store/map_file.hpp"
#include "support/bundled_map.hpp"
#include "support/expect_contains.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

using testing::BundledFr079;

// Enough of the bundled log for several submaps and /map periods, cheap under the sanitizers.
constexpr std::size_t kScans = 250;
// The robot's odometry frame is not the truth's.
const Pose2 kT_odom_world(3.0, -7.0, 0.8);

Pose2 TrueOdometry(std::size_t k) { return kT_odom_world * BundledFr079().inputs.poses[k]; }

struct SlamNodeRun {
  std::vector<StampedTransform> transforms;
  std::vector<Pose2> T_map_odom;  // sent with each processed scan
  std::vector<StampedGrid> maps;
  std::vector<NodeEvent> events;
  std::vector<Pose2> T_odom_robot;  // as sent, per processed scan
  std::vector<std::size_t> scan;    // the bundled scan of each processed one

  void Add(SlamNodeOutput output) {
    transforms.insert(transforms.end(), output.transforms.begin(), output.transforms.end());
    if (output.map) maps.push_back(*output.map);
    events.insert(events.end(), output.events.begin(), output.events.end());
  }
};

// Odometry, then the scan; `jump` is added to the odometry from scan `jump_at` on.
SlamNodeRun Stream(SlamNode& node, std::size_t scans, std::size_t jump_at = 0,
                   const Pose2& jump = Pose2()) {
  SlamNodeRun run;
  for (std::size_t k = 0; k < scans; ++k) {
    const Pose2 T_odom_robot =
        k >= jump_at && jump_at > 0 ? jump * TrueOdometry(k) : TrueOdometry(k);
    const double stamp_s = BundledFr079().inputs.log.scans[k].timestamp_s;
    run.Add(node.AddOdometry({stamp_s, T_odom_robot}));
    const std::size_t processed = node.status().scans_processed;
    SlamNodeOutput output = node.AddScan(testing::BundledScanMessage(k));
    if (node.status().scans_processed > processed) {
      EXPECT_EQ(output.transforms.front().stamp_s, stamp_s);
      run.T_map_odom.push_back(output.transforms.front().T_parent_child);
      run.T_odom_robot.push_back(T_odom_robot);
      run.scan.push_back(k);
    }
    run.Add(std::move(output));
  }
  return run;
}

// The default node over the first kScans scans, streamed once per test program.
struct SharedRun {
  SlamNode node{Config{}};
  SlamNodeRun run;
};

SharedRun& DefaultRun() {
  static SharedRun* const shared = [] {
    auto* streamed = new SharedRun;
    streamed->run = Stream(streamed->node, kScans);
    return streamed;
  }();
  return *shared;
}

std::size_t OccupiedCells(const OccupancyGrid& grid, const OccupancyGridConfig& config) {
  std::size_t occupied = 0;
  for (int row = 0; row < grid.height; ++row) {
    for (int column = 0; column < grid.width; ++column) {
      occupied += grid.State(column, row, config) == CellState::kOccupied ? 1 : 0;
    }
  }
  return occupied;
}

TEST(SlamNode, MapToOdomComposesWithTheOdometryToAPoseNearTheTruth) {
  const SlamNodeRun& run = DefaultRun().run;
  const SlamNodeStatus status = DefaultRun().node.status();
  EXPECT_EQ(status.scans_received, kScans);
  EXPECT_EQ(status.scans_processed, kScans);
  EXPECT_EQ(status.scans_dropped, 0U);
  EXPECT_GE(status.submaps, 3U);
  const std::vector<Pose2>& T_map_odom = run.T_map_odom;
  ASSERT_EQ(T_map_odom.size(), kScans);
  // One transform per stamp: tf refuses a second one at a stamp it has.
  for (std::size_t i = 0; i < run.transforms.size(); ++i) {
    EXPECT_EQ(run.transforms[i].parent_frame, "map");
    EXPECT_EQ(run.transforms[i].child_frame, "odom");
    if (i > 0) {
      ASSERT_GT(run.transforms[i].stamp_s, run.transforms[i - 1].stamp_s);
    }
  }
  // SLAM's map frame is the odometry frame of the first scan (the odometry here is the corrected
  // trajectory): the robot's map pose drifts from it slowly (its loops close at the ends of the
  // corridors, beyond these scans).
  for (std::size_t i = 0; i < kScans; ++i) {
    const Pose2 T_map_robot = T_map_odom[i] * run.T_odom_robot[i];
    const Pose2 error = Between(TrueOdometry(run.scan[i]), T_map_robot);
    ASSERT_LT(TranslationNorm(error), 1.0) << "scan " << i;
    ASSERT_LT(std::abs(error.theta), 5.0 * M_PI / 180.0) << "scan " << i;
  }
  const Pose2 last = T_map_odom.back() * run.T_odom_robot.back();
  EXPECT_NEAR(last.x, status.T_map_robot.x, 1e-9);
  EXPECT_NEAR(last.y, status.T_map_robot.y, 1e-9);
}

TEST(SlamNode, MapGoesOutEveryPeriodWithTheWallsOfTheLog) {
  const Config config;
  ASSERT_EQ(config.node.map_period_s, 5.0);
  const SlamNodeRun& run = DefaultRun().run;
  const std::vector<LogScan>& scans = BundledFr079().inputs.log.scans;
  const double span_s = scans[kScans - 1].timestamp_s - scans[0].timestamp_s;
  // The first scan's /map, then one per period of stamps (each at the first message after it
  // ends; the log's scans are up to about a second apart).
  EXPECT_GE(run.maps.size(), static_cast<std::size_t>(span_s / 6.0));
  EXPECT_LE(run.maps.size(), static_cast<std::size_t>(span_s / 5.0) + 1);
  EXPECT_EQ(DefaultRun().node.status().maps_published, run.maps.size());
  for (std::size_t i = 1; i < run.maps.size(); ++i) {
    EXPECT_GE(run.maps[i].stamp_s - run.maps[i - 1].stamp_s, 5.0);
  }
  const StampedGrid& map = run.maps.back();
  EXPECT_EQ(map.frame_id, "map");
  EXPECT_GT(OccupiedCells(map.grid, config.grid), 1000U);
  // The clock sends the scans since the last /map, then no more while no scan comes.
  SlamNode node(config);
  constexpr std::size_t kFew = 30;
  Stream(node, kFew);
  const double end_s = scans[kFew - 1].timestamp_s;
  const SlamNodeOutput last = node.Tick(end_s + 60.0);
  ASSERT_TRUE(last.map.has_value());
  EXPECT_EQ(last.map->stamp_s, end_s + 60.0);
  const SlamNodeOutput idle = node.Tick(end_s + 120.0);
  EXPECT_FALSE(idle.map.has_value());
  EXPECT_TRUE(idle.status_due);
  // map -> odom goes out from the clock while no scan sends it, not within a period of one.
  ASSERT_EQ(idle.transforms.size(), 1U);
  EXPECT_EQ(idle.transforms.front().stamp_s, end_s + 120.0);
  EXPECT_TRUE(node.Tick(end_s + 120.5).transforms.empty());
  node.AddOdometry({end_s + 121.0, TrueOdometry(kFew - 1)});
  ScanInput scan = testing::BundledScanMessage(kFew);
  scan.stamp_s = end_s + 121.0;
  EXPECT_EQ(node.AddScan(scan).transforms.size(), 1U);
  EXPECT_TRUE(node.Tick(end_s + 121.5).transforms.empty());
  EXPECT_EQ(node.Tick(end_s + 122.0).transforms.size(), 1U);
}

TEST(SlamNode, SaveMapWritesAMapAndAGridThatLoad) {
  const Config config;
  SlamNode node(config);
  const std::string directory = testing::MakeTempDir("slam_node");
  Stream(node, 5);
  EXPECT_THROW(node.SaveMap(directory + "/early.kpm"), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(directory + "/early.kpm"));
  EXPECT_FALSE(std::filesystem::exists(directory + "/early.yaml"));

  SlamNode& full = DefaultRun().node;
  const SavedSlamMap saved = full.SaveMap(directory + "/site.kpm");
  EXPECT_EQ(saved.grid_path, directory + "/site.yaml");
  EXPECT_EQ(saved.scans, kScans);
  EXPECT_TRUE(CheckMapFile(saved.map_path).ok());
  const GlobalMap map = LoadMap(saved.map_path);
  EXPECT_EQ(map.submaps.size(), saved.submaps);
  EXPECT_EQ(map.pose_source, "slam");
  testing::ExpectContains(map.configuration, "map_period_s");
  const MapServerMap grid = ReadMapServerMap(saved.grid_path);
  const OccupancyGrid expected = full.Grid();
  EXPECT_EQ(grid.width, expected.width);
  EXPECT_EQ(grid.height, expected.height);
  EXPECT_THROW(full.SaveMap("/nonexistent-dir/site.kpm"), std::runtime_error);
}

TEST(SlamNode, AnOdometryJumpIsAbsorbedAndTheMapGoesOn) {
  const Config config;
  SlamNode node(config);
  constexpr std::size_t kJumpAt = 120;
  const Pose2 jump(1e5, -3e4, 1.0);
  const SlamNodeRun run = Stream(node, kScans, kJumpAt, jump);
  EXPECT_EQ(node.status().odometry_jumps, 1U);
  EXPECT_EQ(node.status().scans_processed, kScans);
  std::string warnings;
  for (const NodeEvent& event : run.events) warnings += event.what + "\n";
  testing::ExpectContains(warnings, "a reset or a glitch of the odometry, not motion; absorbed");
  const std::vector<Pose2>& T_map_odom = run.T_map_odom;
  ASSERT_EQ(T_map_odom.size(), kScans);
  // The map poses are those of the same run without the jump, up to the one step of motion the
  // jump hides from the odometry (ICP measures it; the front end, started from a slightly
  // different guess, differed from the smooth run by less than 0.1 mm here, and by 0.09 m and
  // 2.5 degrees in one turn with the jump at scan 250 of 500): map -> odom takes the jump.
  const SlamNodeRun& smooth = DefaultRun().run;
  ASSERT_EQ(smooth.T_map_odom.size(), kScans);
  for (std::size_t i = 0; i < kScans; ++i) {
    const Pose2 T_map_robot = T_map_odom[i] * run.T_odom_robot[i];
    const Pose2 expected = smooth.T_map_odom[i] * smooth.T_odom_robot[i];
    const Pose2 difference = Between(expected, T_map_robot);
    ASSERT_LT(TranslationNorm(difference), 0.3) << "scan " << i;
    ASSERT_LT(std::abs(difference.theta), 5.0 * M_PI / 180.0) << "scan " << i;
  }
  EXPECT_GT(TranslationNorm(T_map_odom.back()), 1e4);
  EXPECT_LT(node.Grid().width, 2000);  // the grid did not stretch over the jump
}

TEST(SlamNode, HostileScansAreDroppedAndMappingGoesOn) {
  const Config config;
  SlamNode node(config);
  const std::vector<LogScan>& scans = BundledFr079().inputs.log.scans;
  // Up to the scan that completes a submap: the next one starts a new submap.
  std::size_t k = 0;
  for (; k < 200 && node.status().submaps == 0; ++k) {
    node.AddOdometry({scans[k].timestamp_s, TrueOdometry(k)});
    node.AddScan(testing::BundledScanMessage(k));
  }
  ASSERT_EQ(node.status().submaps, 1U);
  const double stamp_s = scans[k - 1].timestamp_s;
  const auto at = [&](double dt_s) {
    ScanInput scan = testing::BundledScanMessage(k);
    scan.stamp_s = stamp_s + dt_s;
    return scan;
  };
  ScanInput empty = at(0.01);
  empty.ranges_m.clear();
  ScanInput huge = at(0.02);
  huge.ranges_m.assign(9000, 1.0F);
  // A valid beam 5 km away at 45 degrees as the first scan of a submap: the mapper refuses it
  // (its stability grid would exceed mapping.max_grid_cells), and the map must not break.
  ScanInput far = at(0.03);
  far.range_max_m = 1e4;
  far.ranges_m[far.ranges_m.size() / 4] = 5000.0F;
  ScanInput nan = at(0.04);
  nan.ranges_m.assign(nan.ranges_m.size(), std::nanf(""));
  SlamNodeRun run;
  for (const ScanInput& scan : {empty, huge, far, nan}) {
    SlamNodeOutput output;
    EXPECT_NO_THROW(output = node.AddScan(scan));
    run.Add(std::move(output));
  }
  run.Add(node.AddOdometry({stamp_s + 0.05, TrueOdometry(k - 1)}));
  std::string warnings;
  for (const NodeEvent& event : run.events) warnings += event.what + "\n";
  testing::ExpectContains(warnings, "alone it would grow the stability grid");
  EXPECT_EQ(node.status().scans_dropped, 3U);       // empty, 9000 beams, the 5 km beam
  EXPECT_EQ(node.status().scans_processed, k + 1);  // the all-NaN scan is a scan without returns
  // Mapping goes on: the next 200 scans complete submaps as before.
  const std::size_t processed = node.status().scans_processed;
  for (std::size_t next = k; next < k + 200; ++next) {
    node.AddOdometry({scans[next].timestamp_s, TrueOdometry(next)});
    node.AddScan(testing::BundledScanMessage(next));
  }
  EXPECT_EQ(node.status().scans_dropped, 3U);
  EXPECT_EQ(node.status().scans_processed, processed + 200);
  EXPECT_GT(node.status().submaps, 4U);
  EXPECT_NO_THROW(node.Grid());
  EXPECT_NO_THROW(node.SaveMap(testing::MakeTempDir("slam_node_hostile") + "/site.kpm"));
}

TEST(SlamNode, AHeadingResetIsAbsorbedToo) {
  const Config config;
  SlamNode node(config);
  const std::vector<LogScan>& scans = BundledFr079().inputs.log.scans;
  constexpr std::size_t kResetAt = 100;
  // The odometry frame turns by 3 rad about the robot (an IMU's yaw reset) while it stands: the
  // scan before the reset is sent again 0.1 s later with the reset odometry, a heading jump of
  // more than 0.5 rad + one turn per second. (The bundled log's scans are 0.42 s apart at least,
  // over which one turn per second allows any heading change.)
  const Pose2 at_robot(TrueOdometry(kResetAt - 1).x, TrueOdometry(kResetAt - 1).y, 0.0);
  const Pose2 reset = at_robot * Pose2(0.0, 0.0, 3.0) * at_robot.inverse();
  std::vector<Pose2> T_map_robot;  // of the log's scans
  const auto send = [&](std::size_t k, double stamp_s, const Pose2& T_odom_robot) {
    node.AddOdometry({stamp_s, T_odom_robot});
    ScanInput scan = testing::BundledScanMessage(k);
    scan.stamp_s = stamp_s;
    const SlamNodeOutput output = node.AddScan(scan);
    EXPECT_FALSE(output.transforms.empty()) << "scan " << k;
    return output.transforms.empty() ? Pose2()
                                     : output.transforms.front().T_parent_child * T_odom_robot;
  };
  for (std::size_t k = 0; k < 150; ++k) {
    if (k == kResetAt) send(k - 1, scans[k - 1].timestamp_s + 0.1, reset * TrueOdometry(k - 1));
    const Pose2 T_odom_robot = k >= kResetAt ? reset * TrueOdometry(k) : TrueOdometry(k);
    T_map_robot.push_back(send(k, scans[k].timestamp_s, T_odom_robot));
  }
  EXPECT_EQ(node.status().odometry_jumps, 1U);
  // The map poses are those of the run without the reset.
  const SlamNodeRun& smooth = DefaultRun().run;
  for (std::size_t i = 0; i < T_map_robot.size(); ++i) {
    const Pose2 difference = Between(smooth.T_map_odom[i] * smooth.T_odom_robot[i], T_map_robot[i]);
    ASSERT_LT(TranslationNorm(difference), 0.3) << "scan " << i;
    ASSERT_LT(std::abs(difference.theta), 5.0 * M_PI / 180.0) << "scan " << i;
  }
}

TEST(SlamNode, RefusesAnInvalidNodeSection) {
  Config config;
  config.node.map_period_s = 0.0;
  EXPECT_THROW(SlamNode node(config), std::invalid_argument);
  config.node.map_period_s = 5.0;
  config.node.map_path = "site.yaml";  // the grid's own name
  EXPECT_THROW(SlamNode node(config), std::invalid_argument);
  EXPECT_EQ(GridPathOf("maps/site.kpm"), "maps/site.yaml");
  EXPECT_EQ(GridPathOf("maps.d/site"), "maps.d/site.yaml");
}

}  // namespace
}  // namespace keyplace
