// A fix as the /initialpose message (issue 16): the pose, its quaternion and the covariance
// derived from the matches, in YAML that ROS tools parse and in JSON.

#include <cmath>
#include <fstream>
#include <iterator>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "keyplace/localization/initial_pose.hpp"
#include "keyplace/localization/relocalizer.hpp"
#include "support/test_data.hpp"

namespace keyplace {
namespace {

// The covariance a match gives (PlaceMatch::estimated_pose_covariance), with off-diagonal terms.
Eigen::Matrix3d MatchCovariance(double scale) {
  Eigen::Matrix3d covariance;
  covariance << 0.004, 0.001, 0.0002, 0.001, 0.002, -0.0001, 0.0002, -0.0001, 0.00005;
  return scale * covariance;
}

LocalizationResult Answer(const Pose2& T_world_odom, double covariance_scale = 1.0) {
  LocalizationResult answer;
  answer.found = true;
  answer.confidence = 0.5;
  answer.T_world_odom = T_world_odom;
  answer.match.estimated_pose_covariance = MatchCovariance(covariance_scale);
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

TEST(InitialPose, TheFiltersVariancesGrowWithUnconfirmedTravel) {
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

TEST(InitialPose, TheCovarianceIsTheMatchesCarriedByOdometryAndFusedLikeTheFix) {
  const FixPolicy policy;
  FixFilter filter = FixedFilter(policy);
  // The map's own error is added to whatever the matches say.
  Eigen::Matrix3d map_error = Eigen::Matrix3d::Zero();
  map_error(0, 0) = map_error(1, 1) = policy.map_sigma_m * policy.map_sigma_m;
  map_error(2, 2) = std::pow(policy.map_sigma_deg * M_PI / 180.0, 2);
  // At the fix: the covariance of the answer that made it, as it is (the robot has not moved).
  const RelocalizationUpdate at_fix = filter.Update(std::nullopt, Odometry(6));
  EXPECT_TRUE(at_fix.covariance.isApprox(MatchCovariance(1.0) + map_error, 1e-14))
      << at_fix.covariance;
  // 10 m later: the heading error moves the robot by the lever arm (the displacement in the map
  // turned by 90 degrees), and the drift allowance is added.
  const RelocalizationUpdate later = filter.Update(std::nullopt, Odometry(46));
  const Eigen::Vector2d moved =
      (kTrue * Odometry(46)).translation() - (kTrue * Odometry(6)).translation();
  Eigen::Matrix3d jacobian = Eigen::Matrix3d::Identity();
  jacobian(0, 2) = -moved.y();
  jacobian(1, 2) = moved.x();
  const double drift_m = policy.agree_per_m * 10.0;
  const double heading_drift_rad =
      drift_m / (0.5 * policy.agree_m) * (0.5 * policy.agree_deg * M_PI / 180.0);
  Eigen::Matrix3d expected = jacobian * MatchCovariance(1.0) * jacobian.transpose();
  expected(0, 0) += drift_m * drift_m;
  expected(1, 1) += drift_m * drift_m;
  expected(2, 2) += heading_drift_rad * heading_drift_rad;
  expected += map_error;
  EXPECT_TRUE(later.covariance.isApprox(expected, 1e-12)) << later.covariance << "\n" << expected;
  // A confirming answer with twice the covariance: the new fix is (1 - w) fix + w answer, with the
  // filter's weight w, so its covariance is (1 - w)^2 C_fix + w^2 C_answer.
  const double travelled = 10.25;
  const double fix_variance =
      0.25 * policy.agree_m * policy.agree_m + std::pow(policy.agree_per_m * travelled, 2);
  const double weight = fix_variance / (fix_variance + 0.25 * policy.agree_m * policy.agree_m);
  const Eigen::Vector2d moved47 =
      (kTrue * Odometry(47)).translation() - (kTrue * Odometry(6)).translation();
  jacobian(0, 2) = -moved47.y();
  jacobian(1, 2) = moved47.x();
  const double drift47_m = policy.agree_per_m * travelled;
  const double heading_drift47_rad =
      drift47_m / (0.5 * policy.agree_m) * (0.5 * policy.agree_deg * M_PI / 180.0);
  Eigen::Matrix3d fix_now = jacobian * MatchCovariance(1.0) * jacobian.transpose();
  fix_now(0, 0) += drift47_m * drift47_m;
  fix_now(1, 1) += drift47_m * drift47_m;
  fix_now(2, 2) += heading_drift47_rad * heading_drift47_rad;
  const Eigen::Matrix3d fused =
      (1.0 - weight) * (1.0 - weight) * fix_now + weight * weight * MatchCovariance(2.0);
  const RelocalizationUpdate confirmed = filter.Update(Answer(kTrue, 2.0), Odometry(47));
  ASSERT_TRUE(confirmed.confirmed);
  // (the map's error is shared by all answers: added once, not fused away)
  EXPECT_TRUE(confirmed.covariance.isApprox(fused + map_error, 1e-12))
      << confirmed.covariance << "\n"
      << fused + map_error;
  // A worse match makes a fix with a larger covariance.
  FixFilter worse(policy);
  worse.Update(Answer(kTrue, 5.0), Odometry(0));
  const RelocalizationUpdate worse_fix = worse.Update(Answer(kTrue, 5.0), Odometry(6));
  ASSERT_EQ(worse_fix.status, FixStatus::kFixed);
  EXPECT_GT(worse_fix.covariance.trace(), at_fix.covariance.trace());
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
    // Row-major over x, y, z, roll, pitch, yaw: the (x, y, yaw) block in rows/columns 0, 1, 5.
    const std::size_t axis[3] = {0, 1, 5};
    double in_block = 0.0;
    for (std::size_t r = 0; r < 3; ++r) {
      for (std::size_t c = 0; c < 3; ++c) {
        EXPECT_DOUBLE_EQ(
            covariance[6 * axis[r] + axis[c]],
            update.covariance(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)));
        in_block += std::abs(covariance[6 * axis[r] + axis[c]]);
      }
    }
    EXPECT_NE(update.covariance(0, 1), 0.0);  // the off-diagonal terms are there
    double all = 0.0;
    for (const double value : covariance) all += std::abs(value);
    EXPECT_EQ(all, in_block);  // z, roll and pitch: 0
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
  // Issue 31: refused when made from a fix too, not only when written; the id shown escaped.
  const RelocalizationUpdate fixed = filter.Update(std::nullopt, Odometry(8));
  EXPECT_NO_THROW(InitialPoseOf(fixed, "map"));
  try {
    InitialPoseOf(fixed, "bad name!");
    FAIL() << "'bad name!' was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("frame id 'bad name!'"), std::string::npos);
  }
  try {
    CheckInitialPoseFrameId(std::string("a\0b", 3));
    FAIL() << "a NUL byte was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()),
              "initial pose: frame id 'a\\0b' is not a ROS frame name (letters, digits, _ / . -)");
  }
}

TEST(InitialPose, NoFixNoInitialPose) {
  FixFilter filter;
  const RelocalizationUpdate searching = filter.Update(Answer(kTrue), Odometry(0));
  EXPECT_THROW(InitialPoseOf(searching), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
