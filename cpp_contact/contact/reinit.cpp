// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "reinit.h"
#include "projection.h"
#include "shapes.h"
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>

using namespace contact;

namespace {
constexpr double inf = std::numeric_limits<double>::infinity();

/// Root u >= max(a, b) of ((u - a)/hx)^2 + ((u - b)/hy)^2 = 1 with the Godunov
/// switch: a direction whose neighbour is not upwind of u drops out.
inline double godunov2(double a, double hx, double b, double hy) {
  // One-sided cases first; they also absorb infinite neighbours (inf <= inf).
  if (a + hx <= b)
    return a + hx;
  if (b + hy <= a)
    return b + hy;
  // Both terms active; here |a - b| < max(hx, hy), so the discriminant is > 0.
  const double hx2 = hx * hx, hy2 = hy * hy, ab = a - b;
  return (a * hy2 + b * hx2 + hx * hy * std::sqrt(hx2 + hy2 - ab * ab)) / (hx2 + hy2);
}

/// Upwind neighbours along one axis as (value, spacing) pairs; returns how many
/// must be tried. The update is increasing in both the value and the spacing,
/// so a neighbour that is not better in either is dominated. On a uniform axis
/// this always leaves one, on a graded axis sometimes two.
inline int upwind_pair(double am, double hm, double ap, double hp, double* a, double* h) {
  if (am <= ap and hm <= hp) {
    a[0] = am, h[0] = hm;
    return 1;
  }
  if (ap <= am and hp <= hm) {
    a[0] = ap, h[0] = hp;
    return 1;
  }
  a[0] = am, h[0] = hm, a[1] = ap, h[1] = hp;
  return 2;
}

/// Physical width of `band` cells around node i of an axis: a point closer than
/// this to node i along the axis lies within `band` node indices of it.
double band_width(const std::vector<double>& a, std::size_t i, std::size_t band) {
  double w = inf;
  if (i + band < a.size())
    w = std::min(w, a[i + band] - a[i]);
  if (i >= band)
    w = std::min(w, a[i] - a[i - band]);
  return w;
}
} // namespace

