#include "keyplace/eval/trajectory_error.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace keyplace {
namespace {

PairedTrajectory Straight(std::size_t n) {
  PairedTrajectory t;
  for (std::size_t i = 0; i < n; ++i) {
    t.truth.emplace_back(static_cast<double>(i), 0.0, 0.1 * i);
    t.estimated.push_back(t.truth.back());
    t.raw_index.push_back(i);
  }
  return t;
}

TEST(RelativePoseErrorCurve, ZeroForARigidlyMovedCopy) {
  PairedTrajectory t = Straight(20);
  const Pose2 A(3.0, -2.0, 0.7);
  for (Pose2& p : t.estimated) p = A * p;
  for (const RpePoint& point : RelativePoseErrorCurve(t, {1, 5, 19, 25})) {
    EXPECT_NEAR(point.translation_rmse_m, 0.0, 1e-9);
    EXPECT_NEAR(point.rotation_rmse_deg, 0.0, 1e-9);
    EXPECT_EQ(point.count, point.delta < 20 ? 20 - point.delta : 0u);
  }
  const AteSeries ate = AbsoluteTrajectoryErrors(t);
  EXPECT_NEAR(ate.translation_rmse_m, 0.0, 1e-9);
  EXPECT_NEAR(ate.rotation_rmse_deg, 0.0, 1e-9);
  EXPECT_NEAR(ate.points.back().path_length_m, 19.0, 1e-9);
}

TEST(RelativePoseErrorCurve, OneDisplacedPoseByHand) {
  // Straight line, no rotation; pose 5 displaced by 1 m sideways. For Delta = 1 the errors of the
  // intervals (4, 5) and (5, 6) are 1 m each, the other 7 are 0: RMSE = sqrt(2 / 9).
  PairedTrajectory t;
  for (int i = 0; i < 10; ++i) {
    t.truth.emplace_back(i, 0.0, 0.0);
    t.estimated.emplace_back(i, i == 5 ? 1.0 : 0.0, 0.0);
  }
  const std::vector<RpePoint> curve = RelativePoseErrorCurve(t, {1});
  EXPECT_EQ(curve[0].count, 9u);
  EXPECT_NEAR(curve[0].translation_rmse_m, std::sqrt(2.0 / 9.0), 1e-12);
  EXPECT_THROW(RelativePoseErrorCurve(t, {0}), std::invalid_argument);
}

TEST(PairTrajectory, SortsByCorrectedIndexAndChecksRanges) {
  const std::vector<Pose2> estimate{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  const std::vector<Pose2> corrected{{10, 0, 0}, {11, 0, 0}};
  const PairedTrajectory t = PairTrajectory(estimate, corrected, {{2, 1}, {0, 0}});
  ASSERT_EQ(t.estimated.size(), 2u);
  EXPECT_EQ(t.raw_index[0], 0u);
  EXPECT_DOUBLE_EQ(t.truth[1].x, 11.0);
  EXPECT_THROW(PairTrajectory(estimate, corrected, {{3, 0}}), std::invalid_argument);
  EXPECT_THROW(PairTrajectory(estimate, corrected, {{0, 2}}), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
