#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <set>
#include <stdexcept>

#include "sim/cell_grid.h"

using namespace meshnav::sim;

TEST(SimCellGrid, FiveByFiveCellsOfEightMetresInAFortyMetreHall) {
  const CellGrid g(Hall::ofSize({40, 40, 10}), 5, 5);
  EXPECT_EQ(g.cellCount(), 25);
  EXPECT_DOUBLE_EQ(g.cellSize_m().x(), 8.0);
  EXPECT_DOUBLE_EQ(g.cellSize_m().y(), 8.0);
  EXPECT_EQ(g.cellOf({-19.9, -19.9, 5.0}), 0);
  EXPECT_EQ(g.cellOf({-12.01, -19.9, 5.0}), 0);
  EXPECT_EQ(g.cellOf({-12.0, -19.9, 5.0}), 1);  // the boundary belongs to the next cell
  EXPECT_EQ(g.cellOf({0.0, 0.0, 0.0}), g.cellAt(2, 2));
  EXPECT_EQ(g.cellOf({19.99, 19.99, 9.0}), 24);
  EXPECT_EQ(g.cellOf({50.0, -50.0, 0.0}), g.cellAt(4, 0));  // outside: the nearest cell
  EXPECT_EQ(g.indexX(7), 2);
  EXPECT_EQ(g.indexY(7), 1);
  EXPECT_EQ(g.neighbourhood(0), (std::vector<int>{0, 1, 5, 6}));
  EXPECT_EQ(g.neighbourhood(12), (std::vector<int>{6, 7, 8, 11, 12, 13, 16, 17, 18}));
  EXPECT_TRUE(g.neighbours(12, 18));
  EXPECT_TRUE(g.neighbours(12, 12));
  EXPECT_FALSE(g.neighbours(12, 14));
  EXPECT_FALSE(g.neighbours(0, 10));
}

TEST(SimCellGrid, CellsOfOneColourAreThreeApartAndTheirNeighbourhoodsShareNoCell) {
  const CellGrid g(Hall::ofSize({40, 40, 10}), 5, 5);
  EXPECT_EQ(g.colourCount(), 9);
  EXPECT_EQ(g.colour(0), 0);
  EXPECT_EQ(g.colour(g.cellAt(3, 0)), 0);
  EXPECT_EQ(g.colour(g.cellAt(1, 2)), 7);
  EXPECT_EQ(g.cellsOfColour(0), (std::vector<int>{0, 3, 15, 18}));
  EXPECT_EQ(g.cellsOfColour(4), (std::vector<int>{6, 9, 21, 24}));
  int total = 0;
  for (int c = 0; c < g.colourCount(); ++c) {
    const auto cells = g.cellsOfColour(c);
    total += static_cast<int>(cells.size());
    for (int a : cells)
      for (int b : cells) {
        if (a == b) continue;
        EXPECT_GE(std::max(std::abs(g.indexX(a) - g.indexX(b)), std::abs(g.indexY(a) - g.indexY(b))), 3);
        const auto na = g.neighbourhood(a), nb = g.neighbourhood(b);
        for (int x : na) EXPECT_EQ(std::count(nb.begin(), nb.end(), x), 0) << a << " and " << b << " share " << x;
      }
  }
  EXPECT_EQ(total, 25);  // every cell has one colour
}

TEST(SimCellGrid, SmallGridsHaveAColourPerCellAndBadSizesAreRefused) {
  const CellGrid g(Hall::ofSize({16, 16, 6}), 2, 2);
  EXPECT_EQ(g.colourCount(), 4);
  std::set<int> colours;
  for (int c = 0; c < 4; ++c) colours.insert(g.colour(c));
  EXPECT_EQ(colours.size(), 4u);
  EXPECT_THROW(CellGrid(Hall::ofSize({16, 16, 6}), 0, 2), std::invalid_argument);
  EXPECT_THROW(CellGrid(Hall::ofSize({16, 16, 6}), 2, 2, 0), std::invalid_argument);
}
