// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "point_location.h"
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

using namespace contact;

namespace {
constexpr double inf = std::numeric_limits<double>::infinity();

/// Vertex order of the boundary polygon of a DOLFINx cell (quads are in tensor order)
constexpr int polygon_tri[3] = {0, 1, 2};
constexpr int polygon_quad[4] = {0, 1, 3, 2};

const int* polygon(int nverts) {
  return nverts == 3 ? polygon_tri : polygon_quad;
}

/// Float rounded towards -inf / +inf (boxes stay conservative)
float round_down(double t) {
  const float f = float(t);
  return double(f) > t ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
float round_up(double t) {
  const float f = float(t);
  return double(f) < t ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

std::string point_str(double x, double y) {
  return "(" + std::to_string(x) + ", " + std::to_string(y) + ")";
}

/// Squared distance from p to the rectangle [lo, hi] (0 inside)
double box_distance2(const double* lo, const double* hi, double px, double py) {
  const double dx = std::max(std::max(lo[0] - px, px - hi[0]), 0.0);
  const double dy = std::max(std::max(lo[1] - py, py - hi[1]), 0.0);
  return dx * dx + dy * dy;
}
} // namespace

CellLocator::CellLocator(std::span<const double> x, int gdim, std::span<const std::int32_t> cells,
                         int nverts, std::span<const std::int32_t> subset)
    : _nverts(nverts) {
  if (gdim != 2 and gdim != 3)
    throw std::invalid_argument("CellLocator: gdim must be 2 or 3, got " + std::to_string(gdim));
  if (x.size() % std::size_t(gdim) != 0)
    throw std::invalid_argument("CellLocator: x must have shape (nv, gdim) with gdim = " +
                                std::to_string(gdim));
  if (nverts != 3 and nverts != 4)
    throw std::invalid_argument("CellLocator: nverts must be 3 (triangles) or 4 "
                                "(quadrilaterals), got " +
                                std::to_string(nverts));
  if (cells.size() % std::size_t(nverts) != 0)
    throw std::invalid_argument("CellLocator: cells must have shape (nc, " +
                                std::to_string(nverts) + ")");
  const std::int64_t nv = std::int64_t(x.size() / std::size_t(gdim));
  const std::int64_t nc = std::int64_t(cells.size() / std::size_t(nverts));

  for (std::size_t i = 0; i < subset.size(); ++i)
    if (subset[i] < 0 or subset[i] >= nc)
      throw std::invalid_argument("CellLocator: subset[" + std::to_string(i) +
                                  "] = " + std::to_string(subset[i]) +
                                  " is not a cell index in [0, " + std::to_string(nc) + ")");
  std::vector<std::int32_t> ids(subset.begin(), subset.end());
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());

  const std::size_t n = ids.size();
  const int* poly = polygon(nverts);
  _cells.resize(n);
  double diam_sum = 0;
  for (std::size_t k = 0; k < n; ++k) {
    Cell& cell = _cells[k];
    cell = Cell{};
    cell.id = ids[k];
    double* v = cell.v;
    for (int i = 0; i < nverts; ++i) {
      const std::int32_t iv = cells[std::size_t(cell.id) * std::size_t(nverts) + std::size_t(i)];
      if (iv < 0 or iv >= nv)
        throw std::invalid_argument("CellLocator: cells: cell " + std::to_string(cell.id) +
                                    " has vertex index " + std::to_string(iv) + " outside [0, " +
                                    std::to_string(nv) + ")");
      v[2 * i] = x[std::size_t(iv) * std::size_t(gdim)];
      v[2 * i + 1] = x[std::size_t(iv) * std::size_t(gdim) + 1];
      if (!std::isfinite(v[2 * i]) or !std::isfinite(v[2 * i + 1]))
        throw std::invalid_argument("CellLocator: x: vertex " + std::to_string(iv) +
                                    " is not finite");
    }
    double diam = 0;
    double* b = cell.box;
    b[0] = b[2] = v[0];
    b[1] = b[3] = v[1];
    for (int i = 0; i < nverts; ++i) {
      b[0] = std::min(b[0], v[2 * i]), b[2] = std::max(b[2], v[2 * i]);
      b[1] = std::min(b[1], v[2 * i + 1]), b[3] = std::max(b[3], v[2 * i + 1]);
      for (int j = 0; j < i; ++j)
        diam = std::max(diam, std::hypot(v[2 * i] - v[2 * j], v[2 * i + 1] - v[2 * j + 1]));
    }
    // Twice the signed area of the boundary polygon, and the turn at each corner
    double area2 = 0;
    double turn[4];
    for (int i = 0; i < nverts; ++i) {
      const double* a = v + 2 * poly[i];
      const double* q = v + 2 * poly[(i + 1) % nverts];
      const double* r = v + 2 * poly[(i + 2) % nverts];
      area2 += a[0] * q[1] - a[1] * q[0];
      turn[i] = (q[0] - a[0]) * (r[1] - q[1]) - (q[1] - a[1]) * (r[0] - q[0]);
    }
    if (!(std::abs(area2) > 1e-14 * diam * diam))
      throw std::invalid_argument("CellLocator: cells: cell " + std::to_string(cell.id) +
                                  " is degenerate (zero area)");
    cell.sign = area2 > 0 ? 1.0 : -1.0;
    if (nverts == 4)
      for (int i = 0; i < 4; ++i)
        if (!(cell.sign * turn[i] > 0))
          throw std::invalid_argument(
              "CellLocator: cells: quadrilateral " + std::to_string(cell.id) +
              " is not convex (or not in DOLFINx tensor order (0,0),(1,0),(0,1),(1,1))");
    cell.tol = tolerance * diam;
    // Inflated so that every cell containing a point up to the tolerance is in its bin
    for (int d = 0; d < 2; ++d)
      b[d] -= 2 * cell.tol, b[2 + d] += 2 * cell.tol;
    diam_sum += diam;
  }

  _offsets.assign(1, 0);
  if (n == 0)
    return;

  // Bin grid over the bounding box of the subset, bins of about the mean cell diameter
  std::array<double, 2> hi;
  for (int d = 0; d < 2; ++d) {
    _lo[d] = _cells[0].box[d];
    hi[d] = _cells[0].box[2 + d];
    for (const Cell& c : _cells) {
      _lo[d] = std::min(_lo[d], c.box[d]);
      hi[d] = std::max(hi[d], c.box[2 + d]);
    }
  }
  const double hmean = diam_sum / double(n);
  std::array<double, 2> nb;
  for (int d = 0; d < 2; ++d)
    nb[d] = std::max(1.0, std::ceil((hi[d] - _lo[d]) / hmean));
  // Scattered subsets (e.g. two far-apart clusters) must not create a huge empty grid
  const double max_bins = 4.0 * double(n) + 16.0;
  if (nb[0] * nb[1] > max_bins) {
    const double s = std::sqrt(nb[0] * nb[1] / max_bins);
    for (int d = 0; d < 2; ++d)
      nb[d] = std::max(1.0, std::floor(nb[d] / s));
  }
  for (int d = 0; d < 2; ++d) {
    _nb[d] = std::int32_t(nb[d]);
    _h[d] = (hi[d] - _lo[d]) / nb[d];
  }

  // Cells of a bin stored close together in memory: sorted by the bin of their box centre
  // (then by mesh index); pos[k] is the new place of the k-th cell by mesh index
  std::vector<std::pair<std::size_t, std::int32_t>> key(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double* b = _cells[k].box;
    key[k] = {std::size_t(bin(1, 0.5 * (b[1] + b[3]))) * std::size_t(_nb[0]) +
                  std::size_t(bin(0, 0.5 * (b[0] + b[2]))),
              std::int32_t(k)};
  }
  std::sort(key.begin(), key.end());
  std::vector<Cell> sorted(n);
  std::vector<std::int32_t> pos(n);
  for (std::size_t k = 0; k < n; ++k) {
    sorted[k] = _cells[std::size_t(key[k].second)];
    pos[std::size_t(key[k].second)] = std::int32_t(k);
  }
  _cells = std::move(sorted);

  // Register the cells by increasing mesh index: each bin's list is sorted by mesh index
  const std::size_t nbins = std::size_t(_nb[0]) * std::size_t(_nb[1]);
  _offsets.assign(nbins + 1, 0);
  std::vector<std::int32_t> fill;
  for (int pass = 0; pass < 2; ++pass) {
    if (pass == 1) {
      for (std::size_t i = 0; i < nbins; ++i)
        _offsets[i + 1] += _offsets[i];
      _bins.resize(std::size_t(_offsets.back()));
      fill.assign(_offsets.begin(), _offsets.end() - 1);
    }
    for (std::int32_t k : pos) {
      const double* b = _cells[std::size_t(k)].box;
      Entry e{{round_down(b[0]), round_down(b[1]), round_up(b[2]), round_up(b[3])}, k};
      for (std::int32_t j = bin(1, b[1]); j <= bin(1, b[3]); ++j)
        for (std::int32_t i = bin(0, b[0]); i <= bin(0, b[2]); ++i) {
          const std::size_t ib = std::size_t(i) + std::size_t(_nb[0]) * std::size_t(j);
          if (pass == 0)
            ++_offsets[ib + 1];
          else
            _bins[std::size_t(fill[ib]++)] = e;
        }
    }
  }
}

std::int32_t CellLocator::bin(int d, double t) const {
  const double f = std::floor((t - _lo[std::size_t(d)]) / _h[std::size_t(d)]);
  return std::int32_t(std::clamp(f, 0.0, double(_nb[std::size_t(d)] - 1)));
}

double CellLocator::distance(const Cell& c, std::array<double, 2> p) const {
  const double* v = c.v;
  const int* poly = polygon(_nverts);
  bool inside = true;
  for (int i = 0; i < _nverts and inside; ++i) {
    const double* a = v + 2 * poly[i];
    const double* b = v + 2 * poly[(i + 1) % _nverts];
    inside = c.sign * ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])) >= 0;
  }
  if (inside)
    return 0.0;
  // Outside a convex polygon: the distance is the distance to its boundary
  double d2 = inf;
  for (int i = 0; i < _nverts; ++i) {
    const double* a = v + 2 * poly[i];
    const double* b = v + 2 * poly[(i + 1) % _nverts];
    const double e[2] = {b[0] - a[0], b[1] - a[1]}, w[2] = {p[0] - a[0], p[1] - a[1]};
    const double t =
        std::clamp((w[0] * e[0] + w[1] * e[1]) / (e[0] * e[0] + e[1] * e[1]), 0.0, 1.0);
    const double r[2] = {w[0] - t * e[0], w[1] - t * e[1]};
    d2 = std::min(d2, r[0] * r[0] + r[1] * r[1]);
  }
  return std::sqrt(d2);
}

