#include "keyplace/io/trajectory_file.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/test_data.hpp"

namespace keyplace {
namespace {

std::vector<double> Numbers(const std::string& line) {
  std::istringstream in(line);
  std::vector<double> numbers;
  for (double value = 0.0; in >> value;) numbers.push_back(value);
  return numbers;
}

// A heading of 90 degrees is the rotation by pi/2 about z: qz = qw = sqrt(2) / 2 (by hand), the
// other components 0; -135 degrees: qz = -sin(67.5 deg) = -0.9238795325112867, qw =
// cos(67.5 deg) = 0.3826834323650898.
TEST(TumTrajectory, HeadingIsTheRotationAboutZ) {
  const std::vector<double> left = Numbers(TumLine({1.5, Pose2(2.0, -3.0, M_PI / 2)}));
  ASSERT_EQ(left.size(), 8u);
  EXPECT_EQ(left[0], 1.5);
  EXPECT_EQ(left[1], 2.0);
  EXPECT_EQ(left[2], -3.0);
  EXPECT_EQ(left[3], 0.0);  // tz
  EXPECT_EQ(left[4], 0.0);  // qx
  EXPECT_EQ(left[5], 0.0);  // qy
  EXPECT_NEAR(left[6], std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(left[7], std::sqrt(0.5), 1e-15);
  const std::vector<double> back = Numbers(TumLine({0.0, Pose2(0.0, 0.0, -0.75 * M_PI)}));
  ASSERT_EQ(back.size(), 8u);
  EXPECT_NEAR(back[6], -0.9238795325112867, 1e-15);
  EXPECT_NEAR(back[7], 0.3826834323650898, 1e-15);
}

// Written to a file and read back by hand: the stamps and positions exactly (shortest text that
// reads back the same double), the heading from the quaternion to 1e-12.
TEST(TumTrajectory, AFileReadsBackAsTheSamePoses) {
  const std::vector<TrajectoryPose> poses = {{976052905.167303, Pose2(0.1 + 0.2, -7.25, 3.0)},
                                             {976052905.5, Pose2(12.0, 1e-7, -2.9)}};
  const std::string path = keyplace::testing::MakeTempDir("tum") + "/trajectory.tum";
  WriteTumTrajectory(path, poses);
  std::ifstream in(path);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "# timestamp tx ty tz qx qy qz qw");
  for (const TrajectoryPose& pose : poses) {
    ASSERT_TRUE(std::getline(in, line));
    const std::vector<double> row = Numbers(line);
    ASSERT_EQ(row.size(), 8u) << line;
    EXPECT_EQ(row[0], pose.timestamp_s);
    EXPECT_EQ(row[1], pose.T_world_robot.x);
    EXPECT_EQ(row[2], pose.T_world_robot.y);
    EXPECT_NEAR(2.0 * std::atan2(row[6], row[7]), pose.T_world_robot.theta, 1e-12);
  }
  EXPECT_FALSE(std::getline(in, line));
}

TEST(TumTrajectory, FormatNamesAndUnwritablePaths) {
  EXPECT_EQ(ParseTrajectoryFormat("tum"), TrajectoryFormat::kTum);
  EXPECT_EQ(ParseTrajectoryFormat("tsv"), TrajectoryFormat::kTsv);
  EXPECT_THROW(ParseTrajectoryFormat("TUM "), std::invalid_argument);
  try {
    WriteTumTrajectory("/nonexistent/dir/t.tum", {});
    FAIL() << "a write into a missing directory succeeded";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent/dir/t.tum"), std::string::npos);
  }
}

}  // namespace
}  // namespace keyplace
