// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include <cmath>
#include <contact/cut_cell.h>
#include <gtest/gtest.h>
#include <numbers>
#include <random>
#include <stdexcept>

using namespace contact::cut;

namespace {
double fraction(std::array<double, 4> phi) {
  return inside_fraction(phi);
}

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

namespace {
/// Tensor Gauss-Legendre points on [0,1]^2 (X slow, Y fast as in basix) and weights, m = 2..4.
void tensor_gauss(int m, std::vector<double>& pts, std::vector<double>& wts) {
  std::vector<double> x, w;
  if (m == 2)
    x = {0.5 - std::sqrt(3.0) / 6, 0.5 + std::sqrt(3.0) / 6}, w = {0.5, 0.5};
  else if (m == 3)
    x = {0.5 - std::sqrt(15.0) / 10, 0.5, 0.5 + std::sqrt(15.0) / 10},
    w = {5. / 18, 8. / 18, 5. / 18};
  else {
    const double a = std::sqrt(3. / 7 - 2. / 7 * std::sqrt(1.2)),
                 b = std::sqrt(3. / 7 + 2. / 7 * std::sqrt(1.2));
    const double wa = (18 + std::sqrt(30.0)) / 72, wb = (18 - std::sqrt(30.0)) / 72;
    x = {0.5 * (1 - b), 0.5 * (1 - a), 0.5 * (1 + a), 0.5 * (1 + b)}, w = {wb, wa, wa, wb};
  }
  pts.clear(), wts.clear();
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j)
      pts.insert(pts.end(), {x[i], x[j]}), wts.push_back(w[i] * w[j]);
}

std::vector<double> fitted(std::array<double, 4> phi, const std::vector<double>& pts) {
  std::vector<double> w(pts.size() / 2);
  moment_fitted_weights(phi, pts, w);
  return w;
}

/// Random polynomial in Q_{m-1}: coefficient c[a * m + b] of X^a Y^b.
struct Poly {
  int m;
  std::vector<double> c;
  double operator()(double X, double Y) const {
    double s = 0;
    for (int a = 0; a < m; ++a)
      for (int b = 0; b < m; ++b)
        s += c[a * m + b] * std::pow(X, a) * std::pow(Y, b);
    return s;
  }
};
} // namespace

TEST(MomentFitting, FullCellGivesGaussWeightsEmptyCellZeros) {
  for (int m : {2, 3, 4}) {
    std::vector<double> pts, gauss;
    tensor_gauss(m, pts, gauss);
    const auto full = fitted({-1, -2, -0.5, -3}, pts);
    for (std::size_t k = 0; k < gauss.size(); ++k)
      EXPECT_NEAR(full[k], gauss[k], 2e-16) << "m = " << m << " point " << k;
    for (double w : fitted({1, 2, 0, 3}, pts)) // phi = 0 is outside
      EXPECT_EQ(w, 0.0);
  }
}

TEST(MomentFitting, ExactForTensorPolynomialsOnStraightCuts) {
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int m : {2, 3, 4}) {
    std::vector<double> pts, gauss;
    tensor_gauss(m, pts, gauss);
    for (int trial = 0; trial < 50; ++trial) {
      // phi = a + b X + c Y at the vertices: a straight cut through the cell (or none)
      const double a = 0.5 * U(gen), b = U(gen), c = U(gen);
      const std::array<double, 4> phi = {a, a + b, a + c, a + b + c};
      Poly p{m, std::vector<double>(m * m)};
      for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) // m = 4: keep total degree <= 4 (the reference rule's)
          p.c[i * m + j] = (i + j <= 4) ? U(gen) : 0.0;
      const auto w = fitted(phi, pts);
      double s = 0;
      for (std::size_t k = 0; k < w.size(); ++k)
        s += w[k] * p(pts[2 * k], pts[2 * k + 1]);
      EXPECT_NEAR(s, integrate(phi, 4, p), 1e-14) << "m = " << m << " trial " << trial;
    }
  }
  // m = 4, the full Q3 (degree 6) against closed forms: the strip X < s and the corner
  // triangle X + Y < s, int X^a Y^b = s^(a+1) / ((a+1)(b+1)) and a! b! s^(a+b+2) / (a+b+2)!
  std::vector<double> pts, gauss;
  tensor_gauss(4, pts, gauss);
  const double s = 0.37;
  const auto strip = fitted({-s, 1 - s, -s, 1 - s}, pts);
  const auto corner = fitted({-s, 1 - s, 1 - s, 2 - s}, pts);
  auto fact = [](int n) { return std::tgamma(n + 1.0); };
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) {
      double ss = 0, sc = 0;
      for (std::size_t k = 0; k < strip.size(); ++k) {
        const double f = std::pow(pts[2 * k], a) * std::pow(pts[2 * k + 1], b);
        ss += strip[k] * f, sc += corner[k] * f;
      }
      EXPECT_NEAR(ss, std::pow(s, a + 1) / ((a + 1) * (b + 1)), 1e-15) << a << " " << b;
      EXPECT_NEAR(sc, fact(a) * fact(b) * std::pow(s, a + b + 2) / fact(a + b + 2), 1e-16)
          << a << " " << b;
    }
}

TEST(MomentFitting, PointOrderIsFree) {
  std::vector<double> pts, gauss;
  tensor_gauss(3, pts, gauss);
  const std::array<double, 4> phi = {-0.3, 0.5, -0.1, 0.2};
  const auto w = fitted(phi, pts);
  std::vector<double> rev(pts.size()); // reversed order, X and Y swapped: still a tensor grid
  const std::size_t nq = w.size();
  for (std::size_t k = 0; k < nq; ++k)
    rev[2 * k] = pts[2 * (nq - 1 - k) + 1], rev[2 * k + 1] = pts[2 * (nq - 1 - k)];
  const std::array<double, 4> phi_t = {phi[0], phi[2], phi[1], phi[3]}; // transpose the cell
  const auto wr = fitted(phi_t, rev);
  for (std::size_t k = 0; k < nq; ++k)
    EXPECT_NEAR(wr[k], w[nq - 1 - k], 1e-16);
}

TEST(MomentFitting, NonTensorPointsRejected) {
  std::vector<double> pts, gauss;
  tensor_gauss(3, pts, gauss);
  const std::array<double, 4> phi = {-1, 1, -1, 1};
  std::vector<double> w(9);
  auto bad = [&](std::vector<double> p, std::size_t nw) {
    std::vector<double> out(nw);
    EXPECT_THROW(moment_fitted_weights(phi, p, out), std::invalid_argument);
  };
  EXPECT_NO_THROW(moment_fitted_weights(phi, pts, w));
  bad({pts.begin(), pts.end() - 2}, 8); // a missing point
  auto dup = pts;
  dup[16] = dup[0], dup[17] = dup[1]; // a repeated point instead of the last
  bad(dup, 9);
  auto off = pts;
  off[8] += 1e-3; // one X off its grid line
  bad(off, 9);
  bad({pts.begin(), pts.end() - 1}, 8); // odd number of coordinates
  bad(pts, 8);                          // weights of the wrong size
  bad({}, 0);
  std::vector<double> seven; // 7 x 7: beyond max_fitted_points
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 7; ++j)
      seven.insert(seven.end(), {(i + 0.5) / 7, (j + 0.5) / 7});
  bad(seven, 49);
}
