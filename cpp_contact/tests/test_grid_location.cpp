// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Point location among a body's cells of a structured grid, against the definition: the cell
// holding a point, else the nearest cell of its 3 x 3 neighbourhood within max_distance.
#include <cmath>
#include <contact/grid_location.h>
#include <gtest/gtest.h>
#include <vector>

using namespace contact;

namespace {
/// An L-shaped body on the grid lines 0, 1, ..., 6 (both axes): cells (i, j) with i, j in
/// [1, 3] except (3, 3), reported as 100 + 10 i + j.
struct LBody {
  std::vector<double> lines{0, 1, 2, 3, 4, 5, 6};
  std::vector<double> corners;
  std::vector<std::int32_t> ids;
  LBody() {
    for (int j = 1; j <= 3; ++j)
      for (int i = 1; i <= 3; ++i) {
        if (i == 3 and j == 3)
          continue;
        for (auto [a, b] : {std::pair{0, 0}, {1, 0}, {0, 1}, {1, 1}})
          corners.insert(corners.end(), {double(i + a), double(j + b)});
        ids.push_back(100 + 10 * i + j);
      }
  }
};
} // namespace

TEST(GridCellLocator, InsideNeighbourAndBeyond) {
  const LBody body;
  const GridCellLocator loc(body.lines, body.lines, body.corners, body.ids);
  EXPECT_EQ(loc.num_cells(), 8u);
  // inside (2.25, 1.5): cell (2, 1), X = (0.25, 0.5)
  // in the missing cell (3, 3) at (3.5, 3.9): nearest (2, 3) at 0.5 or (3, 2) at 0.9 -> (2, 3)
  // just outside the body at (4.2, 2.5): cell (3, 2) at distance 0.2
  // two cells beyond the body (5.5, 5.5): none, whatever max_distance
  const std::vector<double> pts{2.25, 1.5, 3.5, 3.9, 4.2, 2.5, 5.5, 5.5};
  const LocatedPoints r = loc.locate(pts, 1.0);
  EXPECT_EQ(r.cells[0], 121);
  EXPECT_DOUBLE_EQ(r.X[0], 0.25);
  EXPECT_DOUBLE_EQ(r.X[1], 0.5);
  EXPECT_EQ(r.outside[0], 0.0);
  EXPECT_EQ(r.cells[1], 123);
  EXPECT_NEAR(r.outside[1], 0.5, 1e-15);
  EXPECT_NEAR(r.X[2], 1.5, 1e-15); // extrapolated beyond the cell
  EXPECT_EQ(r.cells[2], 132);
  EXPECT_NEAR(r.outside[2], 0.2, 1e-15);
  EXPECT_EQ(r.cells[3], -1);
  EXPECT_TRUE(std::isnan(r.X[6]) and std::isinf(r.outside[3]));
  // within the neighbourhood but beyond max_distance: none
  const LocatedPoints s = loc.locate(std::vector<double>{4.2, 2.5}, 0.1);
  EXPECT_EQ(s.cells[0], -1);
}

TEST(GridCellLocator, BadInput) {
  const LBody body;
  EXPECT_THROW(GridCellLocator(std::vector<double>{0.0}, body.lines, body.corners, body.ids),
               std::invalid_argument);
  EXPECT_THROW(GridCellLocator(body.lines, body.lines,
                               std::span<const double>(body.corners).first(8), body.ids),
               std::invalid_argument);
}
