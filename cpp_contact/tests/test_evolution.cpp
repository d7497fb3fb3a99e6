// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Tests of the level-set evolution (eqs 19-20): WENO5 order, normal extension, advection,
// gradient drift and the cut-polygon area. Set CONTACT_TEST_VERBOSE=1 to print the numbers.
#include <contact/cut_cell.h>
#include <contact/evolution.h>
#include <contact/reinit.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <stdexcept>
#include <vector>

using namespace contact;

namespace {
constexpr double pi = std::numbers::pi;

bool verbose() {
  return std::getenv("CONTACT_TEST_VERBOSE") != nullptr;
}

double order(double coarse, double fine) {
  return std::log2(coarse / fine);
}

std::vector<double> disc(const StructuredGrid& g, double cx, double cy, double r) {
  return sample_on_grid(
      g, [&](std::array<double, 2> x) { return std::hypot(x[0] - cx, x[1] - cy) - r; });
}

/// Max |q - cos(3 theta)| over unknown nodes with phi < width after extending cos(3 theta)
/// from the disc of radius 0.5 (grid [-1, 1]^2 with n cells per axis, or graded if asked).
double extension_error(const StructuredGrid& g, double width, ExtensionInfo* info = nullptr) {
  const std::vector<double> phi = disc(g, 0, 0, 0.5);
  const std::size_t n = g.num_nodes();
  std::vector<std::int8_t> known(n);
  std::vector<double> q(2 * n, std::nan(""));
  std::vector<double> f(n);
  for (std::size_t j = 0; j < g.num_nodes(1); ++j)
    for (std::size_t i = 0; i < g.num_nodes(0); ++i) {
      const std::size_t k = g.node(i, j);
      f[k] = std::cos(3 * std::atan2(g.axis(1)[j], g.axis(0)[i]));
      if ((known[k] = phi[k] <= 0))
        q[2 * k] = f[k], q[2 * k + 1] = -f[k];
    }
  const ExtensionInfo inf = extend_normal(g, phi, known, q, 2);
  if (info)
    *info = inf;
  double err = 0;
  for (std::size_t k = 0; k < n; ++k) {
    EXPECT_EQ(q[2 * k + 1], -q[2 * k]); // the fields do not mix
    if (!known[k] and phi[k] < width)
      err = std::max(err, std::abs(q[2 * k] - f[k]));
  }
  return err;
}

/// Translate a disc of radius 0.25 by D in steps of `frac` h on an nx x ny grid of
/// [0, 1] x [0, ly]; returns max |phi - d| at nodes within 1.5 h of the exact circle.
double translation_error(std::size_t nx, std::size_t ny, double ly, double frac) {
  const StructuredGrid g = StructuredGrid::uniform({0, 0}, {1, ly}, {nx, ny});
  const double h = g.min_spacing();
  const double c0[2] = {0.35, 0.4}, D[2] = {0.3, 0.2}, R = 0.25;
  std::vector<double> phi = disc(g, c0[0], c0[1], R);
  const int steps = int(std::ceil(std::hypot(D[0], D[1]) / (frac * h)));
  std::vector<double> v(2 * g.num_nodes());
  for (std::size_t k = 0; k < g.num_nodes(); ++k)
    v[2 * k] = D[0] / steps, v[2 * k + 1] = D[1] / steps;
  for (int s = 0; s < steps; ++s)
    phi = advect(g, phi, v).values;
  const std::vector<double> ex = disc(g, c0[0] + D[0], c0[1] + D[1], R);
  double err = 0;
  for (std::size_t k = 0; k < ex.size(); ++k)
    if (std::abs(ex[k]) < 1.5 * h)
      err = std::max(err, std::abs(phi[k] - ex[k]));
  return err;
}
} // namespace

