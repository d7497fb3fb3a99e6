// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Grid, level-set interpolation, analytic shapes and closest-point projection (eq 25)
// against exact solutions, with observed convergence orders asserted.
#include <cmath>
#include <contact/grid.h>
#include <contact/levelset.h>
#include <contact/projection.h>
#include <contact/shapes.h>
#include <gtest/gtest.h>
#include <limits>
#include <numbers>
#include <random>

using namespace contact;

namespace {
std::vector<double> graded_axis(double lo, double hi, std::size_t n, double beta) {
  // tanh clustering towards the middle of [lo, hi]
  std::vector<double> a(n + 1);
  for (std::size_t i = 0; i <= n; ++i) {
    const double s = -1.0 + 2.0 * double(i) / double(n);
    a[i] = 0.5 * (lo + hi) + 0.5 * (hi - lo) * std::tanh(beta * s) / std::tanh(beta);
  }
  return a;
}

double order(double e_coarse, double e_fine) {
  return std::log2(e_coarse / e_fine);
}

// Max error of projecting `pts` onto the level set of `shape` vs `exact`, grid n x n on [-2, 2]^2
double projection_error(const Shape& shape, std::size_t n, const std::vector<double>& pts,
                        const std::vector<double>& exact) {
  const StructuredGrid g = StructuredGrid::uniform({-2, -2}, {2, 2}, {n, n});
  const LevelSet phi = levelset_from_shape(g, shape);
  const ProjectionResult r = closest_point_projection(phi, pts);
  double e = 0;
  for (std::size_t p = 0; p < pts.size() / 2; ++p) {
    EXPECT_EQ(r.status[p], ProjectionStatus::converged) << "point " << p << " n " << n;
    EXPECT_LE(r.iterations[p], 10) << "Newton-polished projection should need few iterations";
    e = std::max(
        e, std::hypot(r.points[2 * p] - exact[2 * p], r.points[2 * p + 1] - exact[2 * p + 1]));
  }
  return e;
}
} // namespace

TEST(Grid, BadInputThrows) {
  EXPECT_THROW(StructuredGrid({}, {0, 1, 2}), std::invalid_argument);          // empty axis
  EXPECT_THROW(StructuredGrid({0, 1}, {0, 1, 2}), std::invalid_argument);      // too few nodes
  EXPECT_THROW(StructuredGrid({0, 2, 1}, {0, 1, 2}), std::invalid_argument);   // not increasing
  EXPECT_THROW(StructuredGrid({0, NAN, 1}, {0, 1, 2}), std::invalid_argument); // NaN
  EXPECT_THROW(StructuredGrid::uniform({0, 0}, {0, 1}, {4, 4}), std::invalid_argument);
}

TEST(Grid, LocateUniformAndGraded) {
  for (bool graded : {false, true}) {
    const auto x = graded ? graded_axis(0, 1, 37, 2.0) : graded_axis(0, 1, 37, 1e-9);
    const StructuredGrid g(x, x);
    std::mt19937 gen(1);
    std::uniform_real_distribution<double> U(0, 1);
    for (int k = 0; k < 2000; ++k) {
      const double p[2] = {U(gen), U(gen)};
      const auto c = g.locate(std::span<const double, 2>(p, 2));
      ASSERT_TRUE(c.has_value());
      for (int d = 0; d < 2; ++d) {
        EXPECT_LE(x[(*c)[d]], p[d]);
        EXPECT_LE(p[d], x[(*c)[d] + 1]);
      }
    }
    // Nodes, including the upper boundary, belong to a valid cell
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double p[2] = {x[i], x.back()};
      const auto c = g.locate(std::span<const double, 2>(p, 2));
      ASSERT_TRUE(c.has_value());
      EXPECT_LT((*c)[0], x.size() - 1);
    }
    const double out[2] = {1.0 + 1e-12, 0.5};
    EXPECT_FALSE(g.locate(std::span<const double, 2>(out, 2)).has_value());
  }
}

