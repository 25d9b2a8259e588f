#include "registration/correlative_search.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "keyplace/registration/scan_odometry.hpp"
#include "synthetic_scene.hpp"

namespace keyplace {
namespace {

using testing::CastScan;
using testing::DegToRad;
using testing::ScanOptions;

// The scan's usable endpoints, as scan odometry takes them.
std::vector<Eigen::Vector2d> Endpoints(const LaserScan& scan) {
  return ScanOdometry::FilteredEndpoints(scan, ScanOdometryConfig{});
}

std::vector<Eigen::Vector2d> InWorld(const std::vector<Eigen::Vector2d>& points,
                                     const Pose2& T_world_laser) {
  std::vector<Eigen::Vector2d> world;
  for (const Eigen::Vector2d& p : points) world.push_back(T_world_laser * p);
  return world;
}

TEST(ProximityField, ClosenessFallsWithDistanceAndVanishesBeyondThreeSigma) {
  const ProximityField field({{0.0, 0.0}}, {0.0, 0.0}, 1.0, 0.05, 0.1);
  EXPECT_EQ(field.width(), 40);
  // The cell whose centre is (0.025, 0.025): d = 0.035 m.
  EXPECT_NEAR(field.At({0.01, 0.01}), std::exp(-0.00125 / 0.02), 1e-6);
  EXPECT_GT(field.At({0.01, 0.01}), field.At({0.11, 0.01}));
  EXPECT_GT(field.At({0.11, 0.01}), field.At({0.21, 0.01}));
  EXPECT_EQ(field.At({0.41, 0.01}), 0.0);  // beyond 3 sigma
  EXPECT_EQ(field.At({5.0, 0.0}), 0.0);    // outside the grid
  EXPECT_EQ(field.At({std::numeric_limits<double>::quiet_NaN(), 0.0}), 0.0);
  EXPECT_EQ(field.At({1e300, -1e300}), 0.0);
  // Target points outside the grid or not finite are ignored, not written out of bounds.
  const ProximityField sparse({{1e300, 0.0}, {std::numeric_limits<double>::infinity(), 1.0}},
                              {0.0, 0.0}, 1.0, 0.05, 0.1);
  EXPECT_EQ(sparse.At({0.0, 0.0}), 0.0);
}

// A scan 30 deg and 0.3 m off its guess is found within one step of the search, far beyond the
// basin of ICP.
TEST(CorrelativeSearch, FindsTheTruePoseFarFromTheGuess) {
  const auto world = testing::IrregularRoom();
  ScanOptions options = testing::FrontLaser(360, 0.01);
  std::mt19937 rng(3);
  const Pose2 T_world_map_laser(-1.0, -1.0, DegToRad(20.0));
  const Pose2 T_world_laser(-0.8, -1.1, DegToRad(55.0));
  const auto map =
      InWorld(Endpoints(CastScan(world, T_world_map_laser, options, &rng)), T_world_map_laser);
  const auto source = Endpoints(CastScan(world, T_world_laser, options, &rng));
  const Pose2 guess(T_world_laser.x - 0.3, T_world_laser.y + 0.2, T_world_laser.theta - 0.5236);
  const ProximityField field(map, guess.translation(), 25.0, 0.05, 0.1);
  const CorrelativeMatch match = SearchCorrelative(field, source, guess, CorrelativeWindow{});
  EXPECT_LT(std::abs(match.T_target_source.x - T_world_laser.x), 0.1);
  EXPECT_LT(std::abs(match.T_target_source.y - T_world_laser.y), 0.1);
  EXPECT_LT(std::abs(WrapAngle(match.T_target_source.theta - T_world_laser.theta)), DegToRad(1.5));
  EXPECT_GT(match.score, 2.0 * match.score_at_guess);
  EXPECT_TRUE(match.moved);

  // Outside the window the true pose cannot be found: a 60 deg error stays wrong.
  const Pose2 far_guess(T_world_laser.x, T_world_laser.y, T_world_laser.theta - DegToRad(60.0));
  const CorrelativeMatch far = SearchCorrelative(field, source, far_guess, CorrelativeWindow{});
  EXPECT_GT(std::abs(WrapAngle(far.T_target_source.theta - T_world_laser.theta)), DegToRad(10.0));
}

// Along a corridor every translation fits equally: the prior keeps the guess.
TEST(CorrelativeSearch, InAFeaturelessDirectionTheGuessWins) {
  const auto world = testing::Corridor(1.0);
  ScanOptions options;
  options.beams = 360;
  options.fov_rad = M_PI;
  options.max_range_m = 6.0;
  // The map spans the corridor from x = -4 to 4 m, so that no shift runs off its end.
  std::vector<Eigen::Vector2d> map;
  for (int i = -8; i <= 8; ++i) {
    const auto part = Endpoints(CastScan(world, Pose2(0.5 * i, 0.0, 0.0), options));
    const auto moved = InWorld(part, Pose2(0.5 * i, 0.0, 0.0));
    map.insert(map.end(), moved.begin(), moved.end());
  }
  const auto source = Endpoints(CastScan(world, Pose2(), options));
  const Pose2 guess(0.3, 0.0, 0.0);  // 0.3 m along the axis: as good as the truth
  const ProximityField field(map, guess.translation(), 10.0, 0.05, 0.1);
  const CorrelativeMatch match = SearchCorrelative(field, source, guess, CorrelativeWindow{});
  EXPECT_NEAR(match.T_target_source.x, 0.3, 1e-9);
  EXPECT_NEAR(match.T_target_source.y, 0.0, 1e-9);
  EXPECT_NEAR(match.T_target_source.theta, 0.0, 1e-9);
  EXPECT_FALSE(match.moved);
}

// Far from every target point nothing scores: the guess wins, not a corner of the window.
TEST(CorrelativeSearch, NothingInReachKeepsTheGuess) {
  const ProximityField field({{0.0, 0.0}}, {0.0, 0.0}, 50.0, 0.05, 0.1);
  const Pose2 guess(20.0, 20.0, 0.3);
  const CorrelativeMatch match =
      SearchCorrelative(field, {{1.0, 0.0}, {0.0, 1.0}}, guess, CorrelativeWindow{});
  EXPECT_FALSE(match.moved);
  EXPECT_EQ(match.T_target_source.x, guess.x);
  EXPECT_EQ(match.T_target_source.y, guess.y);
  EXPECT_EQ(match.T_target_source.theta, guess.theta);
  EXPECT_EQ(match.score, 0.0);
}

// An extent needing more cells than the widest grid gets coarser cells, not unbounded memory;
// sizes that are no positive finite numbers are refused.
TEST(ProximityField, WideExtentsGetCoarserCellsAndBadSizesAreRefused) {
  const ProximityField wide({{0.0, 0.0}}, {0.0, 0.0}, 1000.0, 0.05, 0.1);
  EXPECT_EQ(wide.width(), kMaxProximityFieldWidth);
  EXPECT_NEAR(wide.cell_m(), 2000.0 / kMaxProximityFieldWidth, 1e-12);
  EXPECT_GT(wide.At({0.0, 0.0}), 0.0);
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(ProximityField({}, {0.0, 0.0}, inf, 0.05, 0.1), std::invalid_argument);
  EXPECT_THROW(ProximityField({}, {0.0, 0.0}, 1.0, 0.0, 0.1), std::invalid_argument);
  EXPECT_THROW(ProximityField({}, {0.0, 0.0}, 1.0, 0.05, -1.0), std::invalid_argument);
  EXPECT_THROW(ProximityField({}, {inf, 0.0}, 1.0, 0.05, 0.1), std::invalid_argument);
}

TEST(CorrelativeSearch, EmptySourceKeepsTheGuess) {
  const ProximityField field({{0.0, 0.0}}, {0.0, 0.0}, 1.0, 0.05, 0.1);
  const Pose2 guess(0.1, 0.2, 0.3);
  const CorrelativeMatch match = SearchCorrelative(field, {}, guess, CorrelativeWindow{});
  EXPECT_EQ(match.T_target_source.x, guess.x);
  EXPECT_EQ(match.T_target_source.theta, guess.theta);
  EXPECT_EQ(match.score, 0.0);
}

}  // namespace
}  // namespace keyplace