TEST(Evolution, Weno5FifthOrderAndExactOnQuadratics) {
  std::vector<double> errs;
  for (std::size_t n : {20, 40, 80, 160}) {
    const double h = 2 * pi / double(n);
    std::vector<double> f(n + 1), dm(n + 1), dp(n + 1);
    for (std::size_t i = 0; i <= n; ++i)
      f[i] = std::sin(double(i) * h);
    weno5_derivatives(f, h, dm, dp);
    double e = 0;
    for (std::size_t i = 5; i + 5 <= n; ++i) {
      const double c = std::cos(double(i) * h);
      e = std::max({e, std::abs(dm[i] - c), std::abs(dp[i] - c)});
    }
    errs.push_back(e);
  }
  for (std::size_t l = 0; l + 1 < errs.size(); ++l) {
    if (verbose())
      std::printf("WENO5 sin: err %.3e order %.2f\n", errs[l + 1], order(errs[l], errs[l + 1]));
    EXPECT_GE(order(errs[l], errs[l + 1]), 4.5);
  }
  // Every candidate stencil is exact for a quadratic, so the convex combination is too
  // (interior nodes: the linear ghosts are not).
  const double h = 0.1;
  std::vector<double> f(21), dm(21), dp(21);
  for (std::size_t i = 0; i < f.size(); ++i)
    f[i] = std::pow(double(i) * h - 0.7, 2);
  weno5_derivatives(f, h, dm, dp);
  for (std::size_t i = 3; i + 3 < f.size(); ++i) {
    EXPECT_NEAR(dm[i], 2 * (double(i) * h - 0.7), 1e-12);
    EXPECT_NEAR(dp[i], 2 * (double(i) * h - 0.7), 1e-12);
  }
}

TEST(Evolution, ExtensionFirstOrderUniformAndGraded) {
  // Fixed width 0.25 beyond the circle: first order (upwind); 3h band: O(h) with a shrinking band
  std::vector<double> far, near;
  for (std::size_t n : {40, 80, 160}) {
    const StructuredGrid g = StructuredGrid::uniform({-1, -1}, {1, 1}, {n, n});
    ExtensionInfo info;
    far.push_back(extension_error(g, 0.25, &info));
    near.push_back(extension_error(g, 3 * g.min_spacing()));
    EXPECT_EQ(info.fallback, 0u);
    EXPECT_LE(info.sweeps, 8); // two rounds: radial characteristics need every ordering once
    EXPECT_LT(near.back(), 1.5 * g.min_spacing());
  }
  for (std::size_t l = 0; l + 1 < far.size(); ++l) {
    if (verbose())
      std::printf("extension: far %.3e (order %.2f) near %.3e (order %.2f)\n", far[l + 1],
                  order(far[l], far[l + 1]), near[l + 1], order(near[l], near[l + 1]));
    EXPECT_GE(order(far[l], far[l + 1]), 0.8);
    EXPECT_GE(order(near[l], near[l + 1]), 0.9);
  }
  // Graded, anisotropic grid (spacing ratio ~3 along x): still first order
  std::vector<double> graded;
  for (std::size_t n : {40, 80, 160}) {
    std::vector<double> x(n + 1), y(n + 1);
    for (std::size_t i = 0; i <= n; ++i) {
      const double s = -1.0 + 2.0 * double(i) / double(n);
      x[i] = std::atanh(s * std::tanh(1.2)) / 1.2;
      y[i] = s;
    }
    x.front() = -1, x.back() = 1;
    graded.push_back(extension_error(StructuredGrid(x, y), 0.25));
  }
  EXPECT_GE(order(graded[1], graded[2]), 0.8);
  EXPECT_LT(graded[2], 0.05);
}

