// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Tests of the MLS projection (eqs 38-45): spline weight, linear reproduction, second-order
// convergence, widening of singular fits and errors. Set CONTACT_TEST_VERBOSE=1 to print the
// measured errors and orders.
#include <contact/mls.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

using namespace contact;

namespace {

bool verbose() {
  return std::getenv("CONTACT_TEST_VERBOSE") != nullptr;
}

/// 3^d jittered points per cell of a uniform grid of [0, 1]^d with n cells per direction: the
/// 3-point Gauss abscissae of each cell moved by up to +-jitter * h per coordinate, i.e. the
/// material points of a deformed 3x3 Gauss rule (~3 points per h per direction).
std::vector<double> gauss_cloud(int dim, int n, double jitter, unsigned seed) {
  const double h = 1.0 / n, g = std::sqrt(0.6) / 2;
  const double gp[3] = {0.5 - g, 0.5, 0.5 + g};
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-jitter, jitter);
  std::vector<double> x;
  const int nz = dim == 3 ? n : 1, qz = dim == 3 ? 3 : 1;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (int c = 0; c < qz; ++c)
          for (int b = 0; b < 3; ++b)
            for (int a = 0; a < 3; ++a) {
              x.push_back((i + gp[a] + u(gen)) * h);
              x.push_back((j + gp[b] + u(gen)) * h);
              if (dim == 3)
                x.push_back((k + gp[c] + u(gen)) * h);
            }
  return x;
}

std::vector<double> uniform_points(int dim, std::size_t k, double lo, double hi, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> x(k * dim);
  for (double& v : x)
    v = u(gen);
  return x;
}

} // namespace

TEST(MLS, SplineWeightValuesAndContinuity) {
  EXPECT_DOUBLE_EQ(quadratic_spline_weight(0.0), 0.75);
  EXPECT_DOUBLE_EQ(quadratic_spline_weight(0.5), 0.5);
  EXPECT_DOUBLE_EQ(quadratic_spline_weight(1.0), 0.125);
  EXPECT_DOUBLE_EQ(quadratic_spline_weight(1.5), 0.0);
  EXPECT_DOUBLE_EQ(quadratic_spline_weight(2.0), 0.0);
  EXPECT_DOUBLE_EQ(quadratic_spline_weight(-1.0), 0.125); // radial: symmetric
  // C1 at the knots: one-sided values and slopes (central differences of step e, exact up to
  // O(e) for the jump in w'' and round-off eps/e) agree to 1e-6.
  const double e = 1e-7;
  for (double r0 : {0.5, 1.5}) {
    EXPECT_NEAR(quadratic_spline_weight(r0 - e), quadratic_spline_weight(r0 + e), 1e-6) << r0;
    const double left = (quadratic_spline_weight(r0) - quadratic_spline_weight(r0 - e)) / e;
    const double right = (quadratic_spline_weight(r0 + e) - quadratic_spline_weight(r0)) / e;
    EXPECT_NEAR(left, right, 1e-6) << r0;
  }
  // Nonnegative and nonincreasing in r.
  double prev = 1.0;
  for (int i = 0; i <= 200; ++i) {
    const double w = quadratic_spline_weight(0.01 * i);
    EXPECT_GE(w, 0.0);
    EXPECT_LE(w, prev);
    prev = w;
  }
  // 1D partition of unity of the B-spline shifts at integer spacing (the MPM property of this
  // kernel): sum_i w(x - i) = 1 for every x. (Not required by MLS, which normalises by M.)
  for (double x : {0.0, 0.13, 0.5, 0.77}) {
    double s = 0;
    for (int i = -3; i <= 3; ++i)
      s += quadratic_spline_weight(x - i);
    EXPECT_NEAR(s, 1.0, 1e-15) << x;
  }
}