std::array<double, 2> CellLocator::pull_back(const Cell& cell, std::array<double, 2> p) const {
  const double* v = cell.v;
  // x(X) = v0 + a X0 + b X1 + c X0 X1 (c = 0 for triangles)
  const double a[2] = {v[2] - v[0], v[3] - v[1]};
  const double b[2] = {v[4] - v[0], v[5] - v[1]};
  const double y[2] = {p[0] - v[0], p[1] - v[1]};
  if (_nverts == 3) {
    const double det = a[0] * b[1] - a[1] * b[0];
    return {(b[1] * y[0] - b[0] * y[1]) / det, (a[0] * y[1] - a[1] * y[0]) / det};
  }
  const double c[2] = {v[6] - v[2] - v[4] + v[0], v[7] - v[3] - v[5] + v[1]};
  const double scale = cell.tol / tolerance; // cell diameter
  std::array<double, 2> X = {0.5, 0.5};
  for (int it = 0; it < max_newton_iterations; ++it) {
    const double r[2] = {a[0] * X[0] + b[0] * X[1] + c[0] * X[0] * X[1] - y[0],
                         a[1] * X[0] + b[1] * X[1] + c[1] * X[0] * X[1] - y[1]};
    const double J[4] = {a[0] + c[0] * X[1], b[0] + c[0] * X[0], //
                         a[1] + c[1] * X[1], b[1] + c[1] * X[0]};
    const double det = J[0] * J[3] - J[1] * J[2];
    if (!(std::abs(det) > 1e-12 * scale * scale))
      break; // singular Jacobian: on the fold of the bilinear map
    const double dX[2] = {-(J[3] * r[0] - J[1] * r[1]) / det, -(J[0] * r[1] - J[2] * r[0]) / det};
    X[0] += dX[0], X[1] += dX[1];
    // Quadratic convergence: after a step of 1e-13 the error is at round-off level
    if (std::max(std::abs(dX[0]), std::abs(dX[1])) <=
        1e-13 * std::max({1.0, std::abs(X[0]), std::abs(X[1])}))
      return X;
  }
  throw std::runtime_error("CellLocator: Newton pull-back of " + point_str(p[0], p[1]) +
                           " into quadrilateral cell " + std::to_string(cell.id) +
                           " did not converge in " + std::to_string(max_newton_iterations) +
                           " iterations: the point is beyond the fold of the bilinear map, far "
                           "outside the cell (reduce max_distance below the cell size)");
}

