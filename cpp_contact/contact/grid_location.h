// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

#include "point_location.h"

#include <cstdint>
#include <span>
#include <vector>

namespace contact {

/// @brief Point location among the active cells of one body on a structured (tensor) grid: a
/// point's grid cell is found by bisection on the grid lines and looked up in a table over the
/// body's cells (plus an empty border), so the cost per point is O(log) in the lines and O(1)
/// in the cells, and the memory the body's size, not the grid's.
///
/// A point whose own grid cell is not one of the body's goes to the nearest of them among its
/// 3 x 3 neighbourhood (own cell first, then (0,-1), (0,1), (-1,0), (-1,-1), (-1,1), (1,0),
/// (1,-1), (1,1): the first of equally near ones), with extrapolated reference coordinates,
/// if it is within max_distance of it: what a closest point on the exact boundary needs where
/// the straight cut misses a sliver. Cells are axis-aligned rectangles with vertices in
/// DOLFINx order (0,0), (1,0), (0,1), (1,1).
class GridCellLocator {
public:
  /// @brief Index the cells.
  /// @param[in] xlines, ylines The grid lines (increasing, at least 2 each)
  /// @param[in] corners (n, 4, 2) vertex coordinates of each cell, DOLFINx order
  /// @param[in] cells (n,) the index reported for each cell (e.g. its mesh cell)
  /// @throws std::invalid_argument for sizes that do not match or lines not increasing
  GridCellLocator(std::span<const double> xlines, std::span<const double> ylines,
                  std::span<const double> corners, std::span<const std::int32_t> cells);

  /// @brief Locate (n, 2) points: cells (-1 where none within max_distance), reference
  /// coordinates X (NaN there) and outside (0 inside a cell, else the distance to the cell
  /// found; inf where none).
  LocatedPoints locate(std::span<const double> points, double max_distance) const;

  /// @brief Number of indexed cells.
  std::size_t num_cells() const { return _cells.size(); }

private:
  std::vector<double> _x, _y;
  std::vector<std::int32_t> _cells;
  std::vector<double> _v0, _ex, _ey, _lo, _hi; // (n, 2) each
  std::vector<std::int32_t> _table;            // (nxt, nyt), x-major: table[i * nyt + j]
  std::int64_t _i0 = 0, _j0 = 0, _nxt = 1, _nyt = 1;
  std::int64_t index(const std::vector<double>& lines, double t) const;
};

} // namespace contact
