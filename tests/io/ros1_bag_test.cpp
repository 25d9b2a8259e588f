// The ROS 1 bag reader on the real bags of ../shared/data: fr079.orig.bag against the CARMEN log
// rebuilt from it (fr079-raw.log.gz), fr-clinic.orig.bag, and damaged copies of fr079.

#include "keyplace/io/ros1_bag.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "keyplace/io/carmen_log.hpp"
#include "support/expect_contains.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

std::string Fr079Bag() { return testing::SharedFile("data/fr079.orig.bag"); }

// The settings that reproduce fr079-raw.log.gz (shared/data/README.md): the log's laser offset
// (the bag's /tf_static has the opposite sign) and its beam spacing (pi/360; the bag says pi/359).
BagInputConfig Fr079AsLog() {
  BagInputConfig config;
  config.laser_pose = "-0.04,0,0";
  config.scan_fov_rad = M_PI;
  return config;
}

const CarmenLog& Fr079FromBag() {
  static const CarmenLog log = ReadRos1Bag(Fr079Bag(), Fr079AsLog());
  return log;
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string WriteBytes(const std::string& name, const std::string& bytes) {
  std::string path = testing::MakeTempDir("ros1bag") + "/" + name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

CarmenReadOptions Reading(const BagInputConfig& config) {
  CarmenReadOptions options;
  options.bag = config;
  return options;
}

std::string ErrorOf(const std::string& path, const BagInputConfig& config) {
  try {
    ReadCarmenLog(path, Reading(config));
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "no error";
}

using testing::ExpectContains;

long Microseconds(double stamp_s) { return std::lround(stamp_s * 1e6); }

TEST(Ros1Bag, Fr079GivesTheScansAndOdometryOfTheLogRebuiltFromIt) {
  const CarmenLog& bag = Fr079FromBag();
  const CarmenLog log = ReadCarmenLog(testing::SharedFile("data/fr079-raw.log.gz"));
  EXPECT_EQ(bag.format, "ROS 1 bag");
  ASSERT_EQ(bag.scans.size(), 4934u);
  ASSERT_EQ(log.scans.size(), bag.scans.size());
  std::size_t beams = 0;
  for (std::size_t k = 0; k < bag.scans.size(); ++k) {
    const LogScan& b = bag.scans[k];
    const LogScan& l = log.scans[k];
    ASSERT_EQ(Microseconds(b.timestamp_s), Microseconds(l.timestamp_s)) << "scan " << k;
    ASSERT_EQ(b.size(), l.size()) << "scan " << k;
    for (std::size_t i = 0; i < b.size(); ++i, ++beams) {
      ASSERT_EQ(static_cast<float>(b.ranges_m[i]), static_cast<float>(l.ranges_m[i]));
      // The shortest decimal of the float32 is what the log's text holds: the same double.
      ASSERT_EQ(b.ranges_m[i], l.ranges_m[i]) << "scan " << k << " beam " << i;
      ASSERT_EQ(b.angles_rad[i], l.angles_rad[i]) << "scan " << k << " beam " << i;
      ASSERT_EQ(b.valid[i], l.valid[i]) << "scan " << k << " beam " << i;
    }
    const Pose2& bo = *b.odometry_pose;
    const Pose2& lo = *l.odometry_pose;
    ASSERT_NEAR(bo.x, lo.x, 1e-6) << "scan " << k;
    ASSERT_NEAR(bo.y, lo.y, 1e-6) << "scan " << k;
    ASSERT_NEAR(WrapAngle(bo.theta - lo.theta), 0.0, 1e-6) << "scan " << k;
    ASSERT_NEAR(b.logged_laser_pose.x, l.logged_laser_pose.x, 1e-6) << "scan " << k;
    ASSERT_NEAR(b.logged_laser_pose.y, l.logged_laser_pose.y, 1e-6) << "scan " << k;
    ASSERT_EQ(b.max_range_m, l.max_range_m);
  }
  EXPECT_EQ(beams, 4934u * 360u);
  EXPECT_EQ(bag.invalid_beams, log.invalid_beams);
  EXPECT_EQ(bag.no_return_beams, log.no_return_beams);
  // The log's ODOM lines are the /odom messages (6 decimals).
  ASSERT_EQ(bag.odometry.size(), log.odometry.size());
  for (std::size_t k = 0; k < bag.odometry.size(); ++k) {
    ASSERT_NEAR(bag.odometry[k].pose.x, log.odometry[k].pose.x, 1e-6);
    ASSERT_EQ(Microseconds(bag.odometry[k].timestamp_s), Microseconds(log.odometry[k].timestamp_s));
  }
}

TEST(Ros1Bag, Fr079ListsItsTopicsAndTakesTheLaserPoseFromTfStatic) {
  const CarmenLog bag = ReadRos1Bag(Fr079Bag());
  ASSERT_EQ(bag.topics.size(), 4u);
  const std::pair<const char*, std::size_t> expected[] = {
      {"/odom", 8951}, {"/scan", 4934}, {"/tf", 8951}, {"/tf_static", 1}};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(bag.topics[i].name, expected[i].first);
    EXPECT_EQ(bag.topics[i].messages, expected[i].second);
  }
  EXPECT_EQ(bag.topics[1].type, "sensor_msgs/LaserScan");
  // /tf_static: base_link -> laser at x = +0.04 m (the converter's sign; README).
  EXPECT_NEAR(bag.scans.at(0).T_robot_laser.x, 0.04, 1e-9);
  EXPECT_NEAR(bag.scans.at(0).T_robot_laser.y, 0.0, 1e-9);
  // Without the override the beams are where the messages put them: -pi/2 + i pi/359.
  EXPECT_NEAR(bag.scans[0].angles_rad.front(), -M_PI / 2, 1e-6);
  EXPECT_NEAR(bag.scans[0].angles_rad.back(), M_PI / 2, 1e-6);
  // The first scan precedes the first /odom message by 10 ms: held, and said so.
  ASSERT_FALSE(bag.warnings.empty());
  ExpectContains(bag.warnings.back(), "1 of 4934 scans lie before the first or after the last");
}

TEST(Ros1Bag, FrClinicReads) {
  const CarmenLog bag = ReadCarmenLog(testing::SharedFile("data/fr-clinic.orig.bag"));
  ASSERT_EQ(bag.scans.size(), 6917u);
  EXPECT_NEAR(bag.scans[0].T_robot_laser.x, 0.22, 1e-9);
  for (const LogScan& scan : bag.scans) ASSERT_TRUE(scan.odometry_pose.has_value());
  // Its 198 s odometry gap is reported.
  ASSERT_FALSE(bag.warnings.empty());
  ExpectContains(bag.warnings.back(), "scans lie in odometry gaps over 1.000 s");
}

TEST(Ros1Bag, ContentDecidesNotTheName) {
  const std::string renamed = WriteBytes("fr079.log.gz", ReadBytes(Fr079Bag()));
  EXPECT_EQ(ReadCarmenLogWithScans(renamed).scans.size(), 4934u);
}

TEST(Ros1Bag, AMissingScanTopicListsTheTopics) {
  BagInputConfig config;
  config.scan_topic = "/base_scan";
  const std::string error = ErrorOf(Fr079Bag(), config);
  ExpectContains(error, Fr079Bag());
  ExpectContains(error, "no topic /base_scan");
  ExpectContains(error, "/scan (sensor_msgs/LaserScan, 4934)");
  ExpectContains(error, "/odom (nav_msgs/Odometry, 8951)");
}

TEST(Ros1Bag, AMessageOfTheWrongTypeOnTheTopicIsNamed) {
  BagInputConfig config;
  config.scan_topic = "/odom";
  const std::string error = ErrorOf(Fr079Bag(), config);
  ExpectContains(error, Fr079Bag());
  ExpectContains(error, "topic /odom holds nav_msgs/Odometry messages, not sensor_msgs/LaserScan");
}

TEST(Ros1Bag, ATruncatedBagIsReadUpToItsLastCompleteChunk) {
  const std::string bytes = ReadBytes(Fr079Bag());
  const std::string cut = WriteBytes("cut.bag", bytes.substr(0, bytes.size() * 6 / 10));
  const CarmenLog log = ReadCarmenLog(cut, Reading(Fr079AsLog()));
  const CarmenLog& whole = Fr079FromBag();
  ASSERT_GT(log.scans.size(), 1000u);
  ASSERT_LT(log.scans.size(), whole.scans.size());
  for (std::size_t k = 0; k < log.scans.size(); ++k) {
    ASSERT_EQ(log.scans[k].timestamp_s, whole.scans[k].timestamp_s) << "scan " << k;
    ASSERT_EQ(log.scans[k].ranges_m, whole.scans[k].ranges_m) << "scan " << k;
  }
  ASSERT_FALSE(log.warnings.empty());
  ExpectContains(log.warnings.front(), cut + ": the bag's index is missing or damaged");
  ExpectContains(log.warnings.front(), "of the 20 it announces");
  ExpectContains(log.warnings.front(), "dropped an incomplete record at byte");
}

TEST(Ros1Bag, ABagCutBeforeItsFirstChunkEndsIsAnError) {
  const std::string cut = WriteBytes("stub.bag", ReadBytes(Fr079Bag()).substr(0, 6000));
  const std::string error = ErrorOf(cut, {});
  ExpectContains(error, cut + ": no complete chunk");
  ExpectContains(error, "rosbag cannot open it either");
}

// A cut bag's chunk claiming 512 MiB uncompressed from 95 kB of bz2 is refused before anything
// that large is allocated (laser data do not compress 1000-fold).
TEST(Ros1Bag, AChunkClaimingAnImplausibleSizeIsRefused) {
  std::string bytes = ReadBytes(Fr079Bag()).substr(0, 150000);
  const auto size_field = bytes.find("size=", bytes.find("compression=bz2"));
  ASSERT_NE(size_field, std::string::npos);
  bytes.replace(size_field + 5, 4, std::string("\0\0\0\x20", 4));
  const std::string path = WriteBytes("huge.bag", bytes);
  const std::string error = ErrorOf(path, {});
  ExpectContains(error, path + ": chunk at byte 4117: uncompressed size 536870912 from ");
}

TEST(Ros1Bag, AnUnknownCompressionIsNamed) {
  std::string bytes = ReadBytes(Fr079Bag());
  std::size_t patched = 0;
  for (auto at = bytes.find("compression=bz2"); at != std::string::npos;
       at = bytes.find("compression=bz2", at + 1)) {
    bytes.replace(at, 15, "compression=zst");
    ++patched;
  }
  ASSERT_EQ(patched, 20u);
  const std::string path = WriteBytes("zst.bag", bytes);
  const std::string error = ErrorOf(path, {});
  ExpectContains(error, path + ": topic /");
  ExpectContains(error, "zst");
}

}  // namespace
}  // namespace keyplace
