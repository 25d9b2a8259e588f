// Precision-recall curve, P_GL and P_CL on hand-made answer lists.

#include "keyplace/eval/localization.hpp"

#include <gtest/gtest.h>

namespace keyplace {
namespace {

TEST(Localization, CorrectPoseThresholds) {
  EXPECT_TRUE(IsCorrectPose(Pose2(0.3, 0.4, 0.0), Pose2(0, 0, 0)));  // 0.5 m exactly
  EXPECT_FALSE(IsCorrectPose(Pose2(0.3, 0.41, 0.0), Pose2(0, 0, 0)));
  EXPECT_TRUE(IsCorrectPose(Pose2(0, 0, M_PI - 0.1), Pose2(0, 0, -M_PI + 0.05)));  // wraps
  EXPECT_FALSE(IsCorrectPose(Pose2(0, 0, 0.2), Pose2(0, 0, 0)));                   // 11.5 deg
}

TEST(Localization, CurvePglPcl) {
  // 10 queries; 6 answered: scores 0.9 (ok), 0.8 (ok), 0.7 (wrong), 0.6 (ok), 0.6 (ok), 0.1 (wrong)
  const std::vector<RankedAnswer> answers = {
      {true, true, 0.9},   {true, true, 0.8},  {true, false, 0.7},  {true, true, 0.6},
      {true, true, 0.6},   {true, false, 0.1}, {false, false, 0.0}, {false, false, 0.0},
      {false, false, 0.0}, {false, false, 0.0}};
  const std::vector<PrPoint> curve = PrecisionRecallCurve(answers, 10);
  ASSERT_EQ(curve.size(), 5u);  // the two 0.6 enter together
  EXPECT_DOUBLE_EQ(curve[0].precision, 1.0);
  EXPECT_DOUBLE_EQ(curve[0].recall, 0.1);
  EXPECT_DOUBLE_EQ(curve[2].precision, 2.0 / 3.0);
  EXPECT_EQ(curve[3].accepted, 5u);
  EXPECT_DOUBLE_EQ(curve[3].precision, 0.8);
  EXPECT_DOUBLE_EQ(curve[3].recall, 0.4);
  // Max recall 0.4 first reached at 5 accepted (precision 0.8), later 4/6.
  EXPECT_DOUBLE_EQ(PrecisionAtMaxRecall(curve), 0.8);
  EXPECT_DOUBLE_EQ(RecallAtPrecision(curve, 0.95), 0.2);
  EXPECT_DOUBLE_EQ(RecallAtPrecision(curve, 0.8), 0.4);
  EXPECT_DOUBLE_EQ(PrecisionAtMaxRecall({}), 0.0);
}

}  // namespace
}  // namespace keyplace
