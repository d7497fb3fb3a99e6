// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include <cmath>
#include <contact/cut_cell.h>
#include <gtest/gtest.h>
#include <numbers>

using namespace contact::cut;

namespace {
double fraction(std::array<double, 4> phi) { return inside_fraction(phi); }

/// Integral of f over the inside part with the cut rule of `degree`.
template <typename F> double integrate(std::array<double, 4> phi, int degree, F f) {
  std::vector<double> p, w;
  cut_square_rule(phi, degree, p, w);
  double s = 0;
  for (std::size_t q = 0; q < w.size(); ++q)
    s += w[q] * f(p[2 * q], p[2 * q + 1]);
  return s;
}
} // namespace

TEST(CutCell, InsideOutsideAndStraightCuts) {
  EXPECT_DOUBLE_EQ(fraction({-1, -2, -3, -4}), 1.0);
  EXPECT_DOUBLE_EQ(fraction({1, 2, 3, 4}), 0.0);
  EXPECT_DOUBLE_EQ(fraction({0, 0, 0, 0}), 0.0); // phi = 0 is outside (zero measure)
  // phi = X - 0.3: the strip X < 0.3
  EXPECT_NEAR(fraction({-0.3, 0.7, -0.3, 0.7}), 0.3, 1e-15);
  // phi = Y - 0.8 + 0.2 X: a trapezoid of area 0.8 - 0.1
  EXPECT_NEAR(fraction({-0.8, -0.6, 0.2, 0.4}), 0.7, 1e-15);
  // one corner: phi = X + Y - 0.5, triangle of area 1/8
  EXPECT_NEAR(fraction({-0.5, 0.5, 0.5, 1.5}), 0.125, 1e-15);
  // crossing exactly at a vertex: phi = X - 1 is inside everywhere but on X = 1
  EXPECT_NEAR(fraction({-1, 0, -1, 0}), 1.0, 1e-15);
}

TEST(CutCell, SaddleResolvedByTheCentreValue) {
  // phi = (X - 1/2)(Y - 1/2) + c: crossings at the edge midpoints for c = 0
  EXPECT_NEAR(fraction({0.25, -0.25, -0.25, 0.25}), 0.25, 1e-15); // centre 0: separate corners
  // centre value < 0: the inside corners are connected (hexagon = square - 2 corners)
  EXPECT_NEAR(fraction({0.2, -0.3, -0.3, 0.2}), 1.0 - 2 * 0.5 * 0.4 * 0.4, 1e-15);
  // centre value > 0 with v0 outside first in the walk: two corners v1, v2
  EXPECT_NEAR(fraction({0.3, -0.2, -0.2, 0.3}), 2 * 0.5 * 0.4 * 0.4, 1e-15);
  // and the mirrored pattern (v0, v3 inside)
  EXPECT_NEAR(fraction({-0.2, 0.3, 0.3, -0.2}), 2 * 0.5 * 0.4 * 0.4, 1e-15);
}

TEST(CutCell, RulesAreExactForPolynomials) {
  // inside part of phi = X + Y - 1.2: the square minus the corner triangle X + Y > 1.2
  const std::array<double, 4> phi = {-1.2, -0.2, -0.2, 0.8};
  auto f2 = [](double X, double Y) { return X * Y + 3 * X * X - Y + 1; };
  auto f4 = [](double X, double Y) { return X * X * Y * Y + X * X * X * Y - 2 * Y * Y * Y + 1; };
  // closed forms over {0 <= X, Y <= 1, X + Y < 6/5} (sympy): 0.947866666..., 116921/225000
  EXPECT_NEAR(integrate(phi, 2, f2), 0.9478666666666666, 1e-14);
  EXPECT_NEAR(integrate(phi, 4, f4), 116921.0 / 225000.0, 1e-14);
  // a degree-2 rule is exact on degree 2: compare with the degree-4 rule to round-off
  EXPECT_NEAR(integrate(phi, 2, f2), integrate(phi, 4, f2), 1e-15);
}

