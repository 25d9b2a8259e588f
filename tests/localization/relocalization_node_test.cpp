// The relocalization node without a middleware (issue 33): the bundled FR079 log's second half
// streamed as driver messages against a map of its first half, what it publishes under each
// policy, and the hostile inputs a live robot sends, each an event and never a crash.

#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/LU>

#include "keyplace/config/config.hpp"
#include "keyplace/localization/relocalization_node.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "support/bundled_map.hpp"
#include "support/expect_contains.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

using testing::BundledFr079;

// The map of the first half of the bundled log (732 of its 1464 scans): the node relocalizes in
// the second half, on scans the map was not built from.
constexpr std::size_t kMapScans = 732;

const GlobalMap& FirstHalfMap() {
  static const GlobalMap map = [] {
    const LogInputs& inputs = BundledFr079().inputs;
    const std::vector<LogScan> scans(inputs.log.scans.begin(),
                                     inputs.log.scans.begin() + kMapScans);
    const std::vector<Pose2> poses(inputs.poses.begin(), inputs.poses.begin() + kMapScans);
    const std::vector<std::vector<Keypoint>> keypoints(inputs.keypoints.begin(),
                                                       inputs.keypoints.begin() + kMapScans);
    return BuildGlobalMap({scans, poses, keypoints}, MappingConfig{});
  }();
  return map;
}

// The robot's odometry frame: the map frame moved, so that map <- odom is not the identity.
const Pose2 kT_odom_world(3.0, -7.0, 0.8);

Config NodeTestConfig(NodePublish publish = NodePublish::kInitialPose) {
  Config config = PresetConfig("strict");  // what a robot program uses (docs/LOCALIZATION.md)
  config.node.publish = publish;
  return config;
}

OdometryInput OdometryMessage(std::size_t k) {
  return {BundledFr079().inputs.log.scans[k].timestamp_s,
          kT_odom_world * BundledFr079().inputs.poses[k]};
}

// Everything the node sent over a stretch of scans.
struct NodeRun {
  std::vector<NodeOutput> outputs;
  std::vector<StampedInitialPose> initial_poses;
  std::vector<StampedTransform> transforms;
  std::vector<FixStatus> statuses;  // one per processed scan
  std::vector<NodeEvent> events;

  void Add(NodeOutput output) {
    initial_poses.insert(initial_poses.end(), output.initial_poses.begin(),
                         output.initial_poses.end());
    transforms.insert(transforms.end(), output.transforms.begin(), output.transforms.end());
    for (const ProcessedScan& scan : output.scans) statuses.push_back(scan.status);
    events.insert(events.end(), output.events.begin(), output.events.end());
    outputs.push_back(std::move(output));
  }
};

// Odometry then the scan, for scans [begin, end); stops `extra` scans after the first fixed one
// when `extra` is given.
NodeRun Stream(RelocalizationNode& node, std::size_t begin, std::size_t end,
               std::optional<std::size_t> extra = std::nullopt) {
  NodeRun run;
  std::optional<std::size_t> stop;
  for (std::size_t k = begin; k < end && (!stop || k < *stop); ++k) {
    run.Add(node.AddOdometry(OdometryMessage(k)));
    run.Add(node.AddScan(testing::BundledScanMessage(k)));
    const bool fixed = !run.statuses.empty() && run.statuses.back() == FixStatus::kFixed;
    if (extra && !stop && fixed) stop = k + 1 + *extra;
  }
  return run;
}

// The scan index of a stamp of the bundled log.
std::size_t ScanAt(double stamp_s) {
  const std::vector<LogScan>& scans = BundledFr079().inputs.log.scans;
  for (std::size_t k = 0; k < scans.size(); ++k) {
    if (scans[k].timestamp_s == stamp_s) return k;
  }
  throw std::runtime_error("no scan at " + std::to_string(stamp_s));
}

void ExpectNearTruth(const Pose2& T_map_robot, std::size_t k) {
  const Pose2 error = Between(BundledFr079().inputs.poses[k], T_map_robot);
  EXPECT_LT(TranslationNorm(error), 0.5) << "scan " << k;
  EXPECT_LT(std::abs(error.theta), 10.0 * M_PI / 180.0) << "scan " << k;
}

