// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Tests of reinitialisation, fast sweeping and polyline level sets against exact
// distances. Set CONTACT_TEST_VERBOSE=1 to print the measured errors and orders.
#include <contact/projection.h>
#include <contact/reinit.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

using namespace contact;

namespace {
constexpr double pi = std::numbers::pi;

bool verbose() {
  return std::getenv("CONTACT_TEST_VERBOSE") != nullptr;
}

StructuredGrid square_grid(std::size_t n) {
  return StructuredGrid::uniform({-1, -1}, {1, 1}, {n, n});
}

/// [-1, 1]^2 with x nodes clustered at 0 by x = atanh(s tanh b)/b (spacing ratio
/// ~3.3 between the ends and the middle) and y uniform: graded and anisotropic.
StructuredGrid tanh_grid(std::size_t n) {
  const double b = 1.2;
  std::vector<double> x(n + 1), y(n + 1);
  for (std::size_t i = 0; i <= n; ++i) {
    const double s = -1.0 + 2.0 * double(i) / double(n);
    x[i] = std::atanh(s * std::tanh(b)) / b;
    y[i] = s;
  }
  x.front() = -1.0, x.back() = 1.0;
  return StructuredGrid(std::move(x), std::move(y));
}

double order(double coarse, double fine) {
  return std::log2(coarse / fine);
}

/// Exact distance from p to segment [a, b] (independent of the library's).
double seg_dist(std::array<double, 2> p, std::array<double, 2> a, std::array<double, 2> b) {
  const double ex = b[0] - a[0], ey = b[1] - a[1];
  const double t =
      std::clamp(((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / (ex * ex + ey * ey), 0.0, 1.0);
  return std::hypot(p[0] - a[0] - t * ex, p[1] - a[1] - t * ey);
}

/// Brute-force signed distance to a closed polygon: min over all edges, sign from
/// the winding number (Sunday's crossing form; inside < 0), O(vertices) per point.
double polygon_sdf(const std::vector<double>& v, std::array<double, 2> p) {
  const std::size_t m = v.size() / 2;
  double d = std::numeric_limits<double>::max();
  int wind = 0;
  for (std::size_t k = 0; k < m; ++k) {
    const std::size_t l = (k + 1) % m;
    const std::array<double, 2> a = {v[2 * k], v[2 * k + 1]}, b = {v[2 * l], v[2 * l + 1]};
    d = std::min(d, seg_dist(p, a, b));
    const double left = (b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1]);
    if (a[1] <= p[1] and b[1] > p[1] and left > 0)
      ++wind;
    else if (a[1] > p[1] and b[1] <= p[1] and left < 0)
      --wind;
  }
  return wind != 0 ? -d : d;
}

/// Errors of reinitialize(x^2 + y^2 - r^2) on one grid (see CircleFigures).
struct CircleErrors {
  double h;        // largest spacing
  double near;     // nodes with |d| <= h_min (crossed cells and neighbours: projected)
  double band;     // nodes with |d| <= 3h (includes swept nodes)
  double drift;    // max distance of the new contour from the old (exact) circle
  double moved;    // max |P_new(x0) - P_old(x0)| over the ring (includes tangential)
  double grad;     // max ||grad psi| - 1| in an annulus away from the centre
  bool signs_kept; // sign of every node value unchanged
  bool converged;  // all ring projections converged
};

CircleErrors circle_errors(const StructuredGrid& grid) {
  const double cx = 0.037, cy = -0.021, r = 0.5; // centre off the grid's symmetry axes
  auto rho = [&](double px, double py) { return std::hypot(px - cx, py - cy); };
  const LevelSet phi(
      grid, sample_on_grid(grid, [&](auto p) { return std::pow(rho(p[0], p[1]), 2) - r * r; }));
  const LevelSet psi = reinitialize(phi);

  CircleErrors e{grid.max_spacing(), 0, 0, 0, 0, 0, true, true};
  const auto& x = grid.axis(0);
  const auto& y = grid.axis(1);
  for (std::size_t j = 0; j < y.size(); ++j)
    for (std::size_t i = 0; i < x.size(); ++i) {
      const std::size_t k = grid.node(i, j);
      const double exact = rho(x[i], y[j]) - r, err = std::abs(psi.values()[k] - exact);
      if (std::abs(exact) <= grid.min_spacing())
        e.near = std::max(e.near, err);
      if (std::abs(exact) <= 3 * e.h)
        e.band = std::max(e.band, err);
      e.signs_kept &= std::signbit(psi.values()[k]) == std::signbit(phi.values()[k]);
    }

  // The bicubic Hermite interpolant reproduces x^2 + y^2 (FD slopes are exact for
  // quadratics), so the old contour is the exact circle and P_old lies on it.
  std::vector<double> ring;
  for (int k = 0; k < 200; ++k) {
    const double t = 2 * pi * (k + 0.3) / 200;
    ring.insert(ring.end(), {cx + (r + 0.1) * std::cos(t), cy + (r + 0.1) * std::sin(t)});
  }
  const ProjectionResult p0 = closest_point_projection(phi, ring);
  const ProjectionResult p1 = closest_point_projection(psi, ring);
  for (std::size_t k = 0; k < 200; ++k) {
    e.converged &=
        p0.status[k] == ProjectionStatus::converged and p1.status[k] == ProjectionStatus::converged;
    const double* a = p0.points.data() + 2 * k;
    const double* b = p1.points.data() + 2 * k;
    e.drift = std::max(e.drift, std::abs(rho(b[0], b[1]) - r));
    e.moved = std::max(e.moved, std::hypot(b[0] - a[0], b[1] - a[1]));
  }

  // |grad psi| on 15 circles 0.15 <= rho <= 0.85: the medial axis is the centre only
  for (int a = 0; a < 100; ++a)
    for (int b = 0; b < 15; ++b) {
      const double t = 2 * pi * (a + 0.1) / 100, s = 0.15 + 0.05 * b;
      const double p[2] = {cx + s * std::cos(t), cy + s * std::sin(t)};
      double g[2];
      psi.eval(std::span<const double, 2>(p, 2), std::span<double, 2>(g, 2));
      e.grad = std::max(e.grad, std::abs(std::hypot(g[0], g[1]) - 1));
    }
  if (verbose())
    std::printf("  h=%.4f near %.2e band(3h) %.2e drift %.2e moved %.2e |grad|-1 %.2e\n", e.h,
                e.near, e.band, e.drift, e.moved, e.grad);
  return e;
}

/// Checks shared by the uniform and graded circle tests, over 3 refinements.
void check_circle(StructuredGrid (*make)(std::size_t)) {
  std::vector<CircleErrors> e;
  for (std::size_t n : {50, 100, 200})
    e.push_back(circle_errors(make(n)));
  for (std::size_t l = 0; l < e.size(); ++l) {
    EXPECT_TRUE(e[l].signs_kept);
    EXPECT_TRUE(e[l].converged);
    // Projected nodes are exact up to the projection tolerance (1e-10 h)
    EXPECT_LT(e[l].near, 1e-8 * e[l].h);
    // Old and new contours agree to third order: measured 0.13 h^3 (uniform),
    // 0.01 h_max^3 (graded)
    EXPECT_LT(e[l].drift, 0.5 * std::pow(e[l].h, 3));
    // First-order sweep: |grad| error measured 0.73-2.1 h
    EXPECT_LT(e[l].grad, 3 * e[l].h);
  }
  for (std::size_t l = 0; l + 1 < e.size(); ++l) {
    // 3-cell band: swept nodes next to the projected ones carry the O(h^2)
    // local truncation error of the upwind update (measured orders 2.05-2.16)
    EXPECT_GE(order(e[l].band, e[l + 1].band), 1.9);
    // Interface drift is O(h^3) (measured orders 2.89-3.16): the Hermite data of
    // crossed cells come from exact distances only
    EXPECT_GE(order(e[l].drift, e[l + 1].drift), 2.7);
    // The projection of a ring point also moves tangentially with the contour's
    // normal, one order less (measured orders 1.86-2.28)
    EXPECT_GE(order(e[l].moved, e[l + 1].moved), 1.7);
    // First-order sweep (measured orders 0.84-0.90)
    EXPECT_GE(order(e[l].grad, e[l + 1].grad), 0.75);
  }
}
} // namespace

//-----------------------------------------------------------------------------
TEST(FastSweep, PointSourceUniform) {
  // Distance from the centre node of [-1, 1]^2
  for (std::size_t n : {40, 80}) {
    const StructuredGrid grid = square_grid(n);
    const double h = 2.0 / double(n);
    std::vector<double> d(grid.num_nodes(), 0.0);
    std::vector<std::int8_t> fixed(grid.num_nodes(), 0);
    fixed[grid.node(n / 2, n / 2)] = 1;
    fast_sweep(grid, d, fixed, 8);

    const auto& x = grid.axis(0);
    const auto& y = grid.axis(1);
    double err_axes = 0, err_max = 0, err_min = 0;
    for (std::size_t j = 0; j <= n; ++j)
      for (std::size_t i = 0; i <= n; ++i) {
        const double err = d[grid.node(i, j)] - std::hypot(x[i], y[j]);
        if (i == n / 2 or j == n / 2)
          err_axes = std::max(err_axes, std::abs(err));
        err_max = std::max(err_max, err);
        err_min = std::min(err_min, err);
      }
    if (verbose())
      std::printf("  n=%zu axes %.2e max over %.3f h under %.2e\n", n, err_axes, err_max / h,
                  err_min);
    // Along the axes the update is 1D, u = a + h: exact up to round-off of the coordinates
    EXPECT_LT(err_axes, 1e-13);
    // Elsewhere the upwind scheme overestimates (monotone, exact at the source) by
    // O(h log(1/h)) at a point source: measured 1.03 h (n = 40), 1.24 h (n = 80)
    EXPECT_GE(err_min, -1e-13);
    EXPECT_LT(err_max, 0.25 * h * std::log2(double(n)));
  }
}

TEST(FastSweep, PlaneWaveExactOnGradedGrid) {
  // d = c x + s y + const is reproduced exactly by the upwind update iff each
  // side uses its own spacing, so this checks the graded-grid update.
  const std::vector<double> ax = tanh_grid(60).axis(0);
  const StructuredGrid grid(ax, ax);
  const double c = std::cos(0.3), s = std::sin(0.3);
  auto exact = [&](double px, double py) { return c * (px + 1) + s * (py + 1) + 0.1; };
  const auto& x = grid.axis(0);
  const auto& y = grid.axis(1);
  std::vector<double> d(grid.num_nodes(), 0.0);
  std::vector<std::int8_t> fixed(grid.num_nodes(), 0);
  for (std::size_t j = 0; j < y.size(); ++j)
    for (std::size_t i = 0; i < x.size(); ++i)
      if (i == 0 or j == 0) {
        fixed[grid.node(i, j)] = 1;
        d[grid.node(i, j)] = exact(x[i], y[j]);
      }
  fast_sweep(grid, d, fixed, 8);
  double err = 0;
  for (std::size_t j = 0; j < y.size(); ++j)
    for (std::size_t i = 0; i < x.size(); ++i)
      err = std::max(err, std::abs(d[grid.node(i, j)] - exact(x[i], y[j])));
  // Exact scheme: only round-off, accumulated over ~120 updates of O(1) values
  EXPECT_LT(err, 1e-12);
}

TEST(FastSweep, BadInput) {
  const StructuredGrid grid = square_grid(4);
  std::vector<double> d(grid.num_nodes(), 0.0);
  std::vector<std::int8_t> none(grid.num_nodes(), 0), short_flags(3, 1);
  EXPECT_THROW(fast_sweep(grid, d, none, 8), std::invalid_argument);
  EXPECT_THROW(fast_sweep(grid, d, short_flags, 8), std::invalid_argument);
}

//-----------------------------------------------------------------------------
TEST(Reinit, CircleUniform) {
  if (verbose())
    std::printf("Reinit circle, uniform grid\n");
  check_circle(square_grid);
}

TEST(Reinit, CircleGraded) {
  if (verbose())
    std::printf("Reinit circle, tanh-graded x axis\n");
  check_circle(tanh_grid);
}

TEST(Reinit, RectangleWithNonConstantFactor) {
  // phi = box SDF-like max(|x| - a, |y| - b) times a factor in [1, 2]: the zero
  // contour is the rectangle, the values are not distances.
  const double a = 0.513, b = 0.347;
  auto box = [&](double px, double py) {
    const double qx = std::abs(px) - a, qy = std::abs(py) - b;
    return std::hypot(std::max(qx, 0.0), std::max(qy, 0.0)) + std::min(std::max(qx, qy), 0.0);
  };
  for (std::size_t n : {100, 200}) {
    const StructuredGrid grid = square_grid(n);
    const double h = 2.0 / double(n);
    const LevelSet phi(grid, sample_on_grid(grid, [&](auto p) {
                         return std::max(std::abs(p[0]) - a, std::abs(p[1]) - b) *
                                (1.5 + 0.5 * std::sin(3 * p[0] + 2 * p[1]));
                       }));
    const LevelSet psi = reinitialize(phi);
    const auto& x = grid.axis(0);
    const auto& y = grid.axis(1);
    double err_edges = 0, err_corners = 0;
    for (std::size_t j = 0; j <= n; ++j)
      for (std::size_t i = 0; i <= n; ++i) {
        const double exact = box(x[i], y[j]);
        if (std::abs(exact) > 2 * h)
          continue;
        const double err = std::abs(psi.values()[grid.node(i, j)] - exact);
        const double to_corner = std::hypot(std::abs(x[i]) - a, std::abs(y[j]) - b);
        double& e = to_corner > 4 * h ? err_edges : err_corners;
        e = std::max(e, err);
        EXPECT_EQ(std::signbit(psi.values()[grid.node(i, j)]),
                  std::signbit(phi.values()[grid.node(i, j)]));
      }
    if (verbose())
      std::printf("  rectangle n=%zu: 2h band, edges %.2e (%.2f h^3), corners %.2e (%.2f h)\n", n,
                  err_edges, err_edges / (h * h * h), err_corners, err_corners / h);
    // Along the edges phi is smooth near the contour and the 2h band is projected
    // nodes: O(h^3) from the interpolated contour, measured 0.16-0.19 h^3
    EXPECT_LT(err_edges, 0.5 * h * h * h);
    // The interpolant rounds the corners (phi has a kink there): O(h), measured 0.24 h
    EXPECT_LT(err_corners, 0.5 * h);
  }
}

TEST(Reinit, CapKeepsTheBandAndTheSign) {
  // Two discs' union: below the cap the capped sweep is the whole sweep (a node's distance
  // depends on nearer nodes only), node for node; beyond it +-cap with phi's sign
  const StructuredGrid grid = StructuredGrid::uniform({-3, -2}, {3, 2}, {96, 64});
  const LevelSet phi(grid, sample_on_grid(grid, [](auto p) {
                       return std::min(std::hypot(p[0] + 1.2, p[1]) - 1.0,
                                       std::hypot(p[0] - 1.3, p[1] - 0.2) - 1.1);
                     }));
  const LevelSet full = reinitialize(phi);
  const double h = grid.max_spacing();
  for (double cap : {3 * h, 0.5, 1.0}) {
    const LevelSet psi = reinitialize(phi, 8, cap);
    std::size_t inside = 0, beyond = 0;
    for (std::size_t k = 0; k < grid.num_nodes(); ++k) {
      const double f = full.values()[k], c = psi.values()[k];
      EXPECT_EQ(std::signbit(c), std::signbit(phi.values()[k]));
      if (std::abs(f) < cap) {
        ASSERT_EQ(c, f) << "node " << k << ", cap " << cap;
        ++inside;
      } else {
        ASSERT_EQ(std::abs(c), cap) << "node " << k << ", cap " << cap;
        ++beyond;
      }
    }
    EXPECT_GT(inside, 100u);
    EXPECT_GT(beyond, 100u);
  }
}

TEST(Reinit, NoZeroContourThrows) {
  const StructuredGrid grid = square_grid(8);
  const LevelSet pos(grid, std::vector<double>(grid.num_nodes(), 1.0));
  const LevelSet neg(grid, std::vector<double>(grid.num_nodes(), -0.5));
  EXPECT_THROW(reinitialize(pos), std::invalid_argument);
  EXPECT_THROW(reinitialize(neg), std::invalid_argument);
}

//-----------------------------------------------------------------------------
namespace {
/// Compare levelset_from_polyline with the brute-force signed distance.
struct PolylineErrors {
  double band = 0;   // max error at nodes within band * h of the curve
  double beyond = 0; // max error elsewhere
  int wrong_sign = 0;
};

PolylineErrors polyline_errors(const StructuredGrid& grid, const std::vector<double>& v, int band) {
  const LevelSet ls = levelset_from_polyline(grid, v, band);
  const auto& x = grid.axis(0);
  const auto& y = grid.axis(1);
  const double w = band * grid.min_spacing();
  PolylineErrors e;
  for (std::size_t j = 0; j < y.size(); ++j)
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double exact = polygon_sdf(v, {x[i], y[j]});
      const double got = ls.values()[grid.node(i, j)];
      const double err = std::abs(got - exact);
      double& ek = std::abs(exact) <= w ? e.band : e.beyond;
      ek = std::max(ek, err);
      // The reference is not exactly 0 on the curve (round-off): no sign there
      if (std::abs(exact) > 1e-14 and std::signbit(got) != std::signbit(exact))
        ++e.wrong_sign;
    }
  return e;
}

std::vector<double> regular_polygon(std::size_t m, double r, double cx, double cy) {
  std::vector<double> v;
  for (std::size_t k = 0; k < m; ++k) {
    const double t = 2 * pi * double(k) / double(m);
    v.insert(v.end(), {cx + r * std::cos(t), cy + r * std::sin(t)});
  }
  return v;
}
} // namespace