TEST(CutCell, DiscAreaConvergesAtSecondOrder) {
  // unit disc on a grid over [-1.3, 1.3]^2, phi = |x| - 1 at the vertices
  std::vector<double> err;
  for (int n : {16, 32, 64, 128}) {
    const double h = 2.6 / n;
    double area = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        auto phi = [&](int a, int b) {
          return std::hypot(-1.3 + (i + a) * h, -1.3 + (j + b) * h) - 1.0;
        };
        area += h * h * fraction({phi(0, 0), phi(1, 0), phi(0, 1), phi(1, 1)});
      }
    err.push_back(std::abs(area - std::numbers::pi));
  }
  for (std::size_t k = 1; k < err.size(); ++k) {
    const double rate = std::log2(err[k - 1] / err[k]);
    EXPECT_GT(rate, 1.8) << "level " << k << " errors " << err[k - 1] << " " << err[k];
  }
  EXPECT_LT(err.back(), 4e-4); // h = 0.02
}

TEST(CutCell, ElasticityKernelRigidModesSymmetryAndFullCell) {
  // a parallelogram, cut by a line
  const double x[12] = {0.1, 0.2, 0, 1.1, 0.3, 0, 0.4, 0.9, 0, 1.4, 1.0, 0};
  double w[Layout::bilinear_size] = {-0.7, 0.1, -0.2, 0.6, 2.0, 3.0};
  double A[64] = {};
  elasticity_q1(A, w, nullptr, x, nullptr, nullptr);
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 8; ++c)
      EXPECT_NEAR(A[r * 8 + c], A[c * 8 + r], 1e-14);
  // translations and the infinitesimal rotation (-y, x) carry no energy
  double modes[3][8];
  for (int n = 0; n < 4; ++n) {
    modes[0][2 * n] = 1, modes[0][2 * n + 1] = 0;
    modes[1][2 * n] = 0, modes[1][2 * n + 1] = 1;
    modes[2][2 * n] = -x[3 * n + 1], modes[2][2 * n + 1] = x[3 * n];
  }
  for (auto& m : modes)
    for (int r = 0; r < 8; ++r) {
      double s = 0;
      for (int c = 0; c < 8; ++c)
        s += A[r * 8 + c] * m[c];
      EXPECT_NEAR(s, 0.0, 1e-13);
    }
  // uniform strain e_xx = 1 on the inside part: energy = (2 mu + lambda) * area
  const double unit[12] = {0, 0, 0, 2, 0, 0, 0, 1, 0, 2, 1, 0}; // 2 x 1 rectangle
  double half[Layout::bilinear_size] = {-0.5, 0.5, -0.5, 0.5, 2.0, 3.0}; // X < 1/2
  double B[64] = {};
  elasticity_q1(B, half, nullptr, unit, nullptr, nullptr);
  double u[8];
  for (int n = 0; n < 4; ++n)
    u[2 * n] = unit[3 * n], u[2 * n + 1] = 0;
  double e = 0;
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 8; ++c)
      e += u[r] * B[r * 8 + c] * u[c];
  EXPECT_NEAR(e, (2 * 2.0 + 3.0) * 1.0, 1e-13);
}

TEST(CutCell, TractionKernelIntegratesTheClippedFacet) {
  const double x[12] = {0, 0, 0, 2, 0, 0, 0, 3, 0, 2, 3, 0}; // facet 1 is x = 0, length 3
  // phi = Y - 0.4 (reference): facet 1 inside for Y < 0.4; t = (1, Y^2 in reference) via Q2
  double w[Layout::traction_size] = {-0.4, -0.4, 0.6, 0.6};
  double* t = w + Layout::traction;
  const double Yn[9] = {0, 0, 1, 1, 0, 0.5, 0.5, 1, 0.5}; // Q2 node Y: vertices, edge mids, centre
  for (int n = 0; n < 9; ++n)
    t[2 * n] = 1.0, t[2 * n + 1] = Yn[n] * Yn[n];
  double b[8] = {};
  const int facet = 1;
  traction_q1(b, w, nullptr, x, &facet, nullptr);
  // exact: int_0^0.4 t (1 - s) 3 ds at v0 and t s 3 ds at v2 (s = Y)
  const double s1 = 0.4;
  EXPECT_NEAR(b[0], 3 * (s1 - s1 * s1 / 2), 1e-14);
  EXPECT_NEAR(b[4], 3 * (s1 * s1 / 2), 1e-14);
  EXPECT_NEAR(b[1], 3 * (std::pow(s1, 3) / 3 - std::pow(s1, 4) / 4), 1e-14);
  EXPECT_NEAR(b[5], 3 * std::pow(s1, 4) / 4, 1e-14);
  EXPECT_EQ(b[2], 0.0);
  EXPECT_EQ(b[6], 0.0);
}