bool HasEvent(const std::vector<NodeEvent>& events, const std::string& fragment) {
  for (const NodeEvent& event : events) {
    if (event.what.find(fragment) != std::string::npos) return true;
  }
  return false;
}

TEST(RelocalizationNode, FixesOnTheSecondHalfAndPublishesOneInitialPoseWithItsCovariance) {
  RelocalizationNode node(FirstHalfMap(), NodeTestConfig());
  const NodeRun run = Stream(node, kMapScans, BundledFr079().inputs.log.scans.size(), 40);
  ASSERT_EQ(run.initial_poses.size(), 1U) << "one fix, published once";
  EXPECT_TRUE(run.transforms.empty()) << "initialpose policy: no map -> odom";
  const StampedInitialPose& fix = run.initial_poses.front();
  EXPECT_EQ(fix.pose.frame_id, "map");
  ExpectNearTruth(fix.pose.T_map_robot, ScanAt(fix.stamp_s));
  // The match's covariance: positive definite and of the size docs/NAVIGATION.md measures.
  const Eigen::Matrix3d& covariance = fix.pose.covariance;
  EXPECT_GT(covariance.determinant(), 0.0);
  EXPECT_GT(covariance(0, 0), 0.03 * 0.03 * 0.99);
  EXPECT_LT(covariance(0, 0), 0.5 * 0.5);
  // searching, then fixed: never fixed before the fix, fixed on the scans after it.
  ASSERT_FALSE(run.statuses.empty());
  EXPECT_EQ(run.statuses.front(), FixStatus::kSearching);
  EXPECT_EQ(run.statuses.back(), FixStatus::kFixed);
  const NodeStatus status = node.status();
  EXPECT_EQ(status.status, FixStatus::kFixed);
  EXPECT_EQ(status.fixes, 1U);
  ASSERT_TRUE(status.pose.has_value());
  ExpectNearTruth(status.pose->T_map_robot, ScanAt(status.last_scan_stamp_s));
  // The odometry frame's place in the map is the inverse of how the test moved it.
  const Pose2 T_map_odom_error = Between(kT_odom_world.inverse(), status.T_world_odom);
  EXPECT_LT(TranslationNorm(T_map_odom_error), 0.5);
  ASSERT_TRUE(status.last_answer.has_value());
  EXPECT_GT(status.answers, 1U);
  // A search's answer names no submap; searches that ended were timed.
  EXPECT_TRUE(!status.last_answer->map_search || status.last_answer->submap_id == -1);
  EXPECT_EQ(status.map_searches > 0, status.map_search_mean_s > 0.0);
  EXPECT_EQ(status.scans_dropped, 0U);
  EXPECT_EQ(status.scans_processed, status.scans_received);
  EXPECT_GT(status.latency_mean_s, 0.0);
  EXPECT_GE(status.latency_p99_s, status.latency_mean_s * 0.5);
  EXPECT_GE(status.latency_max_s, status.latency_p99_s);
  EXPECT_TRUE(HasEvent(run.events, "fixed at"));
  for (const NodeEvent& event : run.events) {
    EXPECT_EQ(event.level, NodeEventLevel::kInfo) << event.what;  // no warning on a clean log
  }
}