TEST(Polyline, RegularPolygon) {
  const std::vector<double> v = regular_polygon(400, 0.6, 0.013, -0.007);
  std::vector<PolylineErrors> e;
  for (std::size_t n : {80, 160}) {
    e.push_back(polyline_errors(square_grid(n), v, 3));
    const double h = 2.0 / double(n);
    if (verbose())
      std::printf("  400-gon n=%zu: band %.2e, beyond %.2e (%.2f h), wrong signs %d\n", n,
                  e.back().band, e.back().beyond, e.back().beyond / h, e.back().wrong_sign);
    // In the band the values are the exact segment distances: round-off only
    EXPECT_LT(e.back().band, 1e-12);
    // Beyond, first-order sweeping from the band: measured 0.72 h (n = 80), 0.85 h (160)
    EXPECT_LT(e.back().beyond, 1.2 * h);
    EXPECT_EQ(e.back().wrong_sign, 0);
  }
  // First order beyond the band, up to the log(1/h) of diverging characteristics
  // outside a convex curve (measured 0.77)
  EXPECT_GE(order(e[0].beyond, e[1].beyond), 0.7);
}

TEST(Polyline, LShapeOnGridNodes) {
  // Non-convex L with every vertex on a grid node, so grid nodes lie exactly on
  // the edges and scanlines pass through vertices (half-open rule).
  const std::size_t n = 100;
  const StructuredGrid grid = square_grid(n);
  const auto& x = grid.axis(0);
  const auto& y = grid.axis(1);
  const std::vector<std::size_t> iv = {20, 80, 80, 50, 50, 20}, jv = {20, 20, 50, 50, 80, 80};
  std::vector<double> v;
  for (std::size_t k = 0; k < iv.size(); ++k)
    v.insert(v.end(), {x[iv[k]], y[jv[k]]});

  const PolylineErrors e = polyline_errors(grid, v, 3);
  const double h = 2.0 / double(n);
  if (verbose())
    std::printf("  L-shape n=%zu: band %.2e, beyond %.2e (%.2f h), wrong signs %d\n", n, e.band,
                e.beyond, e.beyond / h, e.wrong_sign);
  EXPECT_LT(e.band, 1e-12);     // exact segment distances
  EXPECT_LT(e.beyond, 1.2 * h); // first-order sweep, measured 0.78 h
  EXPECT_EQ(e.wrong_sign, 0);

  // Nodes on the curve are exactly 0
  const LevelSet ls = levelset_from_polyline(grid, v, 3);
  for (std::size_t i = 20; i <= 80; ++i)
    EXPECT_EQ(ls.values()[grid.node(i, 20)], 0.0);
  for (std::size_t j = 20; j <= 50; ++j)
    EXPECT_EQ(ls.values()[grid.node(80, j)], 0.0);
  for (std::size_t j = 50; j <= 80; ++j)
    EXPECT_EQ(ls.values()[grid.node(50, j)], 0.0);
}

