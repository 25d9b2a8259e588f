// The ROS 1 bag reader on small bags this test writes with Debian's rosbag library: odometry from
// /tf (a chain, heading across +-pi), the laser pose from /tf_static or the option, beam
// validity, the three chunk compressions, and the errors for missing or mistyped topics.

#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "keyplace/io/carmen_log.hpp"
#include "keyplace/io/ros1_bag.hpp"
#include "support/expect_contains.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

geometry_msgs::Quaternion Heading(double theta_rad) {
  geometry_msgs::Quaternion q;
  q.z = std::sin(theta_rad / 2);
  q.w = std::cos(theta_rad / 2);
  return q;
}

sensor_msgs::LaserScan Scan(double stamp_s, const std::string& frame) {
  sensor_msgs::LaserScan scan;
  scan.header.stamp = ros::Time(stamp_s);
  scan.header.frame_id = frame;
  scan.angle_min = -0.5F;
  scan.angle_increment = 0.25F;
  scan.range_min = 0.1F;
  scan.range_max = 10.0F;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  scan.ranges = {nan, 0.05F, 1.25F, 10.0F, inf};
  return scan;
}

nav_msgs::Odometry Odometry(double stamp_s, double x, double y, double theta) {
  nav_msgs::Odometry odometry;
  odometry.header.stamp = ros::Time(stamp_s);
  odometry.pose.pose.position.x = x;
  odometry.pose.pose.position.y = y;
  odometry.pose.pose.orientation = Heading(theta);
  return odometry;
}

tf2_msgs::TFMessage Transform(double stamp_s, const std::string& parent, const std::string& child,
                              double x, double y, double theta) {
  geometry_msgs::TransformStamped transform;
  transform.header.stamp = ros::Time(stamp_s);
  transform.header.frame_id = parent;
  transform.child_frame_id = child;
  transform.transform.translation.x = x;
  transform.transform.translation.y = y;
  transform.transform.rotation = Heading(theta);
  tf2_msgs::TFMessage message;
  message.transforms.push_back(transform);
  return message;
}

// What to put in a bag.
struct Content {
  bool odom_topic = false;
  bool tf_odometry = false;
  bool tf_laser = false;
  bool scan_on_odom_topic = false;
  rosbag::compression::CompressionType compression = rosbag::compression::Uncompressed;
};

std::string WriteBag(const std::string& name, const Content& content) {
  std::string path = testing::MakeTempDir("written") + "/" + name;
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  bag.setCompression(content.compression);
  const ros::Time t10(10.0);
  if (content.tf_laser) {
    bag.write("/tf_static", t10, Transform(10.0, "base_link", "laser", 0.1, 0.2, 0.5));
  }
  if (content.tf_odometry) {
    // odom -> base_footprint moves; base_footprint -> base_link is fixed (a chain of two).
    bag.write("/tf_static", t10, Transform(10.0, "base_footprint", "base_link", 0.5, 0.0, 0.0));
    bag.write("/tf", t10, Transform(10.0, "odom", "base_footprint", 0.0, 0.0, 3.0));
    bag.write("/tf", ros::Time(12.0), Transform(12.0, "odom", "base_footprint", 2.0, 4.0, -3.0));
  }
  if (content.odom_topic) {
    bag.write("/odom", t10, Odometry(10.0, 0.0, 0.0, 3.0));
    bag.write("/odom", ros::Time(12.0), Odometry(12.0, 2.0, 4.0, -3.0));
  }
  if (content.scan_on_odom_topic) bag.write("/odom", t10, Scan(10.0, "laser"));
  bag.write("/scan", ros::Time(11.0), Scan(11.0, "/laser"));  // tf2 drops the leading slash
  bag.close();
  return path;
}

