#include "keyplace/common/pose2.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace keyplace {
namespace {

TEST(WrapAngle, MapsIntoHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(WrapAngle(M_PI), M_PI);
  EXPECT_DOUBLE_EQ(WrapAngle(-M_PI), M_PI);  // -pi is excluded, maps to +pi
  EXPECT_NEAR(WrapAngle(3.0 * M_PI / 2.0), -M_PI / 2.0, 1e-12);
  EXPECT_NEAR(WrapAngle(-5.0 * M_PI / 2.0), -M_PI / 2.0, 1e-12);
  EXPECT_NEAR(WrapAngle(0.25), 0.25, 1e-15);
}

TEST(Pose2, CompositionMatchesHandComputation) {
  const Pose2 T_a_b(1.0, 2.0, M_PI / 2.0);
  const Pose2 T_b_c(3.0, 0.0, M_PI / 2.0);
  const Pose2 T_a_c = T_a_b * T_b_c;
  // c's origin is 3 m along b's x axis, which points along a's y axis.
  EXPECT_NEAR(T_a_c.x, 1.0, 1e-12);
  EXPECT_NEAR(T_a_c.y, 5.0, 1e-12);
  EXPECT_NEAR(T_a_c.theta, M_PI, 1e-12);
}

TEST(Pose2, InverseUndoesComposition) {
  const Pose2 T_a_b(-0.7, 4.2, 2.9);
  const Pose2 identity = T_a_b * T_a_b.inverse();
  EXPECT_NEAR(identity.x, 0.0, 1e-12);
  EXPECT_NEAR(identity.y, 0.0, 1e-12);
  EXPECT_NEAR(identity.theta, 0.0, 1e-12);
  const Eigen::Vector2d point_b(0.3, -1.1);
  const Eigen::Vector2d back = T_a_b.inverse() * (T_a_b * point_b);
  EXPECT_NEAR((back - point_b).norm(), 0.0, 1e-12);
}

TEST(Pose2, BetweenGivesRelativePose) {
  const Pose2 from(1.0, 1.0, M_PI / 2.0);
  const Pose2 to(1.0, 3.0, M_PI / 2.0);
  const Pose2 relative = Between(from, to);
  EXPECT_NEAR(relative.x, 2.0, 1e-12);  // 2 m straight ahead of `from`
  EXPECT_NEAR(relative.y, 0.0, 1e-12);
  EXPECT_NEAR(relative.theta, 0.0, 1e-12);
}

}  // namespace
}  // namespace keyplace
