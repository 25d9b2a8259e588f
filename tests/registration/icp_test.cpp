#include "keyplace/registration/icp.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "synthetic_scene.hpp"

namespace keyplace {
namespace {

using testing::CastScan;
using testing::DegToRad;
using testing::Endpoints;
using testing::RadToDeg;
using testing::ScanOptions;

// Pose error of `estimate` against `truth`: translation (m) and |rotation| (deg).
struct PoseError {
  double translation_m;
  double rotation_deg;
};
PoseError ErrorOf(const Pose2& estimate, const Pose2& truth) {
  const Pose2 e = Between(truth, estimate);
  return {TranslationNorm(e), std::abs(RadToDeg(e.theta))};
}

struct Pair {
  std::vector<Eigen::Vector2d> target;
  std::vector<Eigen::Vector2d> source;
  Pose2 T_target_source;
};

Pair MakePair(const std::vector<testing::Segment>& world, const Pose2& T_world_target,
              const Pose2& T_world_source, const ScanOptions& options, std::mt19937* rng) {
  Pair pair;
  pair.target = Endpoints(CastScan(world, T_world_target, options, rng));
  pair.source = Endpoints(CastScan(world, T_world_source, options, rng));
  pair.T_target_source = Between(T_world_target, T_world_source);
  return pair;
}

// Two noisy scans 0.5 m apart along a straight corridor whose ends are out of range: nothing
// measures the motion along its axis.
const Pose2 kCorridorTarget(0.0, 0.1, 0.02);
const Pose2 kCorridorSource(0.5, -0.05, 0.06);
Pair CorridorPair() {
  std::mt19937 rng(3);
  ScanOptions options;
  options.max_range_m = 10.0;
  options.range_noise_m = 0.01;
  return MakePair(testing::Corridor(1.0), kCorridorTarget, kCorridorSource, options, &rng);
}

TEST(IcpTest, RecoversKnownTransformInPolygonalRoom) {
  const auto world = testing::IrregularRoom();
  for (const int beams : {180, 360}) {
    ScanOptions options;
    options.beams = beams;
    const Pair pair =
        MakePair(world, Pose2(0.2, -0.3, 0.1), Pose2(0.45, -0.1, 0.16), options, nullptr);
    const IcpConfig config;
    const IcpTarget target(pair.target, config);
    // Guess off by 15 cm and 4 degrees.
    const Pose2 guess = pair.T_target_source * Pose2(0.12, -0.09, DegToRad(4.0));
    const IcpResult result = AlignPointToLine(target, pair.source, guess, config);
    ASSERT_TRUE(result.converged) << ToString(result.status) << " beams " << beams;
    EXPECT_EQ(result.status, IcpStatus::kConverged);
    const PoseError error = ErrorOf(result.T_target_source, pair.T_target_source);
    EXPECT_LT(error.translation_m, 1e-3) << "beams " << beams;
    EXPECT_LT(error.rotation_deg, 0.05) << "beams " << beams;
    EXPECT_GT(result.inlier_ratio, 0.9);
    EXPECT_LT(result.residual_rms_m, 5e-3);  // pairs near corners are not exact
    EXPECT_GT(result.iterations, 1);
    EXPECT_LT(result.iterations, config.max_iterations);
    EXPECT_FALSE(result.degenerate);
  }
}

TEST(IcpTest, RecoversTransformUnderNoiseAndOutliers) {
  const auto world = testing::IrregularRoom();
  std::mt19937 rng(42);
  ScanOptions options;
  options.range_noise_m = 0.01;
  options.outlier_fraction = 0.15;
  const IcpConfig config;
  double worst_m = 0.0;
  double worst_deg = 0.0;
  for (int trial = 0; trial < 10; ++trial) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Pose2 T_world_target(u(rng), u(rng) * 0.8, u(rng));
    // Keep the sensor (and the moved sensor) well away from the pillar at (0.4..1.1, 0.5..1.1).
    while (T_world_target.x > -0.1 && T_world_target.y > -0.2) {
      T_world_target = Pose2(u(rng), u(rng) * 0.8, u(rng));
    }
    const Pose2 motion(0.3 * u(rng), 0.3 * u(rng), DegToRad(10.0) * u(rng));
    const Pair pair = MakePair(world, T_world_target, T_world_target * motion, options, &rng);
    const IcpTarget target(pair.target, config);
    const Pose2 guess =
        pair.T_target_source * Pose2(0.1 * u(rng), 0.1 * u(rng), DegToRad(3.0) * u(rng));
    const IcpResult result = AlignPointToLine(target, pair.source, guess, config);
    ASSERT_TRUE(result.converged) << "trial " << trial << " " << ToString(result.status);
    const PoseError error = ErrorOf(result.T_target_source, pair.T_target_source);
    worst_m = std::max(worst_m, error.translation_m);
    worst_deg = std::max(worst_deg, error.rotation_deg);
    EXPECT_GT(result.inlier_ratio, 0.5);
    EXPECT_LT(result.inlier_ratio, 0.95);  // the outliers are not inliers
  }
  EXPECT_LT(worst_m, 0.01);
  EXPECT_LT(worst_deg, 0.3);
}

TEST(IcpTest, RobustKernelBeatsPlainLeastSquaresWithOutliers) {
  const auto world = testing::IrregularRoom();
  std::mt19937 rng(7);
  ScanOptions options;
  options.range_noise_m = 0.005;
  options.outlier_fraction = 0.3;
  const Pair pair = MakePair(world, Pose2(0, 0, 0), Pose2(0.2, 0.1, 0.05), options, &rng);
  IcpConfig robust;
  IcpConfig plain = robust;
  plain.kernel = RobustKernel::kNone;
  const Pose2 guess = pair.T_target_source * Pose2(0.05, -0.05, 0.03);
  const IcpTarget target_robust(pair.target, robust);
  const IcpResult r = AlignPointToLine(target_robust, pair.source, guess, robust);
  const IcpResult p = AlignPointToLine(target_robust, pair.source, guess, plain);
  const double robust_error = ErrorOf(r.T_target_source, pair.T_target_source).translation_m;
  const double plain_error = ErrorOf(p.T_target_source, pair.T_target_source).translation_m;
  EXPECT_LT(robust_error, 0.01);
  EXPECT_LT(robust_error, plain_error);
}

TEST(IcpTest, DegenerateCorridorStaysAtGuessAlongTheAxis) {
  const Pose2 T_world_target = kCorridorTarget;
  const Pose2 T_world_source = kCorridorSource;
  const Pair pair = CorridorPair();
  const IcpConfig config;
  const IcpTarget target(pair.target, config);
  // Odometry believes in 0.35 m along the axis, and is off laterally / in heading.
  const Pose2 T_world_guess(0.35, 0.03, 0.0);
  const Pose2 guess = Between(T_world_target, T_world_guess);
  const IcpResult result = AlignPointToLine(target, pair.source, guess, config);
  EXPECT_TRUE(result.degenerate);
  ASSERT_TRUE(result.converged) << ToString(result.status);
  const Pose2 T_world_estimate = T_world_target * result.T_target_source;
  // Along the axis: stays at the guess (no sliding); across and in heading: corrected.
  EXPECT_NEAR(T_world_estimate.x, T_world_guess.x, 0.03);
  EXPECT_NEAR(T_world_estimate.y, T_world_source.y, 0.01);
  EXPECT_NEAR(T_world_estimate.theta, T_world_source.theta, DegToRad(0.3));
}

// A prior of information sigma_r^2 / sigma^2 per axis (IcpPosePrior's units).
IcpPosePrior PriorAt(const Pose2& mean, double sigma_m, double sigma_rad, double sigma_r_m) {
  IcpPosePrior prior;
  prior.T_target_source_mean = mean;
  const double v = sigma_r_m * sigma_r_m;
  prior.information.diagonal() << v / (sigma_m * sigma_m), v / (sigma_m * sigma_m),
      v / (sigma_rad * sigma_rad);
  return prior;
}

TEST(IcpTest, PriorDecidesTheCorridorAxisAndThePointsTheRest) {
  const Pose2 T_world_target = kCorridorTarget;
  const Pose2 T_world_source = kCorridorSource;
  const Pair pair = CorridorPair();
  const IcpConfig config;
  const IcpTarget target(pair.target, config);
  // The guess is 0.2 m short along the axis and off across it; the prior's mean is 0.45 m along.
  const Pose2 T_world_guess(0.3, 0.03, 0.0);
  const Pose2 T_world_mean(0.45, 0.03, 0.0);
  const IcpPosePrior prior =
      PriorAt(Between(T_world_target, T_world_mean), 0.05, DegToRad(5.0), 0.05);
  const IcpResult result =
      AlignPointToLine(target, pair.source, Between(T_world_target, T_world_guess), config, &prior);
  EXPECT_TRUE(result.degenerate);  // the points alone would hold the axis
  ASSERT_TRUE(result.converged) << ToString(result.status);
  const Pose2 T_world_estimate = T_world_target * result.T_target_source;
  // Along the axis the prior's mean, not the guess; across it and in heading the walls.
  EXPECT_NEAR(T_world_estimate.x, T_world_mean.x, 0.02);
  EXPECT_NEAR(T_world_estimate.y, T_world_source.y, 0.01);
  EXPECT_NEAR(T_world_estimate.theta, T_world_source.theta, DegToRad(0.3));
}

TEST(IcpTest, WeakPriorBarelyMovesAWellMeasuredPose) {
  const auto world = testing::IrregularRoom();
  const Pair pair = MakePair(world, Pose2(0.2, -0.3, 0.1), Pose2(0.45, -0.1, 0.16), {}, nullptr);
  const IcpConfig config;
  const IcpTarget target(pair.target, config);
  const Pose2 guess = pair.T_target_source * Pose2(0.12, -0.09, DegToRad(4.0));
  // Odometry 10 cm and 3 degrees off, with a 5 cm / 2 degree standard deviation.
  const Pose2 mean = pair.T_target_source * Pose2(0.1, 0.0, DegToRad(3.0));
  const IcpPosePrior prior = PriorAt(mean, 0.05, DegToRad(2.0), 0.05);
  const IcpResult with_prior = AlignPointToLine(target, pair.source, guess, config, &prior);
  ASSERT_TRUE(with_prior.converged) << ToString(with_prior.status);
  const PoseError error = ErrorOf(with_prior.T_target_source, pair.T_target_source);
  EXPECT_LT(error.translation_m, 3e-3);
  EXPECT_LT(error.rotation_deg, 0.1);
  // A prior that is as sure as the points pulls the estimate visibly towards its mean.
  const IcpPosePrior strong = PriorAt(mean, 0.002, DegToRad(0.1), 0.05);
  const IcpResult pulled = AlignPointToLine(target, pair.source, guess, config, &strong);
  ASSERT_TRUE(pulled.converged) << ToString(pulled.status);
  // Between the truth and the prior's mean, 10 cm apart: neither at the truth nor at the mean.
  const double from_truth_m = ErrorOf(pulled.T_target_source, pair.T_target_source).translation_m;
  const double from_mean_m = ErrorOf(pulled.T_target_source, mean).translation_m;
  EXPECT_GT(from_truth_m, 0.02);
  EXPECT_GT(from_mean_m, 0.005);
  EXPECT_LT(from_truth_m + from_mean_m, 0.12);
}

TEST(IcpTest, PriorMustBePositiveDefinite) {
  const auto world = testing::IrregularRoom();
  const Pair pair = MakePair(world, Pose2(), Pose2(0.1, 0.0, 0.0), {}, nullptr);
  const IcpConfig config;
  const IcpTarget target(pair.target, config);
  IcpPosePrior prior;  // zero information
  EXPECT_THROW(AlignPointToLine(target, pair.source, Pose2(), config, &prior),
               std::invalid_argument);
  prior.information = Eigen::Matrix3d::Identity();
  prior.information(0, 1) = 0.5;  // not symmetric
  EXPECT_THROW(AlignPointToLine(target, pair.source, Pose2(), config, &prior),
               std::invalid_argument);
  prior.information = Eigen::Matrix3d::Identity() * std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(AlignPointToLine(target, pair.source, Pose2(), config, &prior),
               std::invalid_argument);
}

TEST(IcpTest, EmptyAndTinyInputsGiveAClearResult) {
  const auto world = testing::IrregularRoom();
  const std::vector<Eigen::Vector2d> room = Endpoints(CastScan(world, Pose2(), ScanOptions{}));
  const std::vector<Eigen::Vector2d> empty;
  const std::vector<Eigen::Vector2d> tiny = {{1.0, 0.0}, {1.0, 0.1}};
  const IcpConfig config;
  const Pose2 guess(0.1, 0.2, 0.3);
  {
    const IcpTarget target(room, config);
    for (const auto* source : {&empty, &tiny}) {
      const IcpResult result = AlignPointToLine(target, *source, guess, config);
      EXPECT_FALSE(result.converged);
      EXPECT_EQ(result.status, IcpStatus::kTooFewPoints);
      EXPECT_EQ(result.iterations, 0);
      EXPECT_DOUBLE_EQ(result.T_target_source.x, guess.x);
      EXPECT_DOUBLE_EQ(result.T_target_source.theta, guess.theta);
    }
  }
  for (const auto* points : {&empty, &tiny}) {
    const IcpTarget target(*points, config);
    EXPECT_EQ(target.CountNormals(), 0u);
    const IcpResult result = AlignPointToLine(target, room, guess, config);
    EXPECT_FALSE(result.converged);
    EXPECT_EQ(result.status, IcpStatus::kTooFewPoints);
  }
  // Source far away from the target: no correspondences at all.
  const IcpTarget target(room, config);
  const IcpResult far = AlignPointToLine(target, room, Pose2(100.0, 0.0, 0.0), config);
  EXPECT_FALSE(far.converged);
  EXPECT_EQ(far.status, IcpStatus::kSingular);
  EXPECT_DOUBLE_EQ(far.T_target_source.x, 100.0);
}

// `count` points uniform over [-10, 10]^2, drawn from `u` (the tests draw their queries from it
// after).
std::vector<Eigen::Vector2d> UniformPoints(std::mt19937& rng,
                                           std::uniform_real_distribution<double>& u, int count) {
  std::vector<Eigen::Vector2d> points(static_cast<std::size_t>(count));
  for (auto& p : points) p = {u(rng), u(rng)};
  return points;
}

// The squared distance from `query` to its nearest point, by a scan of every point.
double NearestSquaredDistance(const std::vector<Eigen::Vector2d>& points,
                              const Eigen::Vector2d& query) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& p : points) best = std::min(best, (p - query).squaredNorm());
  return best;
}

