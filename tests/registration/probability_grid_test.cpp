#include "registration/probability_grid.hpp"

#include <cmath>
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

constexpr double kCellM = 0.05;
constexpr int kWidth = 256;  // 12.8 m

// P(occupied) of the cell holding a world point.
double ProbabilityAt(const ProbabilityGrid& grid, const Eigen::Vector2d& point_world) {
  const Eigen::Vector2d cell = (point_world - grid.origin()) / grid.cell_m();
  return grid.Probability(static_cast<int>(std::lround(cell.x())),
                          static_cast<int>(std::lround(cell.y())));
}

double Logistic(double log_odds) { return 1.0 / (1.0 + std::exp(-log_odds)); }

TEST(ProbabilityGrid, ABeamMarksItsEndCellHitAndTheCellsBeforeItMissed) {
  ProbabilityGrid grid(kCellM, kWidth);
  grid.Push({{0.0, 0.0}, {{2.0, 0.0}}});
  const double hit = Logistic(std::log(0.55 / 0.45));
  const double miss = std::max(Logistic(std::log(0.49 / 0.51)), ProbabilityGrid::kMinProbability);
  EXPECT_NEAR(ProbabilityAt(grid, {2.0, 0.0}), hit, 1e-6);
  EXPECT_NEAR(ProbabilityAt(grid, {1.0, 0.0}), miss, 1e-6);
  EXPECT_NEAR(ProbabilityAt(grid, {0.05, 0.0}), miss, 1e-6);
  // Off the ray and beyond its end: never observed.
  EXPECT_NEAR(ProbabilityAt(grid, {1.0, 0.5}), ProbabilityGrid::kMinProbability, 1e-6);
  EXPECT_NEAR(ProbabilityAt(grid, {2.5, 0.0}), ProbabilityGrid::kMinProbability, 1e-6);
  // Outside the grid.
  EXPECT_EQ(grid.Probability(-1, 0), ProbabilityGrid::kMinProbability);
  EXPECT_EQ(grid.Probability(0, kWidth), ProbabilityGrid::kMinProbability);
}

TEST(ProbabilityGrid, ACellCountsOncePerScanAndAHitWins) {
  ProbabilityGrid grid(kCellM, kWidth);
  // Two beams end in the same cell; a third passes through it to a farther wall.
  grid.Push({{0.0, 0.0}, {{1.0, 0.0}, {1.01, 0.01}, {3.0, 0.0}}});
  EXPECT_NEAR(ProbabilityAt(grid, {1.0, 0.0}), Logistic(std::log(0.55 / 0.45)), 1e-6);
  grid.Push({{0.0, 0.0}, {{1.0, 0.0}}});
  EXPECT_NEAR(ProbabilityAt(grid, {1.0, 0.0}), Logistic(2.0 * std::log(0.55 / 0.45)), 1e-6);
}

TEST(ProbabilityGrid, PoppingTheOldestScanLeavesTheGridOfTheOthers) {
  const GridScan first{{0.0, 0.0}, {{2.0, 0.5}, {2.0, -0.5}, {1.5, 1.5}}};
  const GridScan second{{0.0, 0.0}, {{2.0, 0.0}, {-1.0, 2.0}, {1.5, 1.5}}};
  ProbabilityGrid both(kCellM, kWidth);
  both.Push(first);
  both.Push(second);
  both.Pop();
  ProbabilityGrid only_second(kCellM, kWidth);
  only_second.Push(second);
  ASSERT_EQ(both.num_scans(), 1u);
  EXPECT_EQ(both.origin(), only_second.origin());
  EXPECT_EQ(both.correspondence_costs(), only_second.correspondence_costs());
  both.Pop();
  both.Pop();  // nothing left: no effect
  EXPECT_EQ(both.num_scans(), 0u);
  for (const float cost : both.correspondence_costs()) {
    ASSERT_FLOAT_EQ(cost, 1.0F - static_cast<float>(ProbabilityGrid::kMinProbability));
  }
}

