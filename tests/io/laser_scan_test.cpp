#include "keyplace/io/laser_scan.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace keyplace {
namespace {

TEST(MakeLaserScan, MarksBeamsValidAsTheReadersDo) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const LaserScan scan =
      MakeLaserScan({1.0, 0.0, -1.0, nan, 80.0, 79.9}, {0, 0.1, 0.2, 0.3, 0.4, 0.5}, 80.0, 12.5,
                    Pose2(0.1, 0.0, 0.0));
  EXPECT_EQ(scan.valid, (std::vector<std::uint8_t>{1, 0, 0, 0, 0, 1}));
  EXPECT_EQ(scan.CountValid(), 2u);
  EXPECT_DOUBLE_EQ(scan.max_range_m, 80.0);
  EXPECT_DOUBLE_EQ(scan.timestamp_s, 12.5);
  EXPECT_DOUBLE_EQ(scan.T_robot_laser.x, 0.1);
  EXPECT_DOUBLE_EQ(scan.angles_rad[5], 0.5);
}

TEST(MakeLaserScan, RejectsMismatchedOrBadGeometry) {
  EXPECT_THROW(MakeLaserScan({1.0, 2.0}, {0.0}, 10.0), std::invalid_argument);
  EXPECT_THROW(MakeLaserScan({1.0}, {0.0}, 0.0), std::invalid_argument);
  EXPECT_THROW(MakeLaserScan({1.0}, {std::numeric_limits<double>::infinity()}, 10.0),
               std::invalid_argument);
  EXPECT_THROW(MakeLaserScan(std::vector<double>(kMaxScanBeams + 1, 1.0),
                             std::vector<double>(kMaxScanBeams + 1, 0.0), 10.0),
               std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
