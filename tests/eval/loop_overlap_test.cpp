#include "keyplace/eval/loop_overlap.hpp"

#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace keyplace {
namespace {

OccupancySummary Block(int x0, int y0, int w, int h) {
  OccupancySummary grid;
  grid.cell_size_m = 0.1;
  for (int i = 0; i < w; ++i) {
    for (int j = 0; j < h; ++j) grid.cells.emplace_back(x0 + i, y0 + j);
  }
  return grid;
}

TEST(OccupancyOverlap, IdentityShiftAndDisjoint) {
  const OccupancySummary a = Block(0, 0, 10, 10);
  EXPECT_DOUBLE_EQ(OccupancyOverlap(a, a, Pose2()), 1.0);
  // Shifted by 5 cells along x: 50 common of 150 distinct cells.
  const OccupancySummary b = Block(0, 0, 10, 10);
  EXPECT_NEAR(OccupancyOverlap(a, b, Pose2(0.5, 0.0, 0.0)), 50.0 / 150.0, 1e-12);
  // The same block expressed in a frame shifted by -0.5 m maps back onto a.
  const OccupancySummary c = Block(5, 0, 10, 10);
  EXPECT_DOUBLE_EQ(OccupancyOverlap(a, c, Pose2(-0.5, 0.0, 0.0)), 1.0);
  EXPECT_DOUBLE_EQ(OccupancyOverlap(a, b, Pose2(5.0, 5.0, 0.0)), 0.0);
  EXPECT_DOUBLE_EQ(OccupancyOverlap(OccupancySummary{}, OccupancySummary{}, Pose2()), 0.0);
}

TEST(OccupancyOverlap, RotationByAQuarterTurnAboutTheCentre) {
  // A 10 x 10 block centred on the origin is its own image under a quarter turn.
  const OccupancySummary a = Block(-5, -5, 10, 10);
  EXPECT_DOUBLE_EQ(OccupancyOverlap(a, a, Pose2(0.0, 0.0, M_PI / 2)), 1.0);
}

TEST(OccupancyOverlap, CoarserGridForgivesASmallShift) {
  const OccupancySummary a = Block(0, 0, 10, 1);  // a 1 m wall of 0.1 m cells
  // Shifted by 0.1 m across the wall: no common 0.1 m cell, the same 0.2 m cells half the time.
  EXPECT_DOUBLE_EQ(OccupancyOverlap(a, a, Pose2(0.0, 0.1, 0.0)), 0.0);
  EXPECT_DOUBLE_EQ(OccupancyOverlap(a, a, Pose2(0.0, 0.05, 0.0), 0.2), 1.0);
  EXPECT_THROW(OccupancyOverlap(a, a, Pose2(), -1.0), std::invalid_argument);
}

OccupancySummary Union(OccupancySummary a, const OccupancySummary& b) {
  a.cells.insert(a.cells.end(), b.cells.begin(), b.cells.end());
  return a;
}

TEST(CommonAreaOverlap, IgnoresWhatOnlyOneSubmapObserved) {
  // The reference saw the room x, y in [0, 1) m with a wall along y = 0; the current submap saw
  // that room and the next one, x in [2, 3) m, with a wall there too.
  const OccupancySummary reference_wall = Block(0, 0, 10, 1);
  const OccupancySummary reference_seen = Block(0, 0, 10, 10);
  const OccupancySummary current_wall = Union(Block(0, 0, 10, 1), Block(20, 0, 10, 1));
  const OccupancySummary current_seen = Union(Block(0, 0, 10, 10), Block(20, 0, 10, 10));
  // Over all cells the second wall halves the rate; over the common area it is no disagreement.
  EXPECT_DOUBLE_EQ(OccupancyOverlap(reference_wall, current_wall, Pose2()), 0.5);
  EXPECT_DOUBLE_EQ(
      CommonAreaOverlap(reference_wall, current_wall, reference_seen, current_seen, Pose2()), 1.0);
  // Symmetric in which submap saw more.
  EXPECT_DOUBLE_EQ(
      CommonAreaOverlap(current_wall, reference_wall, current_seen, reference_seen, Pose2()), 1.0);
}

TEST(CommonAreaOverlap, CountsDisagreementInsideTheCommonArea) {
  const OccupancySummary seen = Block(0, 0, 10, 10);
  const OccupancySummary wall = Block(0, 0, 10, 1);
  // A second wall across the room that only the current submap has: 10 common of 20 cells.
  const OccupancySummary two_walls = Union(wall, Block(0, 5, 10, 1));
  EXPECT_DOUBLE_EQ(CommonAreaOverlap(wall, two_walls, seen, seen, Pose2()), 0.5);
  // Misregistered by one cell across the wall: nothing in common, as over all cells.
  EXPECT_DOUBLE_EQ(CommonAreaOverlap(wall, wall, seen, seen, Pose2(0.0, 0.1, 0.0)), 0.0);
  // No occupied cell in the common area (the rooms do not overlap).
  EXPECT_DOUBLE_EQ(CommonAreaOverlap(wall, wall, seen, seen, Pose2(5.0, 0.0, 0.0)), 0.0);
}

TEST(CommonAreaOverlap, RejectsMixedCellSizes) {
  const OccupancySummary a = Block(0, 0, 10, 1);
  OccupancySummary coarse = a;
  coarse.cell_size_m = 0.2;
  EXPECT_THROW(CommonAreaOverlap(a, a, a, coarse, Pose2()), std::invalid_argument);
  EXPECT_THROW(CommonAreaOverlap(OccupancySummary{}, a, a, a, Pose2()), std::invalid_argument);
}

TEST(OverlapHistogram, PaperBinsAndPrecision) {
  const std::vector<double> overlaps{0.0, 0.05, 0.1, 0.15, 0.29, 0.3, 0.39, 0.4, 0.95, 1.0};
  const OverlapHistogram h = HistogramOfOverlaps(overlaps);
  EXPECT_EQ(h.total, 10u);
  EXPECT_EQ(h.counts[0], 2u);  // [0, 10)
  EXPECT_EQ(h.counts[1], 2u);  // [10, 20)
  EXPECT_EQ(h.counts[2], 1u);  // [20, 30)
  EXPECT_EQ(h.counts[3], 2u);  // [30, 40)
  EXPECT_EQ(h.counts[4], 3u);  // [40, 100]
  EXPECT_DOUBLE_EQ(LoopPrecision(overlaps, 0.1), 0.8);
  EXPECT_DOUBLE_EQ(LoopPrecision(overlaps, 0.3), 0.5);
  EXPECT_DOUBLE_EQ(LoopPrecision({}, 0.3), 0.0);
}

}  // namespace
}  // namespace keyplace