std::string ErrorOf(const std::string& path, const BagInputConfig& config = {}) {
  try {
    ReadRos1Bag(path, config);
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "no error";
}

using testing::ExpectContains;

TEST(Ros1BagWritten, OdometryFromATfChainInterpolatedOnTheCircle) {
  Content content;
  content.tf_odometry = content.tf_laser = true;
  const std::string path = WriteBag("tf.bag", content);
  const CarmenLog log = ReadCarmenLog(path);
  ASSERT_EQ(log.scans.size(), 1u);
  // Halfway from heading 3.0 to -3.0 along the shorter turn is pi, not 0; the fixed
  // base_footprint -> base_link (0.5 m ahead) then points back along -x.
  const Pose2 odometry = *log.scans[0].odometry_pose;
  EXPECT_NEAR(odometry.x, 1.0 - 0.5, 1e-9);
  EXPECT_NEAR(odometry.y, 2.0, 1e-9);
  EXPECT_NEAR(WrapAngle(odometry.theta - M_PI), 0.0, 1e-9);
  const Pose2 laser = log.scans[0].T_robot_laser;
  EXPECT_NEAR(laser.x, 0.1, 1e-9);
  EXPECT_NEAR(laser.y, 0.2, 1e-9);
  EXPECT_NEAR(laser.theta, 0.5, 1e-9);
  ASSERT_EQ(log.odometry.size(), 2u);  // the chain at its two stamps
  EXPECT_NEAR(log.odometry[1].pose.x, 2.0 + 0.5 * std::cos(-3.0), 1e-9);
  ExpectContains(log.warnings.at(0),
                 path + ": no topic /odom: odometry from /tf odom -> base_link");
}

TEST(Ros1BagWritten, BeamsBelowMinimumOrNaNAreInvalidAtOrBeyondMaximumNoReturn) {
  Content content;
  content.odom_topic = content.tf_laser = true;
  const CarmenLog log = ReadRos1Bag(WriteBag("beams.bag", content));
  const LogScan& scan = log.scans.at(0);
  EXPECT_EQ(scan.valid, (std::vector<std::uint8_t>{0, 0, 1, 0, 0}));
  EXPECT_EQ(log.invalid_beams, 2u);
  EXPECT_EQ(log.no_return_beams, 2u);
  EXPECT_EQ(scan.ranges_m[2], 1.25);
  EXPECT_EQ(scan.angles_rad[4], -0.5 + 4 * 0.25);
  EXPECT_EQ(scan.max_range_m, 10.0);
  EXPECT_EQ(scan.timestamp_s, 11.0);
  // /odom interpolated halfway: (1, 2), heading pi.
  EXPECT_NEAR(scan.odometry_pose->x, 1.0, 1e-9);
  EXPECT_NEAR(std::abs(scan.odometry_pose->theta), M_PI, 1e-9);
}

TEST(Ros1BagWritten, EveryChunkCompressionReadsTheSame) {
  Content content;
  content.odom_topic = content.tf_laser = true;
  const CarmenLog plain = ReadRos1Bag(WriteBag("none.bag", content));
  for (const auto compression : {rosbag::compression::BZ2, rosbag::compression::LZ4}) {
    content.compression = compression;
    const CarmenLog log = ReadRos1Bag(WriteBag("compressed.bag", content));
    ASSERT_EQ(log.scans.size(), 1u);
    EXPECT_EQ(log.scans[0].ranges_m.size(), plain.scans[0].ranges_m.size());
    EXPECT_EQ(log.scans[0].ranges_m[2], plain.scans[0].ranges_m[2]);
    EXPECT_EQ(log.scans[0].odometry_pose->x, plain.scans[0].odometry_pose->x);
  }
}

TEST(Ros1BagWritten, TheLaserPoseOptionOverridesTf) {
  Content content;
  content.odom_topic = content.tf_laser = true;
  BagInputConfig config;
  config.laser_pose = "-0.04,0,0";
  const CarmenLog log = ReadRos1Bag(WriteBag("override.bag", content), config);
  EXPECT_EQ(log.scans.at(0).T_robot_laser.x, -0.04);
  EXPECT_EQ(log.scans.at(0).T_robot_laser.theta, 0.0);
}

TEST(Ros1BagWritten, NoLaserPoseIsAnErrorSuggestingTheOption) {
  Content content;
  content.odom_topic = true;
  const std::string path = WriteBag("nolaser.bag", content);
  const std::string error = ErrorOf(path);
  ExpectContains(error, path + ": no transform base_link -> laser");
  ExpectContains(error, "--laser-pose x,y,theta");
  BagInputConfig config;
  config.laser_pose = "0.1,0,0";
  EXPECT_EQ(ReadRos1Bag(path, config).scans.at(0).T_robot_laser.x, 0.1);
}

TEST(Ros1BagWritten, NoOdometryIsAnErrorNamingTopicAndFrames) {
  Content content;
  content.tf_laser = true;
  const std::string path = WriteBag("noodom.bag", content);
  const std::string error = ErrorOf(path);
  ExpectContains(error, path + ": no odometry: no topic /odom");
  ExpectContains(error, "transform chain odom -> base_link");
  ExpectContains(error, "base_link -> laser (static)");
  ExpectContains(error, "/scan (sensor_msgs/LaserScan, 1)");
}

TEST(Ros1BagWritten, AScanOnTheOdometryTopicIsAnErrorNamingBoth) {
  Content content;
  content.tf_laser = content.scan_on_odom_topic = true;
  const std::string path = WriteBag("mistyped.bag", content);
  ExpectContains(ErrorOf(path), path + ": topic /odom holds sensor_msgs/LaserScan messages, not " +
                                    "nav_msgs/Odometry");
}

// Issue 31: a frame id of a megabyte was printed whole (1.35 GB of messages). Frame ids longer
// than 1024 bytes are refused, the message showing the start only.
TEST(Ros1BagWritten, AFrameIdOfAMegabyteIsRefusedAndShownShort) {
  const std::string huge(std::size_t{1} << 20, 'f');
  for (const bool in_tf : {false, true}) {
    const std::string path = testing::MakeTempDir("frame") + "/frame.bag";
    {
      rosbag::Bag bag(path, rosbag::bagmode::Write);
      bag.write("/tf_static", ros::Time(10.0),
                Transform(10.0, "base_link", in_tf ? huge : "laser", 0.1, 0.2, 0.5));
      bag.write("/odom", ros::Time(10.0), Odometry(10.0, 0.0, 0.0, 0.0));
      bag.write("/odom", ros::Time(12.0), Odometry(12.0, 1.0, 0.0, 0.0));
      bag.write("/scan", ros::Time(11.0), Scan(11.0, in_tf ? "laser" : huge));
    }
    const std::string error = ErrorOf(path);
    ExpectContains(error, "is longer than 1024 bytes: not a frame id");
    EXPECT_LT(error.size(), 600U) << (in_tf ? "tf" : "scan");
  }
}

// Names and frames listed in a message come from the bag: at most 20 of them are shown.
TEST(Ros1BagWritten, ListsOfTopicsAndTransformsStopAtTwenty) {
  const std::string path = testing::MakeTempDir("lists") + "/lists.bag";
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    for (int i = 0; i < 30; ++i) {
      const std::string name = "frame" + std::to_string(100 + i);
      bag.write("/topic" + std::to_string(100 + i), ros::Time(10.0), Odometry(10.0, 0.0, 0.0, 0.0));
      bag.write("/tf_static", ros::Time(10.0), Transform(10.0, "base_link", name, 0, 0, 0));
    }
    bag.write("/scan", ros::Time(11.0), Scan(11.0, "frame100"));
  }
  const std::string error = ErrorOf(path);  // no odometry: names topics and transforms
  ExpectContains(error, "no odometry");
  ExpectContains(error, ", and 12 more");  // 32 topics: /scan, /tf_static and the 30
  ExpectContains(error, ", and 10 more");  // 30 transforms
  std::size_t listed_frames = 0;
  for (std::size_t at = error.find("base_link -> frame"); at != std::string::npos;
       at = error.find("base_link -> frame", at + 1)) {
    ++listed_frames;
  }
  EXPECT_EQ(listed_frames, 20U) << error;
}

}  // namespace
}  // namespace keyplace