TEST(LevelSet, BadInputThrows) {
  const StructuredGrid g = StructuredGrid::uniform({0, 0}, {1, 1}, {4, 4});
  EXPECT_THROW(LevelSet(g, std::vector<double>(24, 0.0)), std::invalid_argument); // wrong size
  std::vector<double> v(25, 1.0);
  v[7] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(LevelSet(g, v), std::invalid_argument); // NaN value
  const LevelSet phi(g, std::vector<double>(25, 1.0));
  std::vector<double> pts = {0.5, 0.5, 1.5, 0.5}, val(2), grad(4);
  EXPECT_THROW(phi.evaluate(pts, val, grad), std::out_of_range); // point outside the grid
}

// The nodal derivatives are 3-point differences, exact for quadratics, so the
// interpolant reproduces any biquadratic exactly on any graded grid (round-off only).
TEST(LevelSet, ReproducesBiquadraticsOnGradedGrid) {
  const StructuredGrid g(graded_axis(-1, 1, 17, 2.0), graded_axis(-0.5, 1.5, 13, 1.5));
  auto f = [](double x, double y) {
    return 1 + 2 * x - 3 * y + x * x + x * y - 2 * y * y + 0.5 * x * x * y * y - x * y * y;
  };
  auto fx = [](double x, double y) { return 2 + 2 * x + y + x * y * y - y * y; };
  auto fy = [](double x, double y) { return -3 + x - 4 * y + x * x * y - 2 * x * y; };
  const LevelSet phi(g, sample_on_grid(g, [&](std::array<double, 2> p) { return f(p[0], p[1]); }));
  std::mt19937 gen(2);
  std::uniform_real_distribution<double> Ux(-1, 1), Uy(-0.5, 1.5);
  for (int k = 0; k < 500; ++k) {
    const double p[2] = {Ux(gen), Uy(gen)};
    double gr[2], H[3];
    const double v = phi.eval(std::span<const double, 2>(p, 2), std::span<double, 2>(gr, 2),
                              std::span<double, 3>(H, 3));
    EXPECT_NEAR(v, f(p[0], p[1]), 1e-12);
    EXPECT_NEAR(gr[0], fx(p[0], p[1]), 1e-11);
    EXPECT_NEAR(gr[1], fy(p[0], p[1]), 1e-11);
    EXPECT_NEAR(H[1], 1 + 2 * p[0] * p[1] - 2 * p[1], 1e-9); // f_xy
  }
}

// Smooth function: value error O(h^3), gradient O(h^2) (Hermite with 2nd-order slopes).
// Asserted orders leave 0.3 of margin under the theoretical 3 and 2 for pre-asymptotic noise.
TEST(LevelSet, InterpolationOrders) {
  for (bool graded : {false, true}) {
    double ev[3], eg[3];
    std::size_t ns[3] = {20, 40, 80};
    for (int r = 0; r < 3; ++r) {
      const auto a = graded_axis(-1, 1, ns[r], graded ? 1.5 : 1e-9);
      const StructuredGrid g(a, a);
      const LevelSet phi(g, sample_on_grid(g, [](std::array<double, 2> p) {
                           return std::sin(2 * p[0]) * std::cos(3 * p[1]);
                         }));
      ev[r] = eg[r] = 0;
      std::mt19937 gen(3);
      std::uniform_real_distribution<double> U(-0.9, 0.9);
      for (int k = 0; k < 2000; ++k) {
        const double p[2] = {U(gen), U(gen)};
        double gr[2];
        const double v = phi.eval(std::span<const double, 2>(p, 2), std::span<double, 2>(gr, 2));
        ev[r] = std::max(ev[r], std::abs(v - std::sin(2 * p[0]) * std::cos(3 * p[1])));
        eg[r] = std::max(eg[r], std::hypot(gr[0] - 2 * std::cos(2 * p[0]) * std::cos(3 * p[1]),
                                           gr[1] + 3 * std::sin(2 * p[0]) * std::sin(3 * p[1])));
      }
    }
    EXPECT_GT(order(ev[1], ev[2]), 2.7) << "value, graded=" << graded;
    EXPECT_GT(order(eg[1], eg[2]), 1.7) << "gradient, graded=" << graded;
  }
}