// Linear fields are in the basis: eq 44 reproduces them up to round-off (a sum of ~30-70
// terms with O(1) shape functions and rcond >> 1e-8: errors ~1e-15 relative), in 2D and 3D,
// at targets that are sources and between sources, and for m fields at once.
TEST(MLS, ReproducesLinearFields) {
  for (int dim : {2, 3}) {
    const int n = dim == 2 ? 10 : 5;
    const double h = 1.0 / n;
    const auto src = gauss_cloud(dim, n, 0.15, 1);
    const std::size_t np = src.size() / dim;
    auto tgt = uniform_points(dim, 200, 0.0, 1.0, 2);
    tgt.insert(tgt.end(), src.begin(), src.begin() + 50 * dim);
    const std::size_t k = tgt.size() / dim;
    auto field = [&](const double* x, int f) {
      double v = 1.0 + f;
      for (int a = 0; a < dim; ++a)
        v += (a + 1.0 - 2.0 * f) * x[a] * (f == 2 ? 1e3 : 1.0);
      return v;
    };
    const std::size_t m = 3;
    std::vector<double> u(np * m);
    for (std::size_t p = 0; p < np; ++p)
      for (std::size_t f = 0; f < m; ++f)
        u[p * m + f] = field(&src[p * dim], int(f));
    const MLSProjector mls(src, dim, h);
    EXPECT_EQ(mls.num_points(), np);
    const MLSResult r = mls.project(u, m, tgt);
    double err = 0;
    for (std::size_t t = 0; t < k; ++t)
      for (std::size_t f = 0; f < m; ++f) {
        const double ex = field(&tgt[t * dim], int(f));
        err = std::max(err, std::abs(r.values[t * m + f] - ex) / std::max(1.0, std::abs(ex)));
      }
    if (verbose())
      std::printf("MLS linear reproduction %dD: max relative error %.2e\n", dim, err);
    EXPECT_LT(err, 1e-12) << dim;
    for (std::size_t t = 0; t < k; ++t) {
      EXPECT_GE(r.rcond[t], 1e-8);
      EXPECT_GE(r.neighbours[t], dim + 1);
      EXPECT_GE(r.widening[t], 1.0);
    }
  }
}

// The linear fit of a quadratic field errs by O(h^2). With h halved three times on jittered
// 3x3 Gauss clouds the RMS error over fixed targets falls at order ~2 (2.0-2.1 measured; the
// bound 1.8 leaves room for the random jitter changing the error constant between levels).
// The max error is noisier (it samples the worst local configuration, pairwise orders 1.6-2.5
// over seeds), so its order is the least-squares slope over the four levels (1.95-2.17).
TEST(MLS, SecondOrderOnQuadraticField) {
  auto f = [](double x, double y) { return x * x + 0.7 * x * y - 0.5 * y * y + x; };
  const auto tgt = uniform_points(2, 500, 0.0, 1.0, 7);
  std::vector<double> rms, emax, logh;
  for (int n : {8, 16, 32, 64}) {
    const auto src = gauss_cloud(2, n, 0.15, 11 + n);
    std::vector<double> u(src.size() / 2);
    for (std::size_t p = 0; p < u.size(); ++p)
      u[p] = f(src[2 * p], src[2 * p + 1]);
    const MLSResult r = MLSProjector(src, 2, 1.0 / n).project(u, 1, tgt);
    double e2 = 0, em = 0;
    for (std::size_t t = 0; t < r.values.size(); ++t) {
      const double e = std::abs(r.values[t] - f(tgt[2 * t], tgt[2 * t + 1]));
      e2 += e * e;
      em = std::max(em, e);
    }
    rms.push_back(std::sqrt(e2 / double(r.values.size())));
    emax.push_back(em);
    logh.push_back(std::log(1.0 / n));
  }
  for (std::size_t i = 1; i < rms.size(); ++i) {
    const double rate = std::log2(rms[i - 1] / rms[i]);
    if (verbose())
      std::printf("MLS quadratic: h = 1/%d RMS error %.3e rate %.3f, max error %.3e\n", 8 << i,
                  rms[i], rate, emax[i]);
    EXPECT_GT(rate, 1.8) << i;
  }
  // Least-squares slope of log(max error) against log h.
  double mx = 0, my = 0, sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < emax.size(); ++i) {
    mx += logh[i] / double(emax.size());
    my += std::log(emax[i]) / double(emax.size());
  }
  for (std::size_t i = 0; i < emax.size(); ++i) {
    sxy += (logh[i] - mx) * (std::log(emax[i]) - my);
    sxx += (logh[i] - mx) * (logh[i] - mx);
  }
  if (verbose())
    std::printf("MLS quadratic: max-error order (least squares) %.3f\n", sxy / sxx);
  EXPECT_GT(sxy / sxx, 1.8);
}