TEST(IcpTest, KdTreeNearestMatchesBruteForce) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  const std::vector<Eigen::Vector2d> points = UniformPoints(rng, u, 2000);
  const IcpTarget target(points, IcpConfig{});
  EXPECT_EQ(&target.points(), &points);  // an adaptor over the caller's points, no copy
  for (int q = 0; q < 500; ++q) {
    const Eigen::Vector2d query(u(rng) * 1.2, u(rng) * 1.2);
    const double best = NearestSquaredDistance(points, query);
    std::size_t index = 0;
    double d2 = 0.0;
    ASSERT_TRUE(target.Nearest(query, &index, &d2));
    EXPECT_DOUBLE_EQ(d2, best);
    EXPECT_DOUBLE_EQ((points[index] - query).squaredNorm(), best);
  }
}

// The bounded search with a hint finds what a scan of every point finds: the nearest point when
// it lies within the bound (the bound itself included), nothing otherwise, whether the hint is
// the previous answer, a far point, a point beyond the bound or no point at all.
TEST(IcpTest, NearestWithinMatchesBruteForceWhateverTheHint) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  const std::vector<Eigen::Vector2d> points = UniformPoints(rng, u, 2000);
  const IcpTarget target(points, IcpConfig{});
  const double bound_d2 = 0.04;
  std::size_t previous = IcpTarget::kNoHint;
  int within = 0;
  int beyond = 0;
  for (int q = 0; q < 2000; ++q) {
    const Eigen::Vector2d query(u(rng) * 1.2, u(rng) * 1.2);
    const double best = NearestSquaredDistance(points, query);
    const std::size_t far_point = static_cast<std::size_t>(q) % points.size();
    for (const std::size_t hint : {previous, far_point, IcpTarget::kNoHint, points.size() + 3}) {
      std::size_t index = 0;
      double d2 = -1.0;
      const bool found = target.NearestWithin(query, bound_d2, hint, &index, &d2);
      ASSERT_EQ(found, best <= bound_d2) << "query " << q << ", hint " << hint;
      if (!found) continue;
      EXPECT_DOUBLE_EQ(d2, best);
      EXPECT_DOUBLE_EQ((points[index] - query).squaredNorm(), best);
    }
    if (best <= bound_d2) {
      ++within;
    } else {
      ++beyond;
    }
    target.NearestWithin(query, bound_d2, previous, &previous, nullptr);
  }
  EXPECT_GT(within, 100);  // both outcomes are exercised
  EXPECT_GT(beyond, 100);
  // A point exactly at the bound counts, as `d2 > bound` rejected nothing at the bound before:
  // a query 0.25 m from a point with no other within 0.6 m.
  std::size_t lonely = points.size();
  for (std::size_t i = 0; i < points.size() && lonely == points.size(); ++i) {
    bool alone = true;
    for (std::size_t j = 0; j < points.size() && alone; ++j) {
      alone = j == i || (points[j] - points[i]).norm() > 0.6;
    }
    if (alone) lonely = i;
  }
  ASSERT_LT(lonely, points.size());
  const Eigen::Vector2d on_bound = points[lonely] + Eigen::Vector2d(0.0, 0.25);
  const double exact_d2 = (points[lonely] - on_bound).squaredNorm();
  std::size_t index = 0;
  double d2 = 0.0;
  EXPECT_TRUE(target.NearestWithin(on_bound, exact_d2, IcpTarget::kNoHint, &index, &d2));
  EXPECT_EQ(index, lonely);
  EXPECT_FALSE(target.NearestWithin(on_bound, std::nextafter(exact_d2, 0.0), IcpTarget::kNoHint,
                                    &index, &d2));
  const std::vector<Eigen::Vector2d> none;
  EXPECT_FALSE(IcpTarget(none, IcpConfig{}).NearestWithin({0.0, 0.0}, 1.0, 0, &index, &d2));
}