//-----------------------------------------------------------------------------
void contact::fast_sweep(const StructuredGrid& grid, std::span<double> d,
                         std::span<const std::int8_t> fixed, int max_sweeps, double cap) {
  const std::size_t n = grid.num_nodes();
  if (d.size() != n or fixed.size() != n)
    throw std::invalid_argument("fast_sweep: d and fixed must have one entry per node (" +
                                std::to_string(n) + ")");
  if (max_sweeps < 1)
    throw std::invalid_argument("fast_sweep: max_sweeps must be >= 1");

  bool any_fixed = false;
  for (std::size_t k = 0; k < n; ++k) {
    if (fixed[k]) {
      if (!std::isfinite(d[k]))
        throw std::invalid_argument("fast_sweep: fixed node " + std::to_string(k) +
                                    " has a non-finite value");
      d[k] = std::abs(d[k]);
      any_fixed = true;
    } else
      d[k] = cap;
  }
  if (!any_fixed)
    throw std::invalid_argument("fast_sweep: no fixed node to sweep from");

  const auto& x = grid.axis(0);
  const auto& y = grid.axis(1);
  const std::ptrdiff_t nx = std::ptrdiff_t(x.size()), ny = std::ptrdiff_t(y.size());
  double* u = d.data();
  const std::int8_t* fx = fixed.data();

  // Relaxes node (i, j); returns true if its value dropped by more than round-off.
  auto relax = [&](std::ptrdiff_t i, std::ptrdiff_t j) -> bool {
    const std::ptrdiff_t k = i + nx * j;
    if (fx[k])
      return false;
    // Boundary nodes have one neighbour per axis; the missing one is "infinitely far".
    const double am = i > 0 ? u[k - 1] : inf, hm = i > 0 ? x[i] - x[i - 1] : inf;
    const double ap = i + 1 < nx ? u[k + 1] : inf, hp = i + 1 < nx ? x[i + 1] - x[i] : inf;
    const double bm = j > 0 ? u[k - nx] : inf, gm = j > 0 ? y[j] - y[j - 1] : inf;
    const double bp = j + 1 < ny ? u[k + nx] : inf, gp = j + 1 < ny ? y[j + 1] - y[j] : inf;
    // every update exceeds the smallest neighbour: none below u[k], nothing to do (the far
    // field before the front reaches it, or beyond a cap)
    if (std::min(std::min(am, ap), std::min(bm, bp)) >= u[k])
      return false;
    double a[2], hx[2], b[2], hy[2];
    const int na = upwind_pair(am, hm, ap, hp, a, hx);
    const int nb = upwind_pair(bm, gm, bp, gp, b, hy);
    // min over neighbour choices = root of the Godunov Hamiltonian with per-side spacings
    double unew = u[k];
    for (int p = 0; p < na; ++p)
      for (int q = 0; q < nb; ++q)
        unew = std::min(unew, godunov2(a[p], hx[p], b[q], hy[q]));
    const bool changed = u[k] - unew > 1e-14 * unew;
    u[k] = unew;
    return changed;
  };

  // Rounds of the four Gauss-Seidel orderings, so each characteristic direction
  // is followed once per round. A sweep that changes nothing has evaluated
  // every update with final values, i.e. reached the fixed point: stop there
  // rather than at the end of the round.
  for (int sweep = 0; sweep < 4 * max_sweeps; ++sweep) {
    const int ordering = sweep % 4;
    const bool xrev = ordering == 1 or ordering == 2, yrev = ordering >= 2;
    bool changed = false;
    for (std::ptrdiff_t jj = 0; jj < ny; ++jj) {
      const std::ptrdiff_t j = yrev ? ny - 1 - jj : jj;
      if (xrev)
        for (std::ptrdiff_t i = nx - 1; i >= 0; --i)
          changed |= relax(i, j);
      else
        for (std::ptrdiff_t i = 0; i < nx; ++i)
          changed |= relax(i, j);
    }
    if (!changed)
      break;
  }
}
//-----------------------------------------------------------------------------
LevelSet contact::reinitialize(const LevelSet& phi, int max_sweeps, double cap) {
  const StructuredGrid& grid = phi.grid();
  std::span<const double> v = phi.values();
  const std::size_t n = v.size();
  const auto& x = grid.axis(0);
  const auto& y = grid.axis(1);
  const std::size_t nx = x.size(), ny = y.size();

  bool neg = false, pos = false, zero = false;
  for (double vk : v) {
    neg |= vk < 0;
    pos |= vk > 0;
    zero |= vk == 0;
  }
  if (!zero and !(neg and pos))
    throw std::invalid_argument("reinitialize: phi has no zero contour (all node values are " +
                                std::string(neg ? "negative" : "positive") + ")");

  // Nodes of crossed cells. The contour passes through every crossed cell (an
  // edge with a sign change has a root of the interpolant), so a corner's
  // distance to it is at most that cell's diagonal: `bound` rejects
  // projections that converged to a farther part of the contour.
  std::vector<double> bound(n, inf);
  for (std::size_t j = 0; j + 1 < ny; ++j)
    for (std::size_t i = 0; i + 1 < nx; ++i) {
      const std::size_t k[4] = {grid.node(i, j), grid.node(i + 1, j), grid.node(i, j + 1),
                                grid.node(i + 1, j + 1)};
      const auto [lo, hi] = std::minmax({v[k[0]], v[k[1]], v[k[2]], v[k[3]]});
      if (lo <= 0 and hi >= 0) {
        const double diag = std::hypot(x[i + 1] - x[i], y[j + 1] - y[j]);
        for (std::size_t c : k)
          bound[c] = std::min(bound[c], diag);
      }
    }

  // Their 8 neighbours too: the Hermite slopes of a crossed cell are central
  // differences over these, and exact values there keep the new contour within
  // O(h^3) of the old one; swept values (O(h^2) off) would move it by O(h^2).
  const std::vector<double> bound0 = bound;
  for (std::size_t j = 0; j < ny; ++j)
    for (std::size_t i = 0; i < nx; ++i) {
      const double b = bound0[grid.node(i, j)];
      if (b == inf)
        continue;
      for (std::size_t jn = j > 0 ? j - 1 : 0; jn <= std::min(j + 1, ny - 1); ++jn)
        for (std::size_t in = i > 0 ? i - 1 : 0; in <= std::min(i + 1, nx - 1); ++in) {
          double& bn = bound[grid.node(in, jn)];
          bn = std::min(bn, b + std::hypot(x[in] - x[i], y[jn] - y[j]));
        }
    }

  std::vector<double> d(n, 0.0);
  std::vector<std::int8_t> fixed(n, 0);
  std::vector<std::size_t> ids;
  std::vector<double> x0;
  for (std::size_t j = 0; j < ny; ++j)
    for (std::size_t i = 0; i < nx; ++i) {
      const std::size_t k = grid.node(i, j);
      if (bound[k] == inf)
        continue;
      fixed[k] = 1;
      // A zero node is on the contour: d = 0 already
      if (v[k] != 0) {
        ids.push_back(k);
        x0.insert(x0.end(), {x[i], y[j]});
      }
    }

  const ProjectionResult proj = closest_point_projection(phi, x0);
  for (std::size_t p = 0; p < ids.size(); ++p) {
    const std::size_t k = ids[p];
    const double* xp = x0.data() + 2 * p;
    const double* pp = proj.points.data() + 2 * p;
    const double dist = std::hypot(pp[0] - xp[0], pp[1] - xp[1]);
    if (proj.status[p] == ProjectionStatus::converged and dist <= bound[k] * (1 + 1e-12)) {
      d[k] = dist;
      continue;
    }
    // First-order estimate; the contour is still no farther than the bound
    std::array<double, 2> g;
    phi.eval(std::span<const double, 2>(xp, 2), g);
    const double gn = std::hypot(g[0], g[1]);
    if (gn > 0)
      d[k] = std::min(std::abs(v[k]) / gn, bound[k]);
    else
      fixed[k] = 0; // no usable information: let the sweep fill it
  }

  fast_sweep(grid, d, fixed, max_sweeps, cap);
  for (std::size_t k = 0; k < n; ++k)
    d[k] = v[k] < 0 ? -d[k] : (v[k] > 0 ? d[k] : 0.0);
  return LevelSet(grid, std::move(d));
}
//-----------------------------------------------------------------------------
LevelSet contact::levelset_from_polyline(const StructuredGrid& grid,
                                         std::span<const double> vertices, int band) {
  if (vertices.size() % 2 != 0)
    throw std::invalid_argument("levelset_from_polyline: vertices must be a flattened (m, 2) "
                                "array");
  const std::size_t m = vertices.size() / 2;
  if (m < 3)
    throw std::invalid_argument("levelset_from_polyline: vertices must hold at least 3 "
                                "points, got " +
                                std::to_string(m));
  for (std::size_t p = 0; p < vertices.size(); ++p)
    if (!std::isfinite(vertices[p]))
      throw std::invalid_argument("levelset_from_polyline: vertices: coordinate " +
                                  std::to_string(p) + " is not finite");
  if (band < 1)
    throw std::invalid_argument("levelset_from_polyline: band must be >= 1, got " +
                                std::to_string(band));

  const auto& x = grid.axis(0);
  const auto& y = grid.axis(1);
  const std::size_t nx = x.size(), ny = y.size(), n = grid.num_nodes();
  const std::size_t nb = std::size_t(band);

  // Segment k joins vertex k and k+1 with its endpoints in a canonical order,
  // so that a reversed polyline produces bit-identical arithmetic.
  auto segment = [&](std::size_t k) -> std::array<double, 4> {
    const std::size_t l = (k + 1) % m;
    std::array<double, 4> s = {vertices[2 * k], vertices[2 * k + 1], vertices[2 * l],
                               vertices[2 * l + 1]};
    if (std::tie(s[1], s[0]) > std::tie(s[3], s[2]))
      s = {s[2], s[3], s[0], s[1]};
    return s;
  };

  // Exact distance over each segment's bounding box grown by `band` cells
  std::vector<double> d(n, inf);
  auto clamp_to = [](const std::vector<double>& a, double t) {
    return std::clamp(t, a.front(), a.back());
  };
  for (std::size_t k = 0; k < m; ++k) {
    const auto [ax, ay, bx, by] = segment(k);
    const std::size_t i0 = grid.locate_axis(0, clamp_to(x, std::min(ax, bx)));
    const std::size_t i1 = grid.locate_axis(0, clamp_to(x, std::max(ax, bx))) + 1;
    const std::size_t j0 = grid.locate_axis(1, clamp_to(y, std::min(ay, by)));
    const std::size_t j1 = grid.locate_axis(1, clamp_to(y, std::max(ay, by))) + 1;
    const std::size_t ilo = i0 > nb ? i0 - nb : 0, ihi = std::min(i1 + nb, nx - 1);
    const std::size_t jlo = j0 > nb ? j0 - nb : 0, jhi = std::min(j1 + nb, ny - 1);
    for (std::size_t j = jlo; j <= jhi; ++j)
      for (std::size_t i = ilo; i <= ihi; ++i) {
        double& dk = d[grid.node(i, j)];
        dk = std::min(dk, segment_distance({x[i], y[j]}, {ax, ay}, {bx, by}));
      }
  }

  // A node whose nearest segment lies within band_width of it (per axis) is
  // inside that segment's box, so a value <= that width is the exact minimum
  // over all segments; anything larger may have missed a segment.
  std::vector<std::int8_t> fixed(n, 0);
  std::vector<double> wx(nx);
  for (std::size_t i = 0; i < nx; ++i)
    wx[i] = band_width(x, i, nb);
  bool any_fixed = false;
  for (std::size_t j = 0; j < ny; ++j) {
    const double wy = band_width(y, j, nb);
    for (std::size_t i = 0; i < nx; ++i) {
      const std::size_t k = grid.node(i, j);
      if (d[k] <= std::min(wx[i], wy)) {
        fixed[k] = 1;
        any_fixed = true;
      }
    }
  }
  if (!any_fixed)
    throw std::invalid_argument("levelset_from_polyline: the polyline passes no grid node "
                                "within band cells");
  fast_sweep(grid, d, fixed, 8);

  // Scanline crossings per grid row, stored CSR. Half-open rule: an edge crosses
  // y_j if min(y) <= y_j < max(y), so a vertex on a scanline is counted once
  // and a horizontal edge never.
  std::vector<std::size_t> offsets(ny + 1, 0);
  auto row_range = [&](double ylo, double yhi) -> std::pair<std::size_t, std::size_t> {
    return {std::size_t(std::lower_bound(y.begin(), y.end(), ylo) - y.begin()),
            std::size_t(std::lower_bound(y.begin(), y.end(), yhi) - y.begin())};
  };
  for (std::size_t k = 0; k < m; ++k) {
    const auto s = segment(k);
    const auto [r0, r1] = row_range(s[1], s[3]);
    for (std::size_t j = r0; j < r1; ++j)
      ++offsets[j + 1];
  }
  for (std::size_t j = 0; j < ny; ++j)
    offsets[j + 1] += offsets[j];
  std::vector<double> xc(offsets.back());
  {
    std::vector<std::size_t> pos(offsets.begin(), offsets.end() - 1);
    for (std::size_t k = 0; k < m; ++k) {
      const auto [ax, ay, bx, by] = segment(k); // ay <= by
      const auto [r0, r1] = row_range(ay, by);
      for (std::size_t j = r0; j < r1; ++j)
        xc[pos[j]++] = ax + (y[j] - ay) * (bx - ax) / (by - ay);
    }
  }
  for (std::size_t j = 0; j < ny; ++j) {
    const auto first = xc.begin() + std::ptrdiff_t(offsets[j]);
    const auto last = xc.begin() + std::ptrdiff_t(offsets[j + 1]);
    std::sort(first, last);
    // Parity of the crossings strictly left of the node: odd means inside
    auto c = first;
    for (std::size_t i = 0; i < nx; ++i) {
      while (c != last and *c < x[i])
        ++c;
      double& dk = d[grid.node(i, j)];
      if ((c - first) % 2 == 1 and dk > 0) // a node on the curve stays +0
        dk = -dk;
    }
  }
  return LevelSet(grid, std::move(d));
}