TEST(Evolution, ExtensionCapAndFallback) {
  const StructuredGrid g = StructuredGrid::uniform({-1, -1}, {1, 1}, {30, 30});
  const std::vector<double> phi = disc(g, 0, 0, 0.5);
  const std::size_t n = g.num_nodes();
  std::vector<std::int8_t> known(n);
  std::vector<double> q(n, 0.0);
  std::size_t inner = 0;
  for (std::size_t k = 0; k < n; ++k) {
    known[k] = phi[k] <= 0 and phi[k] > -0.3;
    q[k] = known[k] ? 1.0 : 0.0;
    inner += phi[k] <= -0.3;
  }
  // The disc r < 0.2 has no deeper known node: averaged from the ring, counted
  std::vector<double> q1 = q;
  const ExtensionInfo info = extend_normal(g, phi, known, q1, 1);
  EXPECT_EQ(info.fallback, inner);
  for (double v : q1)
    EXPECT_DOUBLE_EQ(v, 1.0);
  // Radial characteristics of cos(3 theta) need a second round of orderings: a cap of one
  // round is reported, not silently returned
  std::vector<double> q2(n);
  for (std::size_t j = 0; j < g.num_nodes(1); ++j)
    for (std::size_t i = 0; i < g.num_nodes(0); ++i) {
      const std::size_t k = g.node(i, j);
      known[k] = phi[k] <= 0;
      q2[k] = known[k] ? std::cos(3 * std::atan2(g.axis(1)[j], g.axis(0)[i])) : 0.0;
    }
  std::vector<double> q3 = q2;
  EXPECT_THROW(extend_normal(g, phi, known, q2, 1, 1), std::runtime_error);
  EXPECT_NO_THROW(extend_normal(g, phi, known, q3, 1, 2));
  std::vector<std::int8_t> none(n, 0);
  EXPECT_THROW(extend_normal(g, phi, none, q2, 1), std::invalid_argument);
  EXPECT_THROW(extend_normal(g, phi, known, q2, 2), std::invalid_argument);
}

TEST(Evolution, TranslationFifthOrderOnRectangularGrid) {
  // nx != ny and hx != hy: exercises the line layout of both axes
  const double e1 = translation_error(32, 48, 1.2, 0.4);
  const double e2 = translation_error(64, 96, 1.2, 0.4);
  if (verbose())
    std::printf("translation: %.3e %.3e order %.2f\n", e1, e2, order(e1, e2));
  EXPECT_LT(e1, 1e-4);
  EXPECT_GE(order(e1, e2), 4.0);
}

TEST(Evolution, AdvectSubstepsSpeedAndErrors) {
  const std::size_t n = 250;
  const StructuredGrid g = StructuredGrid::uniform({0, 0}, {1, 1}, {n, n});
  const std::vector<double> phi = disc(g, 0.4, 0.5, 0.25);
  std::vector<double> v(2 * g.num_nodes());
  for (std::size_t k = 0; k < g.num_nodes(); ++k)
    v[2 * k] = 0.1 / n, v[2 * k + 1] = 0.05 / n;
  const auto t0 = std::chrono::steady_clock::now();
  const AdvectResult r = advect(g, phi, v);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (verbose())
    std::printf("advect 250^2, 0.1 h: %d substep(s), %.2f ms\n", r.substeps, ms);
  EXPECT_EQ(r.substeps, 1);
  EXPECT_LT(ms, 500.0);
  // cfl: |vx| + |vy| = 3 h at cfl 0.5 -> 6 substeps; at cfl 1 -> 3
  for (std::size_t k = 0; k < g.num_nodes(); ++k)
    v[2 * k] = 2.0 / n, v[2 * k + 1] = -1.0 / n;
  EXPECT_EQ(advect(g, phi, v).substeps, 6);
  EXPECT_EQ(advect(g, phi, v, 1.0, 1.0).substeps, 3);
  // A linear phi is translated exactly (up to round-off), boundary ghosts included
  const StructuredGrid s = StructuredGrid::uniform({0, 0}, {1, 1}, {10, 10});
  const std::vector<double> lin =
      sample_on_grid(s, [](std::array<double, 2> x) { return x[0] - 2 * x[1]; });
  std::vector<double> w(2 * s.num_nodes());
  for (std::size_t k = 0; k < s.num_nodes(); ++k)
    w[2 * k] = 0.03, w[2 * k + 1] = 0.01;
  const AdvectResult rl = advect(s, lin, w);
  for (std::size_t k = 0; k < lin.size(); ++k)
    EXPECT_NEAR(rl.values[k], lin[k] - 0.03 + 2 * 0.01, 1e-14);

  std::vector<double> x = {0, 0.1, 0.3, 0.6, 1.0};
  const StructuredGrid gr(x, x);
  EXPECT_THROW(advect(gr, std::vector<double>(25), std::vector<double>(50)), std::invalid_argument);
  EXPECT_THROW(advect(s, lin, std::vector<double>(3)), std::invalid_argument);
  EXPECT_THROW(advect(s, lin, w, 1.0, 1.5), std::invalid_argument);
  EXPECT_THROW(advect(s, lin, w, -1.0), std::invalid_argument);
}