// Among equally near points NearestWithin returns the one Nearest returns, whatever the hint:
// points on a grid, each twice, queried at grid points, cell centres and edge midpoints (four or
// eight points equally near), with the hint on one of the others.
TEST(IcpTest, NearestWithinPicksWhatNearestPicksAmongEquallyNearPoints) {
  std::vector<Eigen::Vector2d> points;
  for (int copy = 0; copy < 2; ++copy) {
    for (int i = 0; i < 30; ++i) {
      for (int j = 0; j < 30; ++j) points.emplace_back(0.25 * i, 0.25 * j);
    }
  }
  const IcpTarget target(points, IcpConfig{});
  int ties_checked = 0;
  for (int i = 1; i < 28; i += 3) {
    for (int j = 1; j < 28; j += 2) {
      for (const Eigen::Vector2d& offset :
           {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.125, 0.125),
            Eigen::Vector2d(0.125, 0.0)}) {
        const Eigen::Vector2d query = Eigen::Vector2d(0.25 * i, 0.25 * j) + offset;
        std::size_t expected = 0;
        double expected_d2 = 0.0;
        ASSERT_TRUE(target.Nearest(query, &expected, &expected_d2));
        for (std::size_t hint = 0; hint < points.size(); hint += 1 + points.size() / 37) {
          if ((points[hint] - query).squaredNorm() != expected_d2) continue;
          ++ties_checked;
          std::size_t index = 0;
          double d2 = 0.0;
          ASSERT_TRUE(target.NearestWithin(query, 0.5, hint, &index, &d2));
          EXPECT_EQ(index, expected) << "query " << query.transpose() << ", hint " << hint;
          EXPECT_EQ(d2, expected_d2);
        }
        // Equally near duplicates of the answer and its neighbours as hints, and no hint.
        for (const std::size_t hint :
             {expected, (expected + 900) % points.size(), IcpTarget::kNoHint}) {
          std::size_t index = 0;
          ASSERT_TRUE(target.NearestWithin(query, 0.5, hint, &index, nullptr));
          EXPECT_EQ(index, expected) << "query " << query.transpose() << ", hint " << hint;
          ++ties_checked;
        }
      }
    }
  }
  EXPECT_GT(ties_checked, 500);
}