TEST(Polyline, LShapeGradedOrientationInvariant) {
  // Off-node vertices on a graded grid; cw, ccw and any start vertex give
  // bit-identical level sets.
  const StructuredGrid grid = tanh_grid(120);
  const std::vector<double> ccw = {-0.61, -0.53, 0.57,  -0.53, 0.57,  0.043,
                                   0.021, 0.043, 0.021, 0.66,  -0.61, 0.66};
  const PolylineErrors e = polyline_errors(grid, ccw, 3);
  const double h = grid.max_spacing();
  if (verbose())
    std::printf("  graded L-shape: band %.2e, beyond %.2e (%.2f h_max), wrong signs %d\n", e.band,
                e.beyond, e.beyond / h, e.wrong_sign);
  EXPECT_LT(e.band, 1e-12);     // exact segment distances
  EXPECT_LT(e.beyond, 1.2 * h); // first-order sweep, measured 0.46 h_max
  EXPECT_EQ(e.wrong_sign, 0);

  std::vector<double> cw, shifted;
  for (std::size_t k = ccw.size() / 2; k-- > 0;)
    cw.insert(cw.end(), {ccw[2 * k], ccw[2 * k + 1]});
  shifted.assign(ccw.begin() + 4, ccw.end());
  shifted.insert(shifted.end(), ccw.begin(), ccw.begin() + 4);
  const LevelSet a = levelset_from_polyline(grid, ccw, 3);
  const LevelSet b = levelset_from_polyline(grid, cw, 3);
  const LevelSet c = levelset_from_polyline(grid, shifted, 3);
  for (std::size_t k = 0; k < grid.num_nodes(); ++k) {
    ASSERT_EQ(a.values()[k], b.values()[k]) << "node " << k;
    ASSERT_EQ(a.values()[k], c.values()[k]) << "node " << k;
  }
}

TEST(Polyline, BadInput) {
  const StructuredGrid grid = square_grid(10);
  const std::vector<double> tri = {-0.5, -0.5, 0.5, -0.5, 0.0, 0.5};
  const std::vector<double> two = {-0.5, -0.5, 0.5, -0.5};
  const std::vector<double> nan = {-0.5, -0.5, std::nan(""), -0.5, 0.0, 0.5};
  const std::vector<double> odd = {-0.5, -0.5, 0.5, -0.5, 0.0};
  EXPECT_NO_THROW(levelset_from_polyline(grid, tri, 1));
  EXPECT_THROW(levelset_from_polyline(grid, two, 3), std::invalid_argument);
  EXPECT_THROW(levelset_from_polyline(grid, nan, 3), std::invalid_argument);
  EXPECT_THROW(levelset_from_polyline(grid, odd, 3), std::invalid_argument);
  EXPECT_THROW(levelset_from_polyline(grid, tri, 0), std::invalid_argument);
}