TEST(RelocalizationNode, MapToOdomGoesOutWithEveryScanWhileFixedAndNoInitialPose) {
  RelocalizationNode node(FirstHalfMap(), NodeTestConfig(NodePublish::kMapToOdom));
  const NodeRun run = Stream(node, kMapScans, BundledFr079().inputs.log.scans.size(), 20);
  EXPECT_TRUE(run.initial_poses.empty());
  std::size_t fixed_scans = 0;
  for (const FixStatus status : run.statuses) fixed_scans += status == FixStatus::kFixed;
  ASSERT_GT(fixed_scans, 10U);
  // Each fixed scan sends one, stamped with it, and no message without a scan (odometry comes at
  // the next scan's stamp: tf refuses a second transform at a stamp it has).
  std::size_t with_scans = 0;
  for (const NodeOutput& output : run.outputs) {
    if (output.scans.empty()) {
      EXPECT_TRUE(output.transforms.empty());
      continue;
    }
    ASSERT_EQ(output.scans.size(), 1U);
    const bool fixed = output.scans.front().status == FixStatus::kFixed;
    ASSERT_EQ(output.transforms.size(), fixed ? 1U : 0U);
    if (fixed) {
      EXPECT_EQ(output.transforms.front().stamp_s, output.scans.front().stamp_s);
    }
    with_scans += output.transforms.size();
  }
  EXPECT_EQ(with_scans, fixed_scans);
  for (const StampedTransform& transform : run.transforms) {
    EXPECT_EQ(transform.parent_frame, "map");
    EXPECT_EQ(transform.child_frame, "odom");
    EXPECT_LT(TranslationNorm(Between(kT_odom_world.inverse(), transform.T_parent_child)), 0.5);
  }
  // While no scan comes, the wrapper's clock sends the fix's map -> odom every
  // node.status_period_s (1 s), and not within a period of the last one.
  const double last_s = node.status().last_scan_stamp_s;
  EXPECT_TRUE(node.Tick(last_s + 0.5).transforms.empty());
  const NodeOutput quiet = node.Tick(last_s + 1.0);
  ASSERT_EQ(quiet.transforms.size(), 1U);
  EXPECT_EQ(quiet.transforms.front().stamp_s, last_s + 1.0);
  EXPECT_EQ(quiet.transforms.front().T_parent_child.x, node.status().T_world_odom.x);
  EXPECT_TRUE(node.Tick(last_s + 1.5).transforms.empty());
  EXPECT_EQ(node.Tick(last_s + 2.0).transforms.size(), 1U);
}

TEST(RelocalizationNode, RelocalizeSearchesAgainAndTheNextFixIsPublishedAgain) {
  RelocalizationNode node(FirstHalfMap(), NodeTestConfig(NodePublish::kBoth));
  const NodeRun first = Stream(node, kMapScans, BundledFr079().inputs.log.scans.size(), 5);
  ASSERT_EQ(first.initial_poses.size(), 1U);
  EXPECT_FALSE(first.transforms.empty());
  const std::size_t resume = ScanAt(node.status().last_scan_stamp_s) + 1;

  const NodeOutput reset = node.Relocalize();
  EXPECT_TRUE(reset.status_due);
  EXPECT_TRUE(HasEvent(reset.events, "searching again"));
  EXPECT_EQ(node.status().status, FixStatus::kSearching);
  EXPECT_FALSE(node.status().pose.has_value());

  const NodeRun second = Stream(node, resume, BundledFr079().inputs.log.scans.size(), 0);
  ASSERT_FALSE(second.statuses.empty());
  EXPECT_EQ(second.statuses.front(), FixStatus::kSearching) << "the fix was forgotten";
  ASSERT_EQ(second.initial_poses.size(), 1U) << "the new fix is published";
  ExpectNearTruth(second.initial_poses.front().pose.T_map_robot,
                  ScanAt(second.initial_poses.front().stamp_s));
  EXPECT_EQ(node.status().fixes, 2U);
}

TEST(RelocalizationNode, AScanWaitsForOdometryAtItsStampAndIsDroppedWhenALaterOneComesFirst) {
  RelocalizationNode node(FirstHalfMap(), NodeTestConfig());
  const std::size_t k = kMapScans;
  node.AddOdometry(OdometryMessage(k - 1));
  NodeOutput output = node.AddScan(testing::BundledScanMessage(k));
  EXPECT_TRUE(output.scans.empty()) << "no odometry at its stamp yet";
  output = node.AddOdometry(OdometryMessage(k));
  ASSERT_EQ(output.scans.size(), 1U) << "processed when the odometry arrives";
  EXPECT_EQ(output.scans.front().stamp_s, testing::BundledScanMessage(k).stamp_s);

  // The next scans get no odometry: the first is dropped when a scan node.odometry_wait_s (1 s)
  // newer comes; the clock drops nothing (its scan's odometry may still be queued).
  node.AddScan(testing::BundledScanMessage(k + 1));
  output = node.Tick(testing::BundledScanMessage(k + 1).stamp_s + 10.0);
  EXPECT_TRUE(output.events.empty());
  EXPECT_EQ(node.status().scans_waiting, 1U);
  EXPECT_TRUE(output.status_due) << "the status goes out every node.status_period_s";
  ASSERT_LT(testing::BundledScanMessage(k + 2).stamp_s - testing::BundledScanMessage(k + 1).stamp_s,
            1.0);
  EXPECT_TRUE(node.AddScan(testing::BundledScanMessage(k + 2)).events.empty());
  ASSERT_GT(testing::BundledScanMessage(k + 3).stamp_s - testing::BundledScanMessage(k + 1).stamp_s,
            1.0);
  output = node.AddScan(testing::BundledScanMessage(k + 3));
  ASSERT_EQ(output.events.size(), 1U);
  testing::ExpectContains(output.events.front().what, "no odometry at its stamp");
  EXPECT_EQ(node.status().scans_dropped, 1U);
  EXPECT_EQ(node.status().scans_waiting, 2U);
  // The odometry comes back: the scans still waiting are processed.
  output = node.AddOdometry(OdometryMessage(k + 3));
  EXPECT_EQ(output.scans.size(), 2U);
  const NodeStatus status = node.status();
  EXPECT_EQ(status.scans_waiting, 0U);
  EXPECT_EQ(status.scans_received, status.scans_processed + status.scans_dropped);
}