TEST(Evolution, AreaIsTheCutPolygonAndDriftOfLinearPhi) {
  // Exact for a half plane, graded grid included
  std::vector<double> t(31);
  for (std::size_t i = 0; i < t.size(); ++i)
    t[i] = std::pow(double(i) / 30.0, 1.5);
  const StructuredGrid g(t, t);
  const std::vector<double> lin =
      sample_on_grid(g, [](std::array<double, 2> x) { return 2 * (x[0] - 0.3 - 0.2 * x[1]); });
  EXPECT_NEAR(inside_area(g, lin), 0.4, 1e-14);
  EXPECT_NEAR(gradient_drift(g, lin, 0.1), 2 * std::hypot(1.0, 0.2) - 1, 1e-12);
  // Equals the sum of the cut-cell fractions (same polygon as the cut integration)
  const StructuredGrid u = StructuredGrid::uniform({0, 0}, {1, 1}, {16, 16});
  const std::vector<double> d = disc(u, 0.5, 0.5, 0.3);
  double s = 0;
  for (std::size_t j = 0; j < 16; ++j)
    for (std::size_t i = 0; i < 16; ++i) {
      const std::array<double, 4> v = {d[u.node(i, j)], d[u.node(i + 1, j)], d[u.node(i, j + 1)],
                                       d[u.node(i + 1, j + 1)]};
      s += cut::inside_fraction(v) / 256.0;
    }
  EXPECT_NEAR(inside_area(u, d), s, 1e-15);
  // Second order in h for a disc
  std::vector<double> errs;
  for (std::size_t n : {32, 64, 128}) {
    const StructuredGrid gn = StructuredGrid::uniform({0, 0}, {1, 1}, {n, n});
    errs.push_back(std::abs(inside_area(gn, disc(gn, 0.5, 0.5, 0.3)) - pi * 0.09));
  }
  EXPECT_GT(order(errs[1], errs[2]), 1.8);
  // Drift of an exact distance is the O(h^2) central-difference error; 0 with no node in band
  std::vector<double> drift;
  for (std::size_t n : {16, 32, 64}) {
    const StructuredGrid gn = StructuredGrid::uniform({0, 0}, {1, 1}, {n, n});
    drift.push_back(gradient_drift(gn, disc(gn, 0.5, 0.5, 0.3), 3 * gn.min_spacing()));
  }
  if (verbose())
    std::printf("drift of a distance: %.3e %.3e %.3e\n", drift[0], drift[1], drift[2]);
  EXPECT_LT(drift[0], 0.05);
  EXPECT_GT(order(drift[1], drift[2]), 1.8);
  EXPECT_EQ(gradient_drift(u, std::vector<double>(u.num_nodes(), 5.0), 0.1), 0.0);
  EXPECT_THROW(gradient_drift(u, d, -1), std::invalid_argument);
  EXPECT_THROW(inside_area(u, std::vector<double>(3)), std::invalid_argument);
}
