// RANSAC recovers a known rigid transform from descriptor pairs with 50 % outliers.

#include "keyplace/place/ransac.hpp"

#include <cmath>
#include <random>
#include <stdexcept>

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

// The match covariance (RigidFitCovariance): n points with centroid at the current frame's origin
// and the true transform, each reference point displaced by a known residual.
struct FitScene {
  std::vector<Eigen::Vector2d> reference;
  std::vector<Eigen::Vector2d> current;
  std::vector<std::pair<int, int>> pairs;
};

FitScene Ring(int n, double radius_m, double residual_m, const Pose2& T_ref_cur) {
  FitScene scene;
  for (int i = 0; i < n; ++i) {
    const double angle = 2.0 * M_PI * i / n;
    const Eigen::Vector2d c(radius_m * std::cos(angle), radius_m * std::sin(angle));
    // Residuals alternate in sign along x and y: they sum to zero, so T_ref_cur stays the fit.
    const Eigen::Vector2d e(i % 2 == 0 ? residual_m : -residual_m,
                            (i / 2) % 2 == 0 ? residual_m : -residual_m);
    scene.current.push_back(c);
    scene.reference.push_back(T_ref_cur * c + e);
    scene.pairs.emplace_back(i, i);
  }
  return scene;
}

TEST(RigidFitCovariance, HandComputedForPointsAroundTheOrigin) {
  // At theta = 0 with the centroid at the origin, sum J^T J = diag(n, n, sum |c|^2); every
  // residual has |e|^2 = 2 e^2, so sigma^2 = n 2 e^2 / (2 n - 3).
  const int n = 8;
  const double radius = 2.0;
  const double e = 0.05;
  const FitScene scene = Ring(n, radius, e, Pose2(1.0, -3.0, 0.0));
  const Eigen::Matrix3d covariance =
      RigidFitCovariance(scene.reference, scene.current, scene.pairs, Pose2(1.0, -3.0, 0.0), 0.0);
  const double sigma2 = n * 2.0 * e * e / (2.0 * n - 3.0);
  EXPECT_NEAR(covariance(0, 0), sigma2 / n, 1e-15);
  EXPECT_NEAR(covariance(1, 1), sigma2 / n, 1e-15);
  EXPECT_NEAR(covariance(2, 2), sigma2 / (n * radius * radius), 1e-15);
  EXPECT_NEAR(covariance(0, 1), 0.0, 1e-15);
  EXPECT_NEAR(covariance(0, 2), 0.0, 1e-15);
}

TEST(RigidFitCovariance, SpreadOutInliersGiveASmallerCovarianceThanClusteredOnes) {
  const Pose2 T(0.5, 0.2, 0.7);
  const FitScene spread = Ring(12, 5.0, 0.04, T);
  const FitScene clustered = Ring(12, 0.3, 0.04, T);
  const Eigen::Matrix3d a =
      RigidFitCovariance(spread.reference, spread.current, spread.pairs, T, 0);
  const Eigen::Matrix3d b =
      RigidFitCovariance(clustered.reference, clustered.current, clustered.pairs, T, 0);
  // The heading is pinned by points far apart: (5 / 0.3)^2 times better.
  EXPECT_NEAR(b(2, 2) / a(2, 2), (5.0 / 0.3) * (5.0 / 0.3), 1e-6);
  EXPECT_LT(a.trace(), b.trace());
  // Positions, expressed away from the points, inherit the heading error by the lever arm.
  const Pose2 far(20.0, 0.0, 0.0);
  EXPECT_LT(ComposedCovariance(Pose2(), T, far, a).trace(),
            ComposedCovariance(Pose2(), T, far, b).trace());
}

