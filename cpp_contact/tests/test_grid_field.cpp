// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Q1 field evaluation on axis-aligned grid cells: a trilinear (bilinear) field is reproduced
// exactly, value and gradient, inside and outside the cell; a wrong dof is an error.
#include <cmath>
#include <contact/grid_field.h>
#include <gtest/gtest.h>
#include <random>
#include <stdexcept>
#include <vector>

using namespace contact;

namespace {

/// A field in Q1 (bilinear / trilinear), 2 components: u_c = c0 + sum_a c_a x_a + c_xy x0 x1.
double field(int c, const double* x, int dim, double* grad) {
  const double k = 1.0 + c;
  double v = 0.5 * k, cross = x[0] * x[1];
  for (int a = 0; a < dim; ++a)
    v += (a + 1) * k * x[a];
  for (int a = 0; a < dim; ++a)
    grad[a] = (a + 1) * k + (a == 0 ? 0.3 * x[1] : a == 1 ? 0.3 * x[0] : 0.0);
  return v + 0.3 * cross;
}

void check(int dim) {
  std::mt19937 gen(3);
  std::uniform_real_distribution<double> U(-0.3, 1.3), E(0.1, 2.0), O(-5, 5);
  const int nv = 1 << dim, n = 50;
  std::vector<double> u, X, ext;
  std::vector<std::int32_t> dofs;
  std::vector<std::vector<double>> points;
  for (int p = 0; p < n; ++p) {
    std::vector<double> o(dim), e(dim), x(dim);
    for (int a = 0; a < dim; ++a) {
      o[a] = O(gen), e[a] = E(gen);
      X.push_back(U(gen));
      ext.push_back(e[a]);
      x[a] = o[a] + X.back() * e[a];
    }
    points.push_back(x);
    for (int v = 0; v < nv; ++v) { // vertex v at o + bit_a(v) e_a, one dof each
      std::vector<double> xv(dim), g(dim);
      for (int a = 0; a < dim; ++a)
        xv[a] = o[a] + ((v >> a) & 1) * e[a];
      dofs.push_back(std::int32_t(u.size() / 2));
      for (int c = 0; c < 2; ++c)
        u.push_back(field(c, xv.data(), dim, g.data()));
    }
  }
  std::vector<double> out(std::size_t(n * 2 * (1 + dim)));
  q1_evaluate(u, 2, dofs, X, ext, dim, out);
  for (int p = 0; p < n; ++p) {
    for (int c = 0; c < 2; ++c) {
      std::vector<double> g(dim);
      const double v = field(c, points[p].data(), dim, g.data());
      const double* o = out.data() + p * 2 * (1 + dim);
      EXPECT_NEAR(o[c], v, 1e-12 * (1 + std::abs(v)));
      for (int a = 0; a < dim; ++a)
        EXPECT_NEAR(o[2 + dim * c + a], g[a], 1e-11 * (1 + std::abs(g[a])));
    }
  }
  dofs[0] = std::int32_t(u.size()); // past the last dof
  EXPECT_THROW(q1_evaluate(u, 2, dofs, X, ext, dim, out), std::invalid_argument);
}

} // namespace

TEST(GridField, BilinearFieldExact) {
  check(2);
}
TEST(GridField, TrilinearFieldExact) {
  check(3);
}
