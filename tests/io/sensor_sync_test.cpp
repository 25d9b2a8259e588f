// Scans paired with odometry at their stamps, as a robot node receives two topics (issue 33): the
// pose interpolated at the scan's stamp, scans waiting and dropped, and the inputs a driver or a
// bag sends that are not scans, each dropped with a reason and never thrown.

#include "keyplace/io/sensor_sync.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/expect_contains.hpp"

namespace keyplace {
namespace {

using testing::ExpectContains;

BagInputConfig InputWithLaserOnTheRobot() {
  BagInputConfig input;
  input.laser_pose = "0.1,0,0";
  return input;
}

ScanInput Scan(double stamp_s, std::size_t beams = 181) {
  ScanInput scan;
  scan.stamp_s = stamp_s;
  scan.frame_id = "laser";
  scan.angle_min_rad = -M_PI / 2.0;
  scan.angle_increment_rad = M_PI / 180.0;
  scan.range_min_m = 0.1;
  scan.range_max_m = 30.0;
  scan.ranges_m.assign(beams, 2.0F);
  return scan;
}

std::string Joined(const std::vector<NodeEvent>& events) {
  std::string text;
  for (const NodeEvent& event : events) text += event.what + "\n";
  return text;
}

TEST(SensorSync, AScanWaitsForOdometryAndGetsThePoseInterpolatedAtItsStamp) {
  SensorSync sync(InputWithLaserOnTheRobot(), 1.0);
  EXPECT_TRUE(sync.AddOdometry({10.0, Pose2(0.0, 0.0, 0.0)}).scans.empty());
  SyncOutput waiting = sync.AddScan(Scan(10.25));
  EXPECT_TRUE(waiting.scans.empty());
  EXPECT_EQ(sync.scans_waiting(), 1U);
  const SyncOutput released = sync.AddOdometry({10.5, Pose2(1.0, 2.0, 0.4)});
  ASSERT_EQ(released.scans.size(), 1U);
  const SyncedScan& synced = released.scans.front();
  EXPECT_NEAR(synced.T_odom_robot.x, 0.5, 1e-12);
  EXPECT_NEAR(synced.T_odom_robot.y, 1.0, 1e-12);
  EXPECT_NEAR(synced.T_odom_robot.theta, 0.2, 1e-12);
  EXPECT_EQ(synced.frame_id, "laser");
  EXPECT_EQ(synced.scan.timestamp_s, 10.25);
  EXPECT_NEAR(synced.scan.T_robot_laser.x, 0.1, 1e-12);
  EXPECT_EQ(sync.scans_waiting(), 0U);
  EXPECT_EQ(sync.scans_dropped(), 0U);
}

TEST(SensorSync, TheHeadingIsInterpolatedAlongTheShorterTurn) {
  SensorSync sync(InputWithLaserOnTheRobot(), 1.0);
  sync.AddOdometry({0.0, Pose2(0.0, 0.0, M_PI - 0.1)});
  sync.AddScan(Scan(0.5));
  const SyncOutput released = sync.AddOdometry({1.0, Pose2(0.0, 0.0, -M_PI + 0.1)});
  ASSERT_EQ(released.scans.size(), 1U);
  EXPECT_NEAR(std::abs(released.scans.front().T_odom_robot.theta), M_PI, 1e-9);
}

TEST(SensorSync, ScansWithoutOdometryAreDroppedSayingWhy) {
  SensorSync sync(InputWithLaserOnTheRobot(), 1.0);
  sync.AddOdometry({5.0, Pose2()});
  // Before the first odometry pose: dropped once odometry is known to start after it.
  SyncOutput before = sync.AddScan(Scan(4.0));
  ExpectContains(Joined(before.events), "precedes the first odometry pose");
  // Odometry stops: the scan waits, and a scan 1 s newer drops it.
  sync.AddScan(Scan(5.5));
  EXPECT_EQ(sync.scans_waiting(), 1U);
  SyncOutput later = sync.AddScan(Scan(6.6));
  ExpectContains(Joined(later.events), "scan at 5.500000 dropped: no odometry at its stamp");
  EXPECT_EQ(sync.scans_dropped(), 2U);
  EXPECT_EQ(sync.scans_waiting(), 1U);
  EXPECT_EQ(sync.scans_received(), 3U);
}

TEST(SensorSync, HostileScansAreDroppedWithTheirReason) {
  SensorSync sync(InputWithLaserOnTheRobot(), 1.0);
  sync.AddOdometry({0.0, Pose2()});
  double stamp_s = 1.0;
  // Each scan is stamped after the last one unless it carries a stamp of its own.
  const auto expect_dropped = [&](ScanInput scan, const std::string& reason) {
    if (scan.stamp_s == 0.0) scan.stamp_s = stamp_s;
    stamp_s += 0.1;
    const std::size_t dropped = sync.scans_dropped();
    SyncOutput output;
    EXPECT_NO_THROW(output = sync.AddScan(scan));
    EXPECT_EQ(sync.scans_dropped(), dropped + 1) << reason;
    ExpectContains(Joined(output.events), reason);
  };
  expect_dropped(Scan(0.0, 0), "it has no beams");
  expect_dropped(Scan(0.0, 9000), "9000 beams, more than the");
  ScanInput no_range = Scan(0.0);
  no_range.range_max_m = std::numeric_limits<double>::infinity();
  expect_dropped(no_range, "range_max must be positive and finite");
  ScanInput one_bearing = Scan(0.0);
  one_bearing.angle_increment_rad = 0.0;
  expect_dropped(one_bearing, "does not spread them over at most one turn");
  ScanInput far_angle = Scan(0.0);
  far_angle.angle_min_rad = 1e30;
  expect_dropped(far_angle, "is not an angle in [-2 pi, 2 pi]");
  ScanInput nan_angle = Scan(0.0);
  nan_angle.angle_increment_rad = std::nan("");
  expect_dropped(nan_angle, "angle_min and angle_increment must be finite");
  expect_dropped(Scan(std::nan("")), "a scan with a stamp that is not finite dropped");
  // A scan that goes back in time.
  sync.AddScan(Scan(stamp_s));
  expect_dropped(Scan(0.5), "out of order or repeated");
  // Without a laser pose (no tf, no input.laser_pose).
  SensorSync no_tf(BagInputConfig{}, 1.0);
  const SyncOutput output = no_tf.AddScan(Scan(1.0));
  ExpectContains(Joined(output.events), "no laser pose for frame 'laser'");
  EXPECT_EQ(no_tf.scans_dropped(), 1U);
}

TEST(SensorSync, NanRangesAreInvalidBeamsNotADroppedScan) {
  SensorSync sync(InputWithLaserOnTheRobot(), 1.0);
  ScanInput scan = Scan(1.0, 5);
  scan.ranges_m = {std::nanf(""), 0.05F, 2.0F, 30.0F, std::numeric_limits<float>::infinity()};
  sync.AddScan(scan);
  const SyncOutput released = sync.AddOdometry({1.0, Pose2()});
  ASSERT_EQ(released.scans.size(), 1U);
  EXPECT_EQ(released.scans.front().scan.valid, (std::vector<std::uint8_t>{0, 0, 1, 0, 0}));
}

TEST(SensorSync, HostileOdometryIsDroppedWithItsReason) {
  SensorSync sync(InputWithLaserOnTheRobot(), 1.0);
  sync.AddOdometry({1.0, Pose2()});
  ExpectContains(Joined(sync.AddOdometry({1.0, Pose2()}).events), "out of order or repeated");
  ExpectContains(Joined(sync.AddOdometry({2.0, Pose2(2e7, 0.0, 0.0)}).events), "beyond +-1e7 m");
  ExpectContains(Joined(sync.AddOdometry({std::nan(""), Pose2()}).events), "not finite");
  EXPECT_EQ(sync.odometry_dropped(), 3U);
  // A jump of 1e5 m is a pose, not a corrupt message: the node decides what it means.
  EXPECT_TRUE(sync.AddOdometry({3.0, Pose2(1e5, 0.0, 0.0)}).events.empty());
}

TEST(SensorSync, AFieldOfViewSpreadsTheBeamsAsAFlaserLine) {
  BagInputConfig input = InputWithLaserOnTheRobot();
  input.scan_fov_rad = M_PI;
  SensorSync sync(input, 1.0);
  sync.AddOdometry({0.0, Pose2()});
  ScanInput scan = Scan(0.5, 361);
  scan.angle_increment_rad = M_PI / 361.0;  // a driver's wrong increment, overridden
  sync.AddScan(scan);
  const SyncOutput released = sync.AddOdometry({1.0, Pose2()});
  ASSERT_EQ(released.scans.size(), 1U);
  const std::vector<double>& angles = released.scans.front().scan.angles_rad;
  // 361 beams over 180 degrees: 0.5 degree apart, from -90 to +90 degrees.
  EXPECT_NEAR(angles.front(), -M_PI / 2.0, 1e-12);
  EXPECT_NEAR(angles.back(), M_PI / 2.0, 1e-12);
  EXPECT_NEAR(angles[1] - angles[0], M_PI / 360.0, 1e-12);
}

TEST(SensorSync, AGeometryChangeIsAWarningAndTheScanIsKept) {
  SensorSync sync(InputWithLaserOnTheRobot(), 1.0);
  ExpectContains(Joined(sync.AddScan(Scan(1.0, 181)).events), "first scan: frame 'laser', 181");
  EXPECT_TRUE(sync.AddScan(Scan(1.1, 181)).events.empty());
  const SyncOutput changed = sync.AddScan(Scan(1.2, 360));
  ASSERT_EQ(changed.events.size(), 1U);
  EXPECT_EQ(changed.events.front().level, NodeEventLevel::kWarning);
  ExpectContains(changed.events.front().what, "the scan geometry changed from");
  EXPECT_EQ(sync.scans_waiting(), 3U);
}

TEST(SensorSync, RefusesAWaitThatIsNotPositive) {
  EXPECT_THROW(SensorSync(BagInputConfig{}, 0.0), std::invalid_argument);
  BagInputConfig bad;
  bad.scan_fov_rad = -1.0;
  EXPECT_THROW(SensorSync(bad, 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