// Sources on the x axis only within 1.5 h of the target, plus two points at distance 2 h off
// the axis: the fit at h is rank-deficient (collinear), one widening (2.25 h) cures it.
TEST(MLS, CollinearNeighboursAreWidened) {
  const double h = 0.1;
  std::vector<double> src;
  for (int i = -9; i <= 9; ++i) {
    src.push_back(i * h / 3);
    src.push_back(0.0);
  }
  src.insert(src.end(), {0.0, 2 * h, 0.05, -2 * h});
  std::vector<double> u(src.size() / 2);
  for (std::size_t p = 0; p < u.size(); ++p)
    u[p] = 2.0 - src[2 * p] + 3.0 * src[2 * p + 1];
  const MLSProjector mls(src, 2, h);
  const std::vector<double> tgt = {0.01, 0.0, 0.02, 0.03};
  const MLSResult r = mls.project(u, 1, tgt);
  for (int t = 0; t < 2; ++t) {
    EXPECT_DOUBLE_EQ(r.widening[t], 1.5) << t;
    EXPECT_GE(r.rcond[t], 1e-8);
    EXPECT_NEAR(r.values[t], 2.0 - tgt[2 * t] + 3.0 * tgt[2 * t + 1], 1e-12) << t;
  }
  // All sources collinear: no widening can help, the projector throws naming the target.
  const std::vector<double> line(src.begin(), src.end() - 4);
  const MLSProjector bad(line, 2, h);
  const std::vector<double> v(line.size() / 2, 1.0);
  try {
    bad.project(v, 1, std::vector<double>{0.0, 0.0, 0.0, 0.01});
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("target 0"), std::string::npos) << e.what();
  }
}

TEST(MLS, FarTargetThrowsWithItsIndex) {
  const auto src = gauss_cloud(2, 4, 0.1, 3);
  const std::vector<double> u(src.size() / 2, 1.0);
  const MLSProjector mls(src, 2, 0.25);
  const std::vector<double> tgt = {0.5, 0.5, 0.2, 0.3, 10.0, -4.0};
  try {
    mls.project(u, 1, tgt);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("target 2 at (10, -4)"), std::string::npos) << what;
  }
  // Just outside the cloud (one-sided support) still projects, without widening.
  const MLSResult r = mls.project(u, 1, std::vector<double>{1.05, 0.5});
  EXPECT_NEAR(r.values[0], 1.0, 1e-14);
  EXPECT_EQ(r.widening[0], 1.0);
}

TEST(MLS, BadInputThrowsInvalidArgument) {
  const auto src = gauss_cloud(2, 2, 0.0, 0);
  EXPECT_THROW(MLSProjector(src, 4, 0.5), std::invalid_argument);
  EXPECT_THROW(MLSProjector(std::vector<double>(src.begin(), src.end() - 1), 2, 0.5),
               std::invalid_argument);
  EXPECT_THROW(MLSProjector(src, 2, 0.0), std::invalid_argument);
  EXPECT_THROW(MLSProjector(src, 2, NAN), std::invalid_argument);
  auto nan_src = src;
  nan_src[3] = NAN;
  EXPECT_THROW(MLSProjector(nan_src, 2, 0.5), std::invalid_argument);
  EXPECT_THROW(MLSProjector(src, 2, 0.5, MLSOptions{1e-8, 1.0, 4}), std::invalid_argument);
  const MLSProjector mls(src, 2, 0.5);
  const std::vector<double> u(mls.num_points(), 1.0);
  EXPECT_THROW(mls.project(u, 2, std::vector<double>{0.5, 0.5}), std::invalid_argument);
  EXPECT_THROW(mls.project(u, 1, std::vector<double>{0.5, 0.5, 0.5}), std::invalid_argument);
  EXPECT_THROW(mls.project(u, 1, std::vector<double>{0.5, NAN}), std::invalid_argument);
}

// Threads share the targets in runs fixed by the targets alone: the values, widenings and
// neighbour counts are the same bit for bit for any thread count (2D and 3D, targets in the
// sources' own cell order as the MPM projects them, plus scattered ones).
TEST(MLS, ThreadsBitIdentical) {
  for (int dim : {2, 3}) {
    const int n = dim == 2 ? 40 : 12;
    const auto src = gauss_cloud(dim, n, 0.15, 5);
    auto tgt = gauss_cloud(dim, n, 0.0, 6);
    const auto extra = uniform_points(dim, 300, 0.0, 1.0, 8);
    tgt.insert(tgt.end(), extra.begin(), extra.end());
    std::vector<double> u(src.size() / dim * 2);
    for (std::size_t p = 0; p < u.size(); ++p)
      u[p] = std::sin(double(p));
    const MLSProjector mls(src, dim, 1.0 / n);
    const MLSResult one = mls.project(u, 2, tgt, 1);
    for (int threads : {2, 3, 7}) {
      const MLSResult r = mls.project(u, 2, tgt, threads);
      EXPECT_EQ(r.values, one.values) << dim << " " << threads;
      EXPECT_EQ(r.widening, one.widening);
      EXPECT_EQ(r.neighbours, one.neighbours);
    }
  }
}