TEST(ProbabilityGrid, MovesWithTheRobotAndKeepsTheScansItHolds) {
  ProbabilityGrid grid(kCellM, kWidth);
  grid.Push({{0.0, 0.0}, {{1.0, 1.0}}});
  const Eigen::Vector2d first_origin = grid.origin();
  grid.Push({{2.0, 0.0}, {{3.0, 1.0}}});  // within a quarter of 12.8 m: the grid stays
  EXPECT_EQ(grid.origin(), first_origin);
  grid.Push({{4.0, 0.0}, {{5.0, 1.0}}});  // beyond it: centred on this origin, refilled
  EXPECT_NE(grid.origin(), first_origin);
  EXPECT_NEAR(grid.origin().x(), 4.0 - 0.5 * (kWidth - 1) * kCellM, 1e-9);
  const double hit = Logistic(std::log(0.55 / 0.45));
  EXPECT_NEAR(ProbabilityAt(grid, {1.0, 1.0}), hit, 1e-6);
  EXPECT_NEAR(ProbabilityAt(grid, {3.0, 1.0}), hit, 1e-6);
  EXPECT_NEAR(ProbabilityAt(grid, {5.0, 1.0}), hit, 1e-6);
  // A point beyond the grid is left out, not wrapped around into the next row.
  const Eigen::Vector2d beyond(4.0 + 7.0, 1.0);
  grid.Push({{4.0, 0.0}, {beyond}});
  EXPECT_EQ(grid.num_scans(), 4u);
  const Eigen::Vector2d wrapped = beyond + Eigen::Vector2d(-kWidth * kCellM, kCellM);
  EXPECT_NEAR(ProbabilityAt(grid, wrapped), ProbabilityGrid::kMinProbability, 1e-6);
}

TEST(ProbabilityGrid, PoppingAfterTheGridMovedLeavesTheGridOfTheOthers) {
  const GridScan first{{0.0, 0.0}, {{1.0, 1.0}, {-1.0, 2.0}}};
  const GridScan second{{4.0, 0.5}, {{5.0, 1.0}, {3.0, 2.5}, {1.0, 1.0}}};
  ProbabilityGrid both(kCellM, kWidth);
  both.Push(first);
  both.Push(second);  // 4 m away: the grid centres on it and refills
  both.Pop();
  ProbabilityGrid only_second(kCellM, kWidth);
  only_second.Push(second);
  EXPECT_EQ(both.origin(), only_second.origin());
  EXPECT_EQ(both.correspondence_costs(), only_second.correspondence_costs());
}

TEST(ProbabilityGrid, SkipsWhatIsNotFinite) {
  const double nan = std::nan("");
  ProbabilityGrid grid(kCellM, kWidth);
  grid.Push({{nan, 0.0}, {{1.0, 0.0}}});  // no origin: the scan is left out
  EXPECT_EQ(grid.num_scans(), 0u);
  grid.Push({{0.0, 0.0}, {}});  // no points: held, nothing marked
  grid.Push({{0.0, 0.0}, {{nan, 1.0}, {2.0, 0.0}, {1e300, 0.0}}});
  EXPECT_EQ(grid.num_scans(), 2u);
  EXPECT_NEAR(ProbabilityAt(grid, {2.0, 0.0}), Logistic(std::log(0.55 / 0.45)), 1e-6);
}

TEST(ProbabilityGrid, RejectsAnInvalidCellOrWidth) {
  EXPECT_THROW(ProbabilityGrid(0.0, kWidth), std::invalid_argument);
  EXPECT_THROW(ProbabilityGrid(std::nan(""), kWidth), std::invalid_argument);
  EXPECT_THROW(ProbabilityGrid(kCellM, 4), std::invalid_argument);
}

