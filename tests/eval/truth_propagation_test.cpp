#include "keyplace/eval/truth_propagation.hpp"

#include <cmath>
#include <optional>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace keyplace {
namespace {

// Odometry drives 1 m along x per scan; the corrected frame is rotated by a quarter turn and
// shifted, so a propagated pose that ignored either would land elsewhere.
std::vector<Pose2> StraightOdometry(int n) {
  std::vector<Pose2> poses;
  for (int k = 0; k < n; ++k) poses.emplace_back(1.0 * k, 0.0, 0.0);
  return poses;
}

Pose2 TruthOf(int k) { return Pose2(10.0, 20.0, M_PI / 2) * Pose2(1.0 * k, 0.0, 0.0); }

TEST(PropagateTruth, MovesTheNearestCorrectedPoseByTheOdometry) {
  const std::vector<Pose2> odometry = StraightOdometry(10);
  std::vector<std::optional<Pose2>> corrected(10);
  corrected[2] = TruthOf(2);
  corrected[7] = TruthOf(7);
  const auto truth = PropagateTruth(corrected, odometry, 3);
  ASSERT_EQ(truth.size(), 10u);
  for (int k = 0; k < 10; ++k) {
    ASSERT_TRUE(truth[k].has_value()) << k;
    const Pose2 expected = TruthOf(k);
    EXPECT_NEAR(truth[k]->T_world_robot.x, expected.x, 1e-9) << k;
    EXPECT_NEAR(truth[k]->T_world_robot.y, expected.y, 1e-9) << k;
    EXPECT_NEAR(truth[k]->T_world_robot.theta, expected.theta, 1e-9) << k;
  }
  EXPECT_EQ(truth[2]->gap, 0);
  EXPECT_EQ(truth[0]->source, 2);
  EXPECT_EQ(truth[5]->source, 7);  // 2 away from 7, 3 away from 2
  EXPECT_EQ(truth[5]->gap, 2);
  EXPECT_EQ(truth[9]->source, 7);
}

TEST(PropagateTruth, EarlierSourceWinsATieAndFarScansGetNone) {
  const std::vector<Pose2> odometry = StraightOdometry(12);
  std::vector<std::optional<Pose2>> corrected(12);
  corrected[2] = TruthOf(2);
  corrected[6] = TruthOf(6);
  const auto truth = PropagateTruth(corrected, odometry, 2);
  EXPECT_EQ(truth[4]->source, 2);
  EXPECT_FALSE(truth[9].has_value());  // 3 scans from the nearest corrected pose
  EXPECT_TRUE(truth[8].has_value());
  EXPECT_FALSE(PropagateTruth(corrected, odometry, 0)[3].has_value());
}

TEST(PropagateTruth, RejectsBadArguments) {
  EXPECT_THROW(PropagateTruth(std::vector<std::optional<Pose2>>(3), StraightOdometry(2), 1),
               std::invalid_argument);
  EXPECT_THROW(PropagateTruth(std::vector<std::optional<Pose2>>(2), StraightOdometry(2), -1),
               std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