TEST(IcpTest, NormalsArePerpendicularToWallsAndMissingAtCorners) {
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i <= 20; ++i) points.emplace_back(0.05 * i, 0.0);     // wall along x
  for (int i = 1; i <= 20; ++i) points.emplace_back(0.0, 0.05 * i);     // wall along y
  for (int i = 0; i < 5; ++i) points.emplace_back(5.0 + 3.0 * i, 7.0);  // isolated points
  IcpConfig config;
  config.normal_neighbours = 5;
  const IcpTarget target(points, config);
  ASSERT_TRUE(target.HasNormal(10));
  EXPECT_NEAR(std::abs(target.normal(10).y()), 1.0, 1e-12);
  ASSERT_TRUE(target.HasNormal(30));
  EXPECT_NEAR(std::abs(target.normal(30).x()), 1.0, 1e-12);
  EXPECT_FALSE(target.HasNormal(0));  // the corner
  for (std::size_t i = 41; i < points.size(); ++i) EXPECT_FALSE(target.HasNormal(i));
}

TEST(IcpTest, MissingNormalsAreFittedOverAllTargetPointsOthersKept) {
  // Two scans of a far wall y = 5, each with points 0.4 m apart (too sparse for a normal alone),
  // the second shifted by 0.2 m: together 0.2 m apart. A near wall x = 0 carries given normals,
  // deliberately tilted so that a refit would show.
  std::vector<Eigen::Vector2d> points;
  PointNormals normals;
  for (int scan = 0; scan < 2; ++scan) {
    for (int i = 0; i < 10; ++i) {
      points.emplace_back(0.4 * i + 0.2 * scan, 5.0);
      normals.normals.emplace_back(0.0, 0.0);
      normals.valid.push_back(0);
    }
  }
  const Eigen::Vector2d tilted = Eigen::Vector2d(1.0, 0.1).normalized();
  for (int i = 0; i < 10; ++i) {
    points.emplace_back(0.0, 0.05 * i);
    normals.normals.push_back(tilted);
    normals.valid.push_back(1);
  }
  IcpTarget target(points, normals, IcpConfig{});
  EXPECT_EQ(target.CountNormals(), 10u);
  // All but the wall's two ends (x = 0 and 3.8 m: one neighbour within 0.3 m) get one.
  EXPECT_EQ(target.FillMissingNormals(IcpConfig{}), 18u);
  EXPECT_EQ(target.CountNormals(), 28u);
  EXPECT_FALSE(target.HasNormal(0));
  EXPECT_FALSE(target.HasNormal(19));
  for (std::size_t i = 1; i < 19; ++i) {
    ASSERT_TRUE(target.HasNormal(i)) << i;
    EXPECT_NEAR(std::abs(target.normal(i).y()), 1.0, 1e-9) << i;
  }
  for (std::size_t i = 20; i < 30; ++i) EXPECT_EQ(target.normal(i), tilted) << i;
  EXPECT_EQ(target.FillMissingNormals(IcpConfig{}), 0u);
}

TEST(IcpTest, InvalidConfigThrowsNamingTheField) {
  const std::vector<Eigen::Vector2d> points = {{0, 0}, {1, 0}, {2, 0}};
  IcpConfig config;
  config.max_correspondence_distance_m = -1.0;
  try {
    const IcpTarget target(points, config);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("max_correspondence_distance_m"), std::string::npos);
  }
  IcpConfig good;
  const IcpTarget target(points, good);
  IcpConfig bad_iterations;
  bad_iterations.max_iterations = 0;
  EXPECT_THROW(AlignPointToLine(target, points, Pose2(), bad_iterations), std::invalid_argument);
}

}  // namespace
}  // namespace keyplace