TEST(Shapes, ExactSignedDistances) {
  const Circle c({0.5, -0.25}, 0.75);
  EXPECT_NEAR(c({0.5, -0.25}), -0.75, 1e-15);
  EXPECT_NEAR(c({2.5, -0.25}), 1.25, 1e-15);
  const Box b({-1, -0.5}, {1, 0.5});
  EXPECT_NEAR(b({0, 0}), -0.5, 1e-15);
  EXPECT_NEAR(b({0.9, 0.0}), -0.1, 1e-15);
  EXPECT_NEAR(b({1.3, 0.9}), 0.5, 1e-15); // corner region: distance to (1, 0.5)
  EXPECT_NEAR(b({0.2, 0.8}), 0.3, 1e-15);
  // Ellipse: closest point on the curve, residual orthogonal to the tangent, |d| matches
  const Ellipse e({0.1, -0.2}, 1.2, 0.5, 0.4);
  std::mt19937 gen(4);
  std::uniform_real_distribution<double> U(-2, 2);
  for (int k = 0; k < 1000; ++k) {
    const std::array<double, 2> x{U(gen), U(gen)};
    const auto q = e.closest_point(x);
    const double lx = std::cos(0.4) * (q[0] - 0.1) + std::sin(0.4) * (q[1] + 0.2);
    const double ly = -std::sin(0.4) * (q[0] - 0.1) + std::cos(0.4) * (q[1] + 0.2);
    EXPECT_NEAR(lx * lx / 1.44 + ly * ly / 0.25, 1.0, 1e-12); // on the ellipse
    // Tangent in the local frame is (-a sin t, b cos t) ~ (-ly a/b, lx b/a)
    const double tl[2] = {-ly * 1.2 / 0.5, lx * 0.5 / 1.2};
    const double t[2] = {std::cos(0.4) * tl[0] - std::sin(0.4) * tl[1],
                         std::sin(0.4) * tl[0] + std::cos(0.4) * tl[1]};
    const double r[2] = {x[0] - q[0], x[1] - q[1]};
    EXPECT_NEAR((r[0] * t[0] + r[1] * t[1]) / std::hypot(t[0], t[1]), 0.0, 1e-10);
    EXPECT_NEAR(std::abs(e(x)), std::hypot(r[0], r[1]), 1e-14);
  }
  EXPECT_LT(e({0.1, -0.2}), 0.0);
  EXPECT_NEAR(e({0.1, -0.2}), -0.5, 1e-14); // centre: distance to the minor vertex
  // Polygon: unit square both orientations equals Box
  const Polygon ccw({0, 0, 1, 0, 1, 1, 0, 1}), cw({0, 0, 0, 1, 1, 1, 1, 0});
  const Box sq({0, 0}, {1, 1});
  for (int k = 0; k < 500; ++k) {
    const std::array<double, 2> x{U(gen), U(gen)};
    EXPECT_NEAR(ccw(x), sq(x), 1e-14);
    EXPECT_NEAR(cw(x), sq(x), 1e-14);
  }
  // Booleans
  auto c1 = std::make_shared<Circle>(std::array<double, 2>{-0.5, 0}, 0.6);
  auto c2 = std::make_shared<Circle>(std::array<double, 2>{0.5, 0}, 0.6);
  const Union u({c1, c2});
  const Intersection in({c1, c2});
  EXPECT_LT(u({-0.9, 0}), 0);
  EXPECT_GT(in({-0.9, 0}), 0);
  EXPECT_LT(in({0, 0}), 0);
  EXPECT_NEAR(Complement(c1)({-0.5, 0}), 0.6, 1e-15);
  EXPECT_THROW(Circle({0, 0}, -1), std::invalid_argument);
  EXPECT_THROW(Ellipse({0, 0}, 1, 0), std::invalid_argument);
  EXPECT_THROW(Polygon({0, 0, 1, 1}), std::invalid_argument);
}