LocatedPoints CellLocator::locate(std::span<const double> points, double max_distance) const {
  if (points.size() % 2 != 0)
    throw std::invalid_argument("CellLocator::locate: points must have shape (n, 2)");
  if (!(max_distance >= 0))
    throw std::invalid_argument("CellLocator::locate: max_distance must be >= 0, got " +
                                std::to_string(max_distance));
  const std::size_t n = points.size() / 2;
  LocatedPoints r;
  r.cells.assign(n, -1);
  r.X.assign(2 * n, std::numeric_limits<double>::quiet_NaN());
  r.outside.assign(n, inf);

  const std::array<double, 2> hi = {_lo[0] + _nb[0] * _h[0], _lo[1] + _nb[1] * _h[1]};
  // Slack of the pruning tests against round-off in the bin geometry
  const double slack = 1e-9 * std::min(_h[0], _h[1]);
  for (std::size_t p = 0; p < n; ++p) {
    const double px = points[2 * p], py = points[2 * p + 1];
    if (!std::isfinite(px) or !std::isfinite(py))
      throw std::invalid_argument("CellLocator::locate: points: point " + std::to_string(p) +
                                  " is not finite");
    if (_cells.empty() or
        box_distance2(_lo.data(), hi.data(), px, py) > max_distance * max_distance)
      continue;
    const std::array<double, 2> pt = {px, py};
    const std::int32_t i0 = bin(0, px), j0 = bin(1, py);
    const Cell* best = nullptr;
    double best_d = inf;

    // Examine the cells of bin (i, j); true once a containing cell is found. All cells
    // containing the point are in its own bin (first visited), sorted by mesh index: the first
    // one found is the lowest. A cell met again in another bin gives the same (d, id): no-op.
    auto visit = [&](std::int32_t i, std::int32_t j) {
      const double blo[2] = {_lo[0] + i * _h[0], _lo[1] + j * _h[1]};
      const double bhi[2] = {blo[0] + _h[0], blo[1] + _h[1]};
      const double lim = std::min(best_d, max_distance);
      if (box_distance2(blo, bhi, px, py) > (lim + slack) * (lim + slack))
        return false;
      const std::size_t ib = std::size_t(i) + std::size_t(_nb[0]) * std::size_t(j);
      double l2 = lim * lim; // squared search radius
      for (std::int32_t q = _offsets[ib]; q < _offsets[ib + 1]; ++q) {
        const Entry& e = _bins[std::size_t(q)];
        const double dx = std::max(std::max(double(e.box[0]) - px, px - double(e.box[2])), 0.0);
        const double dy = std::max(std::max(double(e.box[1]) - py, py - double(e.box[3])), 0.0);
        if (dx * dx + dy * dy > l2)
          continue;
        const Cell& c = _cells[std::size_t(e.k)];
        double d = distance(c, pt);
        if (d <= c.tol)
          d = 0;
        if (d < best_d or (d == best_d and c.id < best->id)) {
          best = &c, best_d = d;
          l2 = std::min(best_d, max_distance);
          l2 *= l2;
        }
        if (best_d == 0)
          return true;
      }
      return false;
    };

    bool done = visit(i0, j0);
    for (std::int32_t ring = 1; !done; ++ring) {
      // Cells not yet examined lie outside the block of bins within ring - 1 of (i0, j0):
      // the distance to the nearest side of the block bounds their distance from below
      const std::int32_t m = ring - 1;
      double lb = inf;
      if (i0 - m > 0)
        lb = std::min(lb, px - (_lo[0] + (i0 - m) * _h[0]));
      if (i0 + m < _nb[0] - 1)
        lb = std::min(lb, _lo[0] + (i0 + m + 1) * _h[0] - px);
      if (j0 - m > 0)
        lb = std::min(lb, py - (_lo[1] + (j0 - m) * _h[1]));
      if (j0 + m < _nb[1] - 1)
        lb = std::min(lb, _lo[1] + (j0 + m + 1) * _h[1] - py);
      if (lb == inf or lb - slack > std::min(best_d, max_distance))
        break; // the block covers the grid, or no unexamined cell can be nearer
      // Ring `ring` around (i0, j0), clipped to the grid: bottom and top rows, then the sides
      const std::int32_t ia = std::max(i0 - ring, 0), ib = std::min(i0 + ring, _nb[0] - 1);
      const std::int32_t ja = std::max(j0 - ring + 1, 0), jb = std::min(j0 + ring - 1, _nb[1] - 1);
      for (std::int32_t i = ia; i <= ib; ++i) {
        if (j0 - ring >= 0)
          visit(i, j0 - ring);
        if (j0 + ring < _nb[1])
          visit(i, j0 + ring);
      }
      for (std::int32_t j = ja; j <= jb; ++j) {
        if (i0 - ring >= 0)
          visit(i0 - ring, j);
        if (i0 + ring < _nb[0])
          visit(i0 + ring, j);
      }
    }
    if (!best or best_d > max_distance)
      continue;

    std::array<double, 2> X;
    try {
      X = pull_back(*best, pt);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error("CellLocator::locate: point " + std::to_string(p) + ": " + e.what());
    }
    const double t = tolerance;
    const bool inside = _nverts == 3
                            ? (X[0] >= -t and X[1] >= -t and X[0] + X[1] <= 1 + t)
                            : (X[0] >= -t and X[1] >= -t and X[0] <= 1 + t and X[1] <= 1 + t);
    r.cells[p] = best->id;
    r.X[2 * p] = X[0];
    r.X[2 * p + 1] = X[1];
    if (inside)
      r.outside[p] = 0.0;
    else {
      // outside > 0 exactly when X is outside the reference cell (up to the tolerance)
      const double d = best_d > 0 ? best_d : distance(*best, pt);
      r.outside[p] = d > 0 ? d : std::numeric_limits<double>::min();
    }
  }
  return r;
}