TEST(RelocalizationNode, ScansBehindTheOdometryAreProcessedInTheirOrder) {
  // A busy node or a slow driver: the odometry runs seconds ahead of the scans.
  RelocalizationNode node(FirstHalfMap(), NodeTestConfig());
  const std::size_t k = kMapScans;
  for (std::size_t i = k; i < k + 20; ++i) node.AddOdometry(OdometryMessage(i));
  ASSERT_GT(testing::BundledScanMessage(k + 19).stamp_s - testing::BundledScanMessage(k).stamp_s,
            5.0);
  for (std::size_t i = k; i < k + 20; ++i) {
    const NodeOutput output = node.AddScan(testing::BundledScanMessage(i));
    ASSERT_EQ(output.scans.size(), 1U) << "scan " << i;
    for (const NodeEvent& event : output.events) {
      EXPECT_EQ(event.level, NodeEventLevel::kInfo) << event.what;
    }
  }
  EXPECT_EQ(node.status().scans_dropped, 0U);
}

TEST(RelocalizationNode, HostileInputsAreEventsAndTheNodeStillFixesAfterThem) {
  RelocalizationNode node(FirstHalfMap(), NodeTestConfig());
  std::size_t k = kMapScans;
  std::vector<NodeEvent> events;
  const auto note = [&](NodeOutput output) {
    events.insert(events.end(), output.events.begin(), output.events.end());
  };
  note(node.AddOdometry(OdometryMessage(k)));
  note(node.AddScan(testing::BundledScanMessage(k)));

  ScanInput empty = testing::BundledScanMessage(++k);
  empty.ranges_m.clear();
  note(node.AddOdometry(OdometryMessage(k)));
  note(node.AddScan(empty));
  EXPECT_TRUE(HasEvent(events, "it has no beams"));

  ScanInput too_many = testing::BundledScanMessage(++k);
  too_many.ranges_m.assign(9000, 5.0F);
  too_many.angle_increment_rad = 2.0 * M_PI / 9000.0;
  note(node.AddOdometry(OdometryMessage(k)));
  note(node.AddScan(too_many));
  EXPECT_TRUE(HasEvent(events, "9000 beams, more than the 8192"));

  ScanInput all_nan = testing::BundledScanMessage(++k);
  all_nan.ranges_m.assign(all_nan.ranges_m.size(), std::numeric_limits<float>::quiet_NaN());
  note(node.AddOdometry(OdometryMessage(k)));
  const NodeOutput nan_output = node.AddScan(all_nan);
  note(nan_output);
  EXPECT_EQ(nan_output.scans.size(), 1U) << "a scan of NaN ranges is processed, no beam valid";

  ScanInput no_laser_pose = testing::BundledScanMessage(++k);
  no_laser_pose.T_robot_laser.reset();
  note(node.AddOdometry(OdometryMessage(k)));
  note(node.AddScan(no_laser_pose));
  EXPECT_TRUE(HasEvent(events, "no laser pose for frame 'laser'"));

  note(node.AddScan(testing::BundledScanMessage(k - 3)));  // an old stamp
  EXPECT_TRUE(HasEvent(events, "out of order or repeated"));

  OdometryInput bad_odometry = OdometryMessage(k);
  bad_odometry.stamp_s += 0.01;
  bad_odometry.T_odom_robot.theta = std::numeric_limits<double>::quiet_NaN();
  note(node.AddOdometry(bad_odometry));
  EXPECT_TRUE(HasEvent(events, "is not finite"));

  // The scanner changes: half the beams over the same field of view.
  ScanInput coarse = testing::BundledScanMessage(++k);
  std::vector<float> every_other;
  for (std::size_t i = 0; i < coarse.ranges_m.size(); i += 2)
    every_other.push_back(coarse.ranges_m[i]);
  coarse.ranges_m = every_other;
  coarse.angle_increment_rad *= 2.0;
  note(node.AddOdometry(OdometryMessage(k)));
  note(node.AddScan(coarse));
  EXPECT_TRUE(HasEvent(events, "the scan geometry changed"));

  // The odometry frame jumps by 1e5 m: processed, the query forgotten.
  ++k;
  OdometryInput jump = OdometryMessage(k);
  jump.T_odom_robot = Pose2(1e5, 0.0, 0.0) * jump.T_odom_robot;
  note(node.AddOdometry(jump));
  const NodeOutput jump_output = node.AddScan(testing::BundledScanMessage(k));
  note(jump_output);
  EXPECT_EQ(jump_output.scans.size(), 1U);
  EXPECT_TRUE(HasEvent(events, "searching again"));
  EXPECT_EQ(node.status().scans_dropped, 4U);
  EXPECT_EQ(node.status().odometry_dropped, 1U);

  // The odometry stays in its new frame: the node relocalizes there as before.
  NodeRun run;
  for (++k; k < BundledFr079().inputs.log.scans.size() && run.initial_poses.empty(); ++k) {
    OdometryInput odometry = OdometryMessage(k);
    odometry.T_odom_robot = Pose2(1e5, 0.0, 0.0) * odometry.T_odom_robot;
    run.Add(node.AddOdometry(odometry));
    run.Add(node.AddScan(testing::BundledScanMessage(k)));
  }
  ASSERT_EQ(run.initial_poses.size(), 1U);
  ExpectNearTruth(run.initial_poses.front().pose.T_map_robot,
                  ScanAt(run.initial_poses.front().stamp_s));
}

