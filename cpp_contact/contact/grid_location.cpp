// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "grid_location.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace contact {

namespace {
// the own grid cell first, then its 8 neighbours
constexpr std::array<std::array<int, 2>, 9> neighbours{
    {{0, 0}, {0, -1}, {0, 1}, {-1, 0}, {-1, -1}, {-1, 1}, {1, 0}, {1, -1}, {1, 1}}};
} // namespace

std::int64_t GridCellLocator::index(const std::vector<double>& lines, double t) const {
  // the last line <= t (numpy searchsorted side "right", minus one), within the cells
  const auto k = std::int64_t(std::upper_bound(lines.begin(), lines.end(), t) - lines.begin()) - 1;
  return std::clamp<std::int64_t>(k, 0, std::int64_t(lines.size()) - 2);
}

GridCellLocator::GridCellLocator(std::span<const double> xlines, std::span<const double> ylines,
                                 std::span<const double> corners,
                                 std::span<const std::int32_t> cells)
    : _x(xlines.begin(), xlines.end()), _y(ylines.begin(), ylines.end()),
      _cells(cells.begin(), cells.end()) {
  if (_x.size() < 2 or _y.size() < 2 or !std::is_sorted(_x.begin(), _x.end()) or
      !std::is_sorted(_y.begin(), _y.end()))
    throw std::invalid_argument("GridCellLocator: xlines and ylines must be increasing, at "
                                "least 2 each");
  const std::size_t n = cells.size();
  if (corners.size() != 8 * n)
    throw std::invalid_argument("GridCellLocator: corners must hold (n, 4, 2) coordinates for "
                                "the n = " +
                                std::to_string(n) + " cells");
  _v0.resize(2 * n), _ex.resize(2 * n), _ey.resize(2 * n), _lo.resize(2 * n), _hi.resize(2 * n);
  std::vector<std::int64_t> ci(n), cj(n);
  for (std::size_t c = 0; c < n; ++c) {
    const double* v = corners.data() + 8 * c;
    std::array<double, 2> centre{};
    for (int a = 0; a < 2; ++a) {
      _v0[2 * c + a] = v[a];
      _ex[2 * c + a] = v[2 + a] - v[a];
      _ey[2 * c + a] = v[4 + a] - v[a];
      _lo[2 * c + a] = std::min({v[a], v[2 + a], v[4 + a], v[6 + a]});
      _hi[2 * c + a] = std::max({v[a], v[2 + a], v[4 + a], v[6 + a]});
      centre[a] = (((v[a] + v[2 + a]) + v[4 + a]) + v[6 + a]) / 4.0;
    }
    ci[c] = index(_x, centre[0]);
    cj[c] = index(_y, centre[1]);
  }
  if (n > 0) {
    const auto [imin, imax] = std::minmax_element(ci.begin(), ci.end());
    const auto [jmin, jmax] = std::minmax_element(cj.begin(), cj.end());
    // the body's cells and a border of one empty cell: a point beyond it has none of them in
    // its 3 x 3 neighbourhood
    _i0 = *imin - 1, _j0 = *jmin - 1;
    _nxt = *imax - *imin + 3, _nyt = *jmax - *jmin + 3;
  }
  _table.assign(std::size_t(_nxt * _nyt), -1);
  for (std::size_t c = 0; c < n; ++c)
    _table[std::size_t((ci[c] - _i0) * _nyt + (cj[c] - _j0))] = std::int32_t(c);
}

LocatedPoints GridCellLocator::locate(std::span<const double> points, double max_distance) const {
  const std::size_t n = points.size() / 2;
  constexpr double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  LocatedPoints out{std::vector<std::int32_t>(n, -1), std::vector<double>(2 * n, nan),
                    std::vector<double>(n, inf)};
  if (_cells.empty())
    return out;
  for (std::size_t p = 0; p < n; ++p) {
    const double px = points[2 * p], py = points[2 * p + 1];
    const std::int64_t li = index(_x, px) - _i0, lj = index(_y, py) - _j0;
    if (li < 0 or li >= _nxt or lj < 0 or lj >= _nyt)
      continue;
    std::int32_t best = -1;
    double dist = inf;
    for (const auto& [di, dj] : neighbours) {
      const std::int64_t ii = std::clamp<std::int64_t>(li + di, 0, _nxt - 1);
      const std::int64_t jj = std::clamp<std::int64_t>(lj + dj, 0, _nyt - 1);
      const std::int32_t k = _table[std::size_t(ii * _nyt + jj)];
      if (k < 0)
        continue;
      const double dx = std::max(0.0, std::max(_lo[2 * k] - px, px - _hi[2 * k]));
      const double dy = std::max(0.0, std::max(_lo[2 * k + 1] - py, py - _hi[2 * k + 1]));
      const double d = std::sqrt(dx * dx + dy * dy);
      if (d < dist)
        best = k, dist = d;
      if (dist == 0) // a cell holding the point cannot be bettered
        break;
    }
    if (best < 0 or !(dist <= max_distance))
      continue;
    const std::size_t k = std::size_t(best);
    const double rx = px - _v0[2 * k], ry = py - _v0[2 * k + 1];
    const double* ex = &_ex[2 * k];
    const double* ey = &_ey[2 * k];
    out.cells[p] = _cells[k];
    out.X[2 * p] = (rx * ex[0] + ry * ex[1]) / (ex[0] * ex[0] + ex[1] * ex[1]);
    out.X[2 * p + 1] = (rx * ey[0] + ry * ey[1]) / (ey[0] * ey[0] + ey[1] * ey[1]);
    out.outside[p] = dist;
  }
  return out;
}

} // namespace contact
