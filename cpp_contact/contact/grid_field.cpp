// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "grid_field.h"

#include <array>
#include <stdexcept>
#include <string>

namespace contact {

namespace {

template <int D>
void evaluate(std::span<const double> u, std::size_t bs, std::span<const std::int32_t> dofs,
              std::span<const double> X, std::span<const double> extent, std::span<double> out) {
  constexpr int V = 1 << D;
  const std::size_t n = X.size() / D, stride = bs * (1 + D);
  const std::size_t ndofs = u.size() / bs;
  for (std::size_t p = 0; p < n; ++p) {
    const double* x = X.data() + D * p;
    // 1D factors per axis: value (1 - X, X) and slope (-1, 1) / e
    std::array<std::array<double, 2>, D> f, g;
    for (int a = 0; a < D; ++a) {
      f[a] = {1.0 - x[a], x[a]};
      const double inv = 1.0 / extent[D * p + a];
      g[a] = {-inv, inv};
    }
    double* o = out.data() + stride * p;
    for (std::size_t k = 0; k < stride; ++k)
      o[k] = 0.0;
    for (int v = 0; v < V; ++v) {
      const std::int32_t dof = dofs[V * p + v];
      if (dof < 0 or std::size_t(dof) >= ndofs)
        throw std::invalid_argument("q1_evaluate: dof " + std::to_string(dof) + " of point " +
                                    std::to_string(p) + " is out of range");
      double N = 1.0;
      std::array<double, D> dN;
      dN.fill(1.0);
      for (int a = 0; a < D; ++a) {
        const int bit = (v >> a) & 1;
        N *= f[a][bit];
        for (int b = 0; b < D; ++b)
          dN[b] *= (a == b) ? g[a][bit] : f[a][bit];
      }
      const double* uv = u.data() + bs * std::size_t(dof);
      for (std::size_t c = 0; c < bs; ++c) {
        o[c] += N * uv[c];
        for (int a = 0; a < D; ++a)
          o[bs + D * c + a] += dN[a] * uv[c];
      }
    }
  }
}

} // namespace

void q1_evaluate(std::span<const double> u, int bs, std::span<const std::int32_t> dofs,
                 std::span<const double> X, std::span<const double> extent, int dim,
                 std::span<double> out) {
  if (dim != 2 and dim != 3)
    throw std::invalid_argument("q1_evaluate: dim must be 2 or 3, got " + std::to_string(dim));
  if (bs < 1 or u.size() % std::size_t(bs) != 0)
    throw std::invalid_argument("q1_evaluate: u must hold (num_dofs, bs) values, bs >= 1");
  const std::size_t d = std::size_t(dim), n = X.size() / d;
  if (X.size() != n * d or extent.size() != n * d or dofs.size() != n * (std::size_t(1) << d) or
      out.size() != n * std::size_t(bs) * (1 + d))
    throw std::invalid_argument("q1_evaluate: X, extent (n, dim), dofs (n, 2^dim) and out "
                                "(n, bs (1 + dim)) must agree in n");
  if (dim == 2)
    evaluate<2>(u, std::size_t(bs), dofs, X, extent, out);
  else
    evaluate<3>(u, std::size_t(bs), dofs, X, extent, out);
}

} // namespace contact
