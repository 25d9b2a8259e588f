// RANSAC recovers a known rigid transform from descriptor pairs with 50 % outliers.

#include "keyplace/place/ransac.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace keyplace {
namespace {

struct Scene {
  std::vector<Eigen::Vector2d> reference;
  std::vector<Eigen::Vector2d> current;
  std::vector<std::pair<int, int>> pairs;  // (current, reference)
};

// `inliers` true correspondences under T_ref_cur (with noise), `outliers` wrong ones.
Scene MakeScene(const Pose2& T_ref_cur, int inliers, int outliers, double noise_m,
                std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coordinate(-8.0, 8.0);
  std::normal_distribution<double> noise(0.0, noise_m);
  Scene scene;
  const Pose2 T_cur_ref = T_ref_cur.inverse();
  for (int i = 0; i < inliers + outliers; ++i) {
    const Eigen::Vector2d r(coordinate(rng), coordinate(rng));
    scene.reference.push_back(r);
    if (i < inliers) {
      scene.current.push_back(T_cur_ref * r + Eigen::Vector2d(noise(rng), noise(rng)));
    } else {
      scene.current.emplace_back(coordinate(rng), coordinate(rng));
    }
    scene.pairs.emplace_back(i, i);
  }
  // Shuffle the pairs so that the inliers are not first.
  std::shuffle(scene.pairs.begin(), scene.pairs.end(), rng);
  return scene;
}

void ExpectNear(const Pose2& a, const Pose2& b, double translation_m, double angle_rad) {
  EXPECT_NEAR(a.x, b.x, translation_m);
  EXPECT_NEAR(a.y, b.y, translation_m);
  EXPECT_NEAR(WrapAngle(a.theta - b.theta), 0.0, angle_rad);
}

TEST(Ransac, RecoversKnownTransformWithHalfOutliersSampled) {
  const Pose2 truth(3.2, -1.7, 2.4);
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    const Scene scene = MakeScene(truth, 12, 12, 0.01, seed);
    RansacConfig config;
    config.exhaustive_max_pairs = 0;  // sampling
    config.iterations = 100;
    config.seed = seed;
    const RansacResult result =
        EstimateRigidTransformRansac(scene.reference, scene.current, scene.pairs, config);
    ASSERT_TRUE(result.valid) << "seed " << seed;
    ExpectNear(result.T_ref_cur, truth, 0.03, 0.01);
    EXPECT_GE(result.inliers.size(), 12u) << "seed " << seed;
    for (const auto& [c, r] : result.inliers) {
      if (c < 12) {
        EXPECT_EQ(c, r);  // every true keypoint found its own partner
      }
    }
  }
}

TEST(Ransac, ExhaustiveHypothesesRecoverTransform) {
  const Pose2 truth(-4.0, 0.5, -0.3);
  const Scene scene = MakeScene(truth, 10, 10, 0.0, 7);
  RansacConfig config;  // 20 pairs <= 40: every pair of pairs
  const RansacResult result =
      EstimateRigidTransformRansac(scene.reference, scene.current, scene.pairs, config);
  ASSERT_TRUE(result.valid);
  ExpectNear(result.T_ref_cur, truth, 1e-9, 1e-9);
  EXPECT_EQ(result.hypotheses > 0, true);
}

TEST(Ransac, SameSeedSameResult) {
  const Scene scene = MakeScene(Pose2(1.0, 2.0, 0.5), 8, 20, 0.02, 3);
  RansacConfig config;
  config.exhaustive_max_pairs = 0;
  config.seed = 42;
  const RansacResult a =
      EstimateRigidTransformRansac(scene.reference, scene.current, scene.pairs, config);
  const RansacResult b =
      EstimateRigidTransformRansac(scene.reference, scene.current, scene.pairs, config);
  EXPECT_EQ(a.T_ref_cur.x, b.T_ref_cur.x);
  EXPECT_EQ(a.T_ref_cur.theta, b.T_ref_cur.theta);
  EXPECT_EQ(a.inliers, b.inliers);
}

TEST(Ransac, FitRigidTransformIsExactOnNoiseFreePoints) {
  const Pose2 truth(0.3, -2.0, 1.1);
  std::vector<Eigen::Vector2d> current = {{0, 0}, {1, 0}, {0, 2}, {-1, 3}};
  std::vector<Eigen::Vector2d> reference;
  for (const auto& p : current) reference.push_back(truth * p);
  ExpectNear(FitRigidTransform(reference, current), truth, 1e-12, 1e-12);
}

TEST(Ransac, TooFewPairsIsInvalid) {
  const std::vector<Eigen::Vector2d> points = {{0, 0}};
  const RansacResult result = EstimateRigidTransformRansac(points, points, {{0, 0}}, {});
  EXPECT_FALSE(result.valid);
}

TEST(Ransac, ScoreIsMeanTruncatedSquaredDistance) {
  const std::vector<Eigen::Vector2d> reference = {{0, 0}, {5, 0}};
  const std::vector<Eigen::Vector2d> current = {{0.05, 0}, {2, 2}};
  std::vector<std::pair<int, int>> inliers;
  const double score = ScoreTransform(reference, current, Pose2{}, 0.1, &inliers);
  EXPECT_NEAR(score, (0.0025 + 0.01) / 2.0, 1e-12);
  ASSERT_EQ(inliers.size(), 1u);
  EXPECT_EQ(inliers[0], std::make_pair(0, 0));
}

}  // namespace
}  // namespace keyplace