TEST(RigidFitCovariance, LargerResidualsGiveALargerCovarianceAboveTheFloor) {
  const Pose2 T(-1.0, 2.0, -2.5);
  const FitScene small = Ring(10, 3.0, 0.04, T);
  const FitScene large = Ring(10, 3.0, 0.08, T);
  const Eigen::Matrix3d a =
      RigidFitCovariance(small.reference, small.current, small.pairs, T, 0.03);
  const Eigen::Matrix3d b =
      RigidFitCovariance(large.reference, large.current, large.pairs, T, 0.03);
  // Twice the residuals, four times the covariance (both above the floor).
  EXPECT_TRUE(b.isApprox(4.0 * a, 1e-12)) << a << "\n" << b;
  // Exact points: the floor, sigma = 0.03 m, and not zero.
  const FitScene exact = Ring(10, 3.0, 0.0, T);
  const Eigen::Matrix3d floor =
      RigidFitCovariance(exact.reference, exact.current, exact.pairs, T, 0.03);
  const Eigen::Matrix3d unit =
      RigidFitCovariance(exact.reference, exact.current, exact.pairs, T, 1.0);
  EXPECT_TRUE(floor.isApprox(0.03 * 0.03 * unit, 1e-12));
  EXPECT_GT(floor(0, 0), 0.0);
  // 0.01 m residuals fall below the floor: the same as exact points.
  const FitScene tiny = Ring(10, 3.0, 0.01, T);
  EXPECT_TRUE(
      RigidFitCovariance(tiny.reference, tiny.current, tiny.pairs, T, 0.03).isApprox(floor, 1e-12));
}

TEST(RigidFitCovariance, UndeterminedFitsAreInfiniteAndBadIndicesRefused) {
  const std::vector<Eigen::Vector2d> points = {{1, 1}, {1, 1}, {1, 1}};
  const Eigen::Matrix3d one = RigidFitCovariance(points, points, {{0, 0}}, Pose2(), 0.03);
  EXPECT_TRUE(std::isinf(one(0, 0)) && std::isinf(one(2, 2)));
  EXPECT_EQ(one(0, 1), 0.0);
  const Eigen::Matrix3d same_spot =
      RigidFitCovariance(points, points, {{0, 0}, {1, 1}, {2, 2}}, Pose2(), 0.03);
  EXPECT_TRUE(std::isinf(same_spot(2, 2)));
  EXPECT_THROW(RigidFitCovariance(points, points, {{0, 0}, {3, 1}}, Pose2(), 0.03),
               std::invalid_argument);
}

TEST(RigidFitCovariance, ComposedCovarianceMatchesNumericalDerivatives) {
  const Pose2 T_a_b(3.0, -1.0, 0.4);
  const Pose2 T_b_c(0.5, 2.0, -1.2);
  const Pose2 T_c_d(4.0, 1.5, 0.3);
  Eigen::Matrix3d covariance;
  covariance << 0.04, 0.01, 0.002, 0.01, 0.09, -0.003, 0.002, -0.003, 0.0004;
  // Numerical Jacobian of T_a_b * T_b_c(x, y, theta) * T_c_d over T_b_c's parameters.
  const Pose2 base = T_a_b * T_b_c * T_c_d;
  Eigen::Matrix3d jacobian;
  const double h = 1e-7;
  for (int k = 0; k < 3; ++k) {
    Pose2 moved_b_c = T_b_c;
    (k == 0 ? moved_b_c.x : k == 1 ? moved_b_c.y : moved_b_c.theta) += h;
    const Pose2 moved = T_a_b * moved_b_c * T_c_d;
    jacobian.col(k) << (moved.x - base.x) / h, (moved.y - base.y) / h,
        WrapAngle(moved.theta - base.theta) / h;
  }
  const Eigen::Matrix3d expected = jacobian * covariance * jacobian.transpose();
  EXPECT_TRUE(ComposedCovariance(T_a_b, T_b_c, T_c_d, covariance).isApprox(expected, 1e-5))
      << ComposedCovariance(T_a_b, T_b_c, T_c_d, covariance) << "\n"
      << expected;
}

}  // namespace
}  // namespace keyplace