// Key scans of an irregular room along a short drive, in the world frame.
ProbabilityGrid RoomGrid(std::mt19937& rng) {
  const auto world = testing::IrregularRoom();
  const testing::ScanOptions options = testing::FrontLaser(361, 0.005);
  ProbabilityGrid grid(kCellM, 1024);
  for (int i = 0; i < 20; ++i) {
    const Pose2 T_world_laser(-2.0 + 0.1 * i, -1.0, DegToRad(2.0 * i));
    const LaserScan scan = CastScan(world, T_world_laser, options, &rng);
    GridScan grid_scan{T_world_laser.translation(), {}};
    for (const Eigen::Vector2d& p : ScanOdometry::FilteredEndpoints(scan, ScanOdometryConfig{})) {
      grid_scan.points_world.push_back(T_world_laser * p);
    }
    grid.Push(std::move(grid_scan));
  }
  return grid;
}

// The refinement starts from ICP's pose and is held near it (Cartographer's weights: 10 per metre,
// 40 per radian), so it moves a start a few centimetres off towards the truth, not all the way:
// a nudge per key scan towards the map of the last 90.
TEST(MatchOnGrid, MovesAStartNearTheScanPoseTowardsIt) {
  std::mt19937 rng(3);
  const ProbabilityGrid grid = RoomGrid(rng);
  const Pose2 truth(-0.6, -0.9, DegToRad(25.0));
  const LaserScan scan =
      CastScan(testing::IrregularRoom(), truth, testing::FrontLaser(361, 0.005), &rng);
  const std::vector<Eigen::Vector2d> points =
      ScanOdometry::FilteredEndpoints(scan, ScanOdometryConfig{});
  const Pose2 start = truth * Pose2(0.02, -0.015, DegToRad(0.3));
  const GridMatch match = MatchOnGrid(grid, points, start);
  ASSERT_TRUE(match.converged);
  const Pose2 error = Between(truth, match.T_world_laser);
  const Pose2 start_error = Between(truth, start);
  // Measured: 0.025 m and 0.30 deg off before, 0.017 m and 0.22 deg after.
  EXPECT_LT(error.translation().norm(), 0.8 * start_error.translation().norm());
  EXPECT_LT(std::abs(error.theta), 0.8 * std::abs(start_error.theta));
  // The map supports the true pose better than the start, and far better than a wrong turn.
  const double at_truth = MeanGridCost(grid, points, truth);
  EXPECT_LT(at_truth, MeanGridCost(grid, points, start));
  EXPECT_LT(at_truth + 0.2, MeanGridCost(grid, points, truth * Pose2(0.0, 0.0, DegToRad(20.0))));
}

TEST(MatchOnGrid, APointBeyondTheGridCostsWhatAnUnobservedCellDoes) {
  ProbabilityGrid grid(kCellM, kWidth);
  // A ray along the grid's bottom row to beyond its edge: that row's edge cell is a miss.
  const double bottom_y = grid.origin().y();
  grid.Push({{0.0, 0.0}, {{1.0, 0.0}}});
  grid.Push({{0.0, bottom_y}, {{30.0, bottom_y}}});
  const Pose2 identity;
  const double unobserved = 1.0 - ProbabilityGrid::kMinProbability;
  EXPECT_NEAR(MeanGridCost(grid, {{20.0, bottom_y - 1.0}}, identity), unobserved, 1e-9);
  EXPECT_NEAR(MeanGridCost(grid, {{40.0, bottom_y}}, identity), unobserved, 1e-9);
}

TEST(MatchOnGrid, WithoutPointsKeepsTheStart) {
  ProbabilityGrid grid(kCellM, kWidth);
  grid.Push({{0.0, 0.0}, {{1.0, 0.0}}});
  const Pose2 start(0.1, 0.2, 0.3);
  const GridMatch match = MatchOnGrid(grid, {}, start);
  EXPECT_FALSE(match.converged);
  EXPECT_EQ(match.T_world_laser.x, start.x);
  EXPECT_EQ(MeanGridCost(grid, {}, start), 1.0 - ProbabilityGrid::kMinProbability);
}

}  // namespace
}  // namespace keyplace
