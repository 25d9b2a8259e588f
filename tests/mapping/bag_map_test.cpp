// A map made from the ROS 1 bag fr079.orig.bag equals the map made from the CARMEN log rebuilt
// from it (fr079-raw.log.gz): the whole pipeline (ICP poses, FLIRT keypoints, submaps) sees the
// same input once the bag's poses carry the 6 decimals the log's text gives them.

#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "keyplace/io/ros1_bag.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

// A number as the log's "%.6f" text reads back.
double AsSixDecimals(double value) {
  char text[64];
  const int length = std::snprintf(text, sizeof(text), "%.6f", value);
  double result = 0.0;
  std::from_chars(text, text + length, result);
  return result;
}

Pose2 AsSixDecimals(const Pose2& pose) {
  return {AsSixDecimals(pose.x), AsSixDecimals(pose.y), AsSixDecimals(pose.theta)};
}

// The bag's scans with their poses as the rebuilt log's FLASER lines hold them: robot and laser
// pose each printed with 6 decimals, the mounting recomputed from the two (as the log reader
// does). FLIRT orients its duplicate box by the laser pose and ICP starts from the odometry, so
// 5e-7 differences change a few of the 115 000 keypoints and the ICP poses.
LogInputs BagInputsAsTheLogWritesThem() {
  BagInputConfig config;
  config.laser_pose = "-0.04,0,0";  // the log's offset; the bag's /tf_static has +0.04
  config.scan_fov_rad = M_PI;       // the log's beam spacing pi/360; the bag's is pi/359
  LogInputs inputs;
  inputs.log = ReadRos1Bag(testing::SharedFile("data/fr079.orig.bag"), config);
  for (LogScan& scan : inputs.log.scans) {
    const Pose2 robot = AsSixDecimals(*scan.odometry_pose);
    const Pose2 laser = AsSixDecimals(*scan.odometry_pose * scan.T_robot_laser);
    scan.odometry_pose = robot;
    scan.logged_laser_pose = laser;
    scan.T_robot_laser = Between(robot, laser);
  }
  inputs.file_scans = inputs.log.scans.size();
  inputs.pose_source = PoseSource::kIcp;
  inputs.poses = ScanPoses(inputs.log, PoseSource::kIcp, ScanOdometryConfig{});
  inputs.keypoints = ExtractKeypoints(inputs.log, FlirtExtractor(FlirtConfig{}));
  return inputs;
}

void ExpectSamePose(const Pose2& a, const Pose2& b) {
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.theta, b.theta);
}

void ExpectSameSubmap(const Submap& a, const Submap& b) {
  ASSERT_EQ(a.scan_indices, b.scan_indices) << "submap " << a.id;
  for (std::size_t i = 0; i < a.poses.size(); ++i) ExpectSamePose(a.poses[i], b.poses[i]);
  ASSERT_EQ(a.keypoints.size(), b.keypoints.size()) << "submap " << a.id;
  for (std::size_t k = 0; k < a.keypoints.size(); ++k) {
    const StableKeypoint& p = a.keypoints[k];
    const StableKeypoint& q = b.keypoints[k];
    EXPECT_EQ(p.position_m, q.position_m) << "submap " << a.id << " keypoint " << k;
    EXPECT_EQ(p.orientation_rad, q.orientation_rad);
    EXPECT_EQ(p.scale_m, q.scale_m);
    EXPECT_EQ(p.scale_level, q.scale_level);
    EXPECT_EQ(p.scan_index, q.scan_index);
    EXPECT_EQ(p.stability, q.stability);
    EXPECT_EQ(p.occurrences, q.occurrences);
    EXPECT_EQ(p.descriptor, q.descriptor) << "submap " << a.id << " keypoint " << k;
  }
  EXPECT_EQ(a.occupancy.cell_size_m, b.occupancy.cell_size_m);
  EXPECT_EQ(a.occupancy.cells, b.occupancy.cells);
  EXPECT_EQ(a.overlap, b.overlap);
  EXPECT_EQ(a.distribution, b.distribution);
  EXPECT_EQ(a.forced, b.forced);
}

TEST(BagMap, Fr079BagGivesTheMapOfTheLogRebuiltFromIt) {
  LogInputOptions options;
  options.poses = PoseSource::kIcp;
  const LogInputs log_inputs =
      PrepareLogInputs(testing::SharedFile("data/fr079-raw.log.gz"), options);
  const LogInputs bag_inputs = BagInputsAsTheLogWritesThem();
  ASSERT_EQ(bag_inputs.log.scans.size(), log_inputs.log.scans.size());
  const LogMap log_map = MapLog(log_inputs, MappingConfig{});
  const LogMap bag_map = MapLog(bag_inputs, MappingConfig{});
  EXPECT_EQ(bag_map.map.source_keypoints, log_map.map.source_keypoints);
  ASSERT_EQ(bag_map.map.submaps.size(), log_map.map.submaps.size());
  ASSERT_GT(log_map.map.submaps.size(), 100u);
  for (std::size_t s = 0; s < log_map.map.submaps.size(); ++s) {
    ExpectSameSubmap(log_map.map.submaps[s], bag_map.map.submaps[s]);
    if (::testing::Test::HasFailure()) break;  // the first differing submap says enough
  }
}

}  // namespace
}  // namespace keyplace
