#include "common/ray_cells.hpp"

#include <cmath>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace keyplace {
namespace {

using Cells = std::vector<std::pair<int, int>>;

Cells CellsBeforeEnd(const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
  Cells cells;
  ForEachCellBeforeEnd(from, to, [&](int column, int row) {
    cells.emplace_back(column, row);
    return true;
  });
  return cells;
}

TEST(RayCells, VisitsEveryCellTheRayCrossesBeforeItsEndInOrder) {
  EXPECT_EQ(CellsBeforeEnd({0.5, 0.5}, {3.5, 0.5}), (Cells{{0, 0}, {1, 0}, {2, 0}}));
  EXPECT_EQ(CellsBeforeEnd({0.5, 0.5}, {0.5, -2.5}), (Cells{{0, 0}, {0, -1}, {0, -2}}));
  // A shallow ray crosses into the next row within column 2.
  EXPECT_EQ(CellsBeforeEnd({0.5, 0.2}, {3.5, 1.2}), (Cells{{0, 0}, {1, 0}, {2, 0}, {2, 1}}));
  // Leftwards and down, across a column boundary first.
  EXPECT_EQ(CellsBeforeEnd({0.2, 0.9}, {-1.5, -0.5}), (Cells{{0, 0}, {-1, 0}, {-1, -1}}));
  EXPECT_TRUE(CellsBeforeEnd({0.3, 0.3}, {0.7, 0.9}).empty());  // ends in its own cell
}

TEST(RayCells, StopsWhenTheVisitorSaysSo) {
  Cells cells;
  ForEachCellBeforeEnd(Eigen::Vector2d(0.5, 0.5), Eigen::Vector2d(10.5, 0.5), [&](int c, int r) {
    cells.emplace_back(c, r);
    return c < 2;
  });
  EXPECT_EQ(cells, (Cells{{0, 0}, {1, 0}, {2, 0}}));
}

TEST(RayCells, VisitsNothingForNonFiniteOrFarPoints) {
  const double nan = std::nan("");
  EXPECT_TRUE(CellsBeforeEnd({nan, 0.0}, {3.0, 0.0}).empty());
  EXPECT_TRUE(CellsBeforeEnd({0.0, 0.0}, {INFINITY, 0.0}).empty());
  EXPECT_TRUE(CellsBeforeEnd({0.0, 0.0}, {2e6, 0.0}).empty());  // beyond max_cells
}

}  // namespace
}  // namespace keyplace