TEST(RelocalizationNode, TheNodeSectionIsOrdinaryConfiguration) {
  Config config;
  ApplyConfigAssignment("node.publish=map_to_odom", config);
  EXPECT_EQ(config.node.publish, NodePublish::kMapToOdom);
  ApplyConfigAssignment("node.map_frame=world", config);
  EXPECT_EQ(config.node.map_frame, "world");
  try {
    ApplyConfigAssignment("node.publish=sometimes", config);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& error) {
    testing::ExpectContains(error.what(), "node.publish");
    testing::ExpectContains(error.what(), "initialpose | map_to_odom | both");
  }
  Config rejected = config;  // a refused value is left in the config it was set in
  EXPECT_THROW(ApplyConfigAssignment("node.odometry_wait_s=0", rejected), std::invalid_argument);
  EXPECT_THROW(ApplyConfigAssignment("node.map_frame=my map", rejected), std::invalid_argument);
  ApplyConfigAssignment("node.odometry=tf", config);
  EXPECT_EQ(config.node.odometry, NodeOdometry::kTf);
  const std::string yaml = ConfigToYaml(config);
  testing::ExpectContains(yaml, "node:");
  Config read_back;
  ApplyConfigYaml(yaml, "dumped", read_back);
  EXPECT_EQ(read_back.node.publish, NodePublish::kMapToOdom);
  EXPECT_EQ(read_back.node.map_frame, "world");
}

TEST(RelocalizationNode, SaveStatusWritesTheStatusAsYaml) {
  RelocalizationNode node(FirstHalfMap(), NodeTestConfig());
  Stream(node, kMapScans, BundledFr079().inputs.log.scans.size(), 0);
  const std::string path = testing::MakeTempDir("node_status") + "/status.yaml";
  node.SaveStatus(path);
  std::ifstream file(path);
  const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  testing::ExpectContains(text, "status: fixed\n");
  testing::ExpectContains(text, "pose: {frame_id: map, x: ");
  testing::ExpectContains(text, "fixes: 1\n");
  testing::ExpectContains(text, "source: ");  // of the last answer: keypoints or a map search
  testing::ExpectContains(text, "map_searches: ");
  EXPECT_THROW(node.SaveStatus("/nonexistent-dir/status.yaml"), std::runtime_error);
}

}  // namespace
}  // namespace keyplace
