// A fix as the /initialpose message (issue 16): the pose, its quaternion and the covariance the
// fix filter holds, in YAML that ROS tools parse and in JSON.

#include <cmath>
#include <fstream>
#include <iterator>
#include <optional>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "keyplace/localization/initial_pose.hpp"
#include "keyplace/localization/relocalizer.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

LocalizationResult Answer(const Pose2& T_world_odom) {
  LocalizationResult answer;
  answer.found = true;
  answer.confidence = 0.5;
  answer.T_world_odom = T_world_odom;
  return answer;
}

Pose2 Odometry(int scan) { return {0.25 * scan, 0.0, 0.0}; }

const Pose2 kTrue(10.0, 5.0, 2.8);

// Two agreeing answers make a fix at scan 6.
FixFilter FixedFilter(const FixPolicy& policy) {
  FixFilter filter(policy);
  filter.Update(Answer(kTrue), Odometry(0));
  const RelocalizationUpdate update = filter.Update(Answer(kTrue), Odometry(6));
  EXPECT_EQ(update.status, FixStatus::kFixed);
  return filter;
}

TEST(InitialPose, TheCovarianceIsTheFiltersAndGrowsWithUnconfirmedTravel) {
  const FixPolicy policy;
  FixFilter filter = FixedFilter(policy);
  const RelocalizationUpdate at_fix = filter.Update(std::nullopt, Odometry(6));
  const double answer_sigma_m = 0.5 * policy.agree_m;
  EXPECT_NEAR(at_fix.position_variance_m2, answer_sigma_m * answer_sigma_m, 1e-12);
  const double heading_sigma_rad = 0.5 * policy.agree_deg * M_PI / 180.0;
  EXPECT_NEAR(at_fix.heading_variance_rad2, heading_sigma_rad * heading_sigma_rad, 1e-12);
  // 10 m later without a confirmation the drift allowance adds (agree_per_m * 10 m)^2.
  const RelocalizationUpdate later = filter.Update(std::nullopt, Odometry(46));
  ASSERT_EQ(later.status, FixStatus::kFixed);
  const double drift_m = policy.agree_per_m * 10.0;
  EXPECT_NEAR(later.position_variance_m2, answer_sigma_m * answer_sigma_m + drift_m * drift_m,
              1e-12);
  EXPECT_GT(later.heading_variance_rad2, at_fix.heading_variance_rad2);
  // A confirmation shrinks it again.
  const RelocalizationUpdate confirmed = filter.Update(Answer(kTrue), Odometry(47));
  EXPECT_TRUE(confirmed.confirmed);
  EXPECT_LT(confirmed.position_variance_m2, at_fix.position_variance_m2);
}

TEST(InitialPose, YamlAndJsonCarryThePoseQuaternionAndCovariance) {
  FixFilter filter = FixedFilter(FixPolicy{});
  const RelocalizationUpdate update = filter.Update(std::nullopt, Odometry(10));
  const InitialPose pose = InitialPoseOf(update, "map");
  const Pose2 expected = kTrue * Odometry(10);
  const std::string dir = testing::MakeTempDir("initialpose");
  for (const std::string name : {"fix.yaml", "fix.json"}) {
    WriteInitialPose(pose, dir + "/" + name);
    const YAML::Node message = YAML::LoadFile(dir + "/" + name);  // JSON is YAML too
    EXPECT_EQ(message["header"]["frame_id"].as<std::string>(), "map");
    const YAML::Node position = message["pose"]["pose"]["position"];
    EXPECT_DOUBLE_EQ(position["x"].as<double>(), expected.x);
    EXPECT_DOUBLE_EQ(position["y"].as<double>(), expected.y);
    const YAML::Node orientation = message["pose"]["pose"]["orientation"];
    const double yaw =
        2.0 * std::atan2(orientation["z"].as<double>(), orientation["w"].as<double>());
    EXPECT_NEAR(std::remainder(yaw - expected.theta, 2.0 * M_PI), 0.0, 1e-12);
    const auto covariance = message["pose"]["covariance"].as<std::vector<double>>();
    ASSERT_EQ(covariance.size(), 36U);
    EXPECT_DOUBLE_EQ(covariance[0], update.position_variance_m2);    // x x
    EXPECT_DOUBLE_EQ(covariance[7], update.position_variance_m2);    // y y
    EXPECT_DOUBLE_EQ(covariance[35], update.heading_variance_rad2);  // yaw yaw
    double others = 0.0;
    for (std::size_t i = 0; i < 36; ++i) {
      if (i != 0 && i != 7 && i != 35) others += std::abs(covariance[i]);
    }
    EXPECT_EQ(others, 0.0);
  }
  std::ifstream json(dir + "/fix.json");
  const std::string text{std::istreambuf_iterator<char>(json), std::istreambuf_iterator<char>()};
  EXPECT_NE(text.find("\"frame_id\": \"map\""), std::string::npos) << text;
}

TEST(InitialPose, AFrameIdThatIsNoRosNameIsRefused) {
  FixFilter filter = FixedFilter(FixPolicy{});
  InitialPose pose = InitialPoseOf(filter.Update(std::nullopt, Odometry(7)), "map");
  pose.frame_id = "map\", x: 1";
  EXPECT_THROW(InitialPoseYaml(pose), std::invalid_argument);
  EXPECT_THROW(InitialPoseJson(pose), std::invalid_argument);
  pose.frame_id = "robot_1/map";
  EXPECT_NO_THROW(InitialPoseYaml(pose));
}

TEST(InitialPose, NoFixNoInitialPose) {
  FixFilter filter;
  const RelocalizationUpdate searching = filter.Update(Answer(kTrue), Odometry(0));
  EXPECT_THROW(InitialPoseOf(searching), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