// Circle and ellipse: the projection error is dominated by the O(h^2) gradient error of
// the interpolant times the distance to the curve, so second order is expected; 1.7 leaves
// margin for the pre-asymptotic range. Start points 0.3 off the curve (inside and outside).
TEST(Projection, CircleAndEllipseSecondOrder) {
  const Circle c({0.05, -0.03}, 1.0);
  const Ellipse el({0.1, 0.0}, 1.2, 0.6, 0.3);
  std::vector<double> pc, ec, pe;
  for (int k = 0; k < 200; ++k) {
    const double t = 2 * std::numbers::pi * k / 200.0;
    const double d = (k % 2 ? 0.3 : -0.3);
    pc.insert(pc.end(), {0.05 + (1 + d) * std::cos(t), -0.03 + (1 + d) * std::sin(t)});
    ec.insert(ec.end(), {0.05 + std::cos(t), -0.03 + std::sin(t)});
    pe.insert(pe.end(), {1.5 * std::cos(t), 0.9 * std::sin(t)});
  }
  std::vector<double> ee(pe.size());
  for (std::size_t p = 0; p < pe.size() / 2; ++p) {
    auto q = el.closest_point({pe[2 * p], pe[2 * p + 1]});
    ee[2 * p] = q[0], ee[2 * p + 1] = q[1];
  }
  double e1[3], e2[3];
  std::size_t ns[3] = {40, 80, 160};
  for (int r = 0; r < 3; ++r) {
    e1[r] = projection_error(c, ns[r], pc, ec);
    e2[r] = projection_error(el, ns[r], pe, ee);
  }
  EXPECT_GT(order(e1[1], e1[2]), 1.7);
  EXPECT_GT(order(e2[1], e2[2]), 1.7);
  EXPECT_LT(e1[2], 1e-4); // h = 0.025: ~0.3 * |grad error| ~ 3e-5 measured
  EXPECT_LT(e2[2], 5e-4);
}

// Box: edge points converge at second order, but the corners of the zero contour are
// rounded by the C1 interpolant over about one cell, so points whose projection is a
// corner converge at first order only (asserted > 0.8, error < h/4).
TEST(Projection, BoxEdgesAndCorners) {
  const Box b({-1, -0.5}, {1, 0.5});
  const std::vector<double> corner_pts = {1.2, 0.7, -1.3, 0.6, 1.1, -0.9, -1.05, -0.52};
  const std::vector<double> corner_ex = {1, 0.5, -1, 0.5, 1, -0.5, -1, -0.5};
  const std::vector<double> edge_pts = {0.3, 0.8, -0.2, -0.3, 1.4, 0.1, -0.7, 0.35};
  const std::vector<double> edge_ex = {0.3, 0.5, -0.2, -0.5, 1.0, 0.1, -0.7, 0.5};
  double ec[3], ee[3];
  std::size_t ns[3] = {40, 80, 160};
  for (int r = 0; r < 3; ++r) {
    ec[r] = projection_error(b, ns[r], corner_pts, corner_ex);
    ee[r] = projection_error(b, ns[r], edge_pts, edge_ex);
  }
  EXPECT_GT(order(ec[0], ec[2]) / 2, 0.8);
  EXPECT_LT(ec[2], 0.25 * 4.0 / 160);
  EXPECT_LT(ee[2], 1e-6); // flat faces away from corners: the SDF is linear there
}

TEST(Projection, FailuresAreReportedNotHidden) {
  const StructuredGrid g = StructuredGrid::uniform({-2, -2}, {2, 2}, {40, 40});
  const LevelSet phi = levelset_from_shape(g, Circle({0, 0}, 1.0));
  // Centre of the disc: grad phi = 0 by symmetry of the interpolant
  auto r = closest_point_projection(phi, std::vector<double>{0.0, 0.0});
  EXPECT_EQ(r.status[0], ProjectionStatus::vanishing_gradient);
  // No zero contour at all: can never converge
  const LevelSet pos(g, sample_on_grid(g, [](auto p) { return 1.0 + p[0] * p[0] + p[1] * p[1]; }));
  r = closest_point_projection(pos, std::vector<double>{0.5, 0.3, -1.0, 1.0});
  for (auto s : r.status)
    EXPECT_NE(s, ProjectionStatus::converged);
  EXPECT_THROW(closest_point_projection(phi, std::vector<double>{2.5, 0.0}), std::out_of_range);
  EXPECT_THROW(closest_point_projection(phi, std::vector<double>{NAN, 0.0}), std::invalid_argument);
  EXPECT_THROW(closest_point_projection(phi, std::vector<double>{0.0}), std::invalid_argument);
}
