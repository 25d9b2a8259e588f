#include "keyplace/io/timestamps.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace keyplace {
namespace {

std::vector<double> Steady(std::size_t count, double start_s = 976055000.0) {
  std::vector<double> stamps;
  for (std::size_t i = 0; i < count; ++i) stamps.push_back(start_s + 0.2 * static_cast<double>(i));
  return stamps;
}

TEST(CheckTimestamps, SteadyStampsOrderTheScansWithoutAWord) {
  const TimestampCheck check = CheckTimestamps(Steady(200));
  EXPECT_TRUE(check.CanOrder());
  EXPECT_TRUE(check.warnings.empty());
  EXPECT_NEAR(check.median_step_s, 0.2, 1e-6);
  EXPECT_NO_THROW(RequireTimeOrder(check, "log"));
}

TEST(CheckTimestamps, ZeroStampsCannotOrder) {
  std::vector<double> stamps = Steady(200);
  stamps[50] = 0.0;
  const TimestampCheck check = CheckTimestamps(stamps);
  EXPECT_EQ(check.zero, 1u);
  EXPECT_FALSE(check.CanOrder());
  // A leading 0 (FR079's raw log starts with one) sorts first anyway: noted, not refused.
  std::vector<double> leading = Steady(200);
  leading[0] = 0.0;
  const TimestampCheck leading_check = CheckTimestamps(leading);
  EXPECT_EQ(leading_check.zero, 1u);
  EXPECT_TRUE(leading_check.CanOrder());
  EXPECT_EQ(leading_check.warnings.size(), 1u);
  const TimestampCheck all_zero = CheckTimestamps(std::vector<double>(10, 0.0));
  EXPECT_EQ(all_zero.zero, 10u);
  EXPECT_EQ(all_zero.repeated, 9u);
  EXPECT_FALSE(all_zero.CanOrder());
}

TEST(CheckTimestamps, StampsKeptToSixDigitsRepeatAndCannotOrder) {
  std::vector<double> stamps = Steady(200);
  for (double& stamp : stamps) stamp = std::round(stamp / 1000.0) * 1000.0;  // 9.76055e8
  const TimestampCheck check = CheckTimestamps(stamps);
  EXPECT_GT(check.repeated, 100u);
  EXPECT_FALSE(check.CanOrder());
  try {
    RequireTimeOrder(check, "x.log: the logger timestamps");
    FAIL() << "coarse stamps were accepted";
  } catch (const std::invalid_argument& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("x.log"), std::string::npos) << message;
    EXPECT_NE(message.find("--order file"), std::string::npos) << message;
    EXPECT_NE(message.find("repeat"), std::string::npos) << message;
  }
}

TEST(CheckTimestamps, AFewRepeatsAndBackwardStepsStillOrder) {
  std::vector<double> stamps = Steady(200);
  stamps[10] = stamps[9];             // 1 repeat in 200: a stable sort keeps file order
  std::swap(stamps[20], stamps[21]);  // out of file order: sorting fixes it
  const TimestampCheck check = CheckTimestamps(stamps);
  EXPECT_EQ(check.repeated, 1u);
  EXPECT_EQ(check.backwards, 1u);
  EXPECT_TRUE(check.CanOrder());
  EXPECT_EQ(check.warnings.size(), 2u);
}

TEST(CheckTimestamps, AWrappedCounterCannotOrder) {
  std::vector<double> stamps = Steady(20, 4294967295.0);
  for (double& stamp : stamps) {
    if (stamp >= 4294967296.0) stamp -= 4294967296.0;
  }
  const TimestampCheck check = CheckTimestamps(stamps);
  EXPECT_EQ(check.wraps, 1u);
  EXPECT_EQ(check.backwards, 0u);
  EXPECT_FALSE(check.CanOrder());
}

}  // namespace
}  // namespace keyplace
