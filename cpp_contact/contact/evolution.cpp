// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "evolution.h"
#include "cut_cell.h"
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

using namespace contact;

namespace {
constexpr int gdim = StructuredGrid::gdim;

/// Node-index stride and node count along each axis (x-fastest numbering).
struct Layout {
  std::array<std::size_t, gdim> n, stride;
  explicit Layout(const StructuredGrid& grid) {
    std::size_t s = 1;
    for (int d = 0; d < gdim; ++d) {
      n[d] = grid.num_nodes(d);
      stride[d] = s;
      s *= n[d];
    }
  }
  /// Index of node k along axis d.
  std::size_t index(std::size_t k, int d) const { return (k / stride[d]) % n[d]; }
};

/// Calls f(first node, stride, count) for every grid line along axis d.
template <typename F> void for_each_line(const Layout& L, int d, F&& f) {
  const std::size_t total = L.stride[gdim - 1] * L.n[gdim - 1];
  const std::size_t s = L.stride[d], len = L.n[d];
  // Line starts are the nodes with index 0 along d: blocks of s consecutive starts every s * len
  for (std::size_t block = 0; block < total; block += s * len)
    for (std::size_t k0 = block; k0 < block + s; ++k0)
      f(k0, s, len);
}

void check_size(std::size_t got, std::size_t want, const char* func, const char* arg,
                const char* what) {
  if (got != want)
    throw std::invalid_argument(std::string(func) + ": " + arg + " must have " + what + " (" +
                                std::to_string(want) + " values), got " + std::to_string(got));
}

void check_finite(std::span<const double> a, const char* func, const char* arg) {
  for (std::size_t k = 0; k < a.size(); ++k)
    if (!std::isfinite(a[k]))
      throw std::invalid_argument(std::string(func) + ": " + arg + "[" + std::to_string(k) +
                                  "] is not finite");
}

/// Same criterion as StructuredGrid's own O(1) location.
bool is_uniform(const std::vector<double>& a) {
  const double h = (a.back() - a.front()) / double(a.size() - 1);
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::abs(a[i] - (a.front() + double(i) * h)) > 1e-12 * h * double(a.size()))
      return false;
  return true;
}

/// Line buffer with 3 ghost values at each end (linear extrapolation) and its divided
/// differences: diff[j] = (g[j + 1] - g[j]) / h, g[3 + i] = phi_i.
struct WenoLine {
  std::vector<double> g, diff;
  void load(const double* phi, std::size_t stride, std::size_t n, double h) {
    g.resize(n + 6);
    diff.resize(n + 5);
    for (std::size_t i = 0; i < n; ++i)
      g[3 + i] = phi[i * stride];
    const double s0 = g[4] - g[3], s1 = g[n + 2] - g[n + 1];
    for (std::size_t m = 1; m <= 3; ++m) {
      g[3 - m] = g[3] - double(m) * s0;
      g[n + 2 + m] = g[n + 2] + double(m) * s1;
    }
    for (std::size_t j = 0; j + 1 < g.size(); ++j)
      diff[j] = (g[j + 1] - g[j]) / h;
  }
  /// D-phi_i: from D-phi_{i-2..i+2} = diff[i..i+4]
  double minus(std::size_t i) const {
    return weno5(diff[i], diff[i + 1], diff[i + 2], diff[i + 3], diff[i + 4]);
  }
  /// D+phi_i: from D+phi_{i+2..i-2} = diff[i+5..i+1]
  double plus(std::size_t i) const {
    return weno5(diff[i + 5], diff[i + 4], diff[i + 3], diff[i + 2], diff[i + 1]);
  }
};
} // namespace

//-----------------------------------------------------------------------------
ExtensionInfo contact::extend_normal(const StructuredGrid& grid, std::span<const double> phi,
                                     std::span<const std::int8_t> known, std::span<double> values,
                                     std::size_t m, int max_sweeps) {
  constexpr const char* fn = "extend_normal";
  const std::size_t n = grid.num_nodes();
  if (m < 1)
    throw std::invalid_argument("extend_normal: m (number of fields) must be >= 1");
  if (max_sweeps < 1)
    throw std::invalid_argument("extend_normal: max_sweeps must be >= 1, got " +
                                std::to_string(max_sweeps));
  check_size(phi.size(), n, fn, "phi", "one value per node");
  check_size(known.size(), n, fn, "known", "one flag per node");
  check_size(values.size(), n * m, fn, "values", "m values per node");
  check_finite(phi, fn, "phi");

  std::vector<std::int8_t> filled(n, 0);
  bool any = false;
  for (std::size_t k = 0; k < n; ++k)
    if (known[k]) {
      check_finite(values.subspan(k * m, m), fn, "values (known row)");
      filled[k] = 1;
      any = true;
    }
  if (!any)
    throw std::invalid_argument("extend_normal: known has no nonzero entry");

  const Layout L(grid);
  std::array<const std::vector<double>*, gdim> axes;
  for (int d = 0; d < gdim; ++d)
    axes[d] = &grid.axis(d);
  std::vector<double> q(m);

  // Upwind update of node k; returns true if it changed (filled now, or a new value).
  auto relax = [&](std::size_t k) -> bool {
    if (known[k])
      return false;
    std::array<std::size_t, gdim> nb;
    std::array<double, gdim> w;
    double wsum = 0;
    for (int d = 0; d < gdim; ++d) {
      w[d] = 0;
      const std::size_t i = L.index(k, d), s = L.stride[d];
      // Neighbours below phi_k along d, the smaller-phi one first: the one-sided difference
      // in the direction of grad phi, as in the Godunov update of fast_sweep.
      std::size_t c[2];
      int nc = 0;
      if (i > 0 and phi[k - s] < phi[k])
        c[nc++] = k - s;
      if (i + 1 < L.n[d] and phi[k + s] < phi[k])
        c[nc++] = k + s;
      if (nc == 2 and phi[c[1]] < phi[c[0]])
        std::swap(c[0], c[1]);
      for (int p = 0; p < nc; ++p)
        if (filled[c[p]]) {
          const std::size_t j = L.index(c[p], d);
          const double h = std::abs((*axes[d])[j] - (*axes[d])[i]);
          nb[d] = c[p];
          w[d] = (phi[k] - phi[c[p]]) / (h * h);
          break;
        }
      wsum += w[d];
    }
    if (!(wsum > 0))
      return false;
    std::fill(q.begin(), q.end(), 0.0);
    for (int d = 0; d < gdim; ++d)
      if (w[d] > 0)
        for (std::size_t c = 0; c < m; ++c)
          q[c] += w[d] * values[nb[d] * m + c];
    bool changed = !filled[k];
    for (std::size_t c = 0; c < m; ++c) {
      const double v = q[c] / wsum;
      changed |= v != values[k * m + c];
      values[k * m + c] = v;
    }
    filled[k] = 1;
    return changed;
  };

  // Rounds of the 2^gdim orderings (Zhao 2005). Every dependency chain descends in phi, so
  // recomputing a node from final upwind values reproduces it bit for bit: a sweep without
  // change is the fixed point.
  ExtensionInfo info;
  bool converged = false;
  const std::size_t nx = L.n[0], ny = L.n[1];
  while (info.sweeps < 4 * max_sweeps) {
    const int ordering = info.sweeps++ % 4;
    const bool xrev = ordering == 1 or ordering == 2, yrev = ordering >= 2;
    bool changed = false;
    for (std::size_t jj = 0; jj < ny; ++jj) {
      const std::size_t j = yrev ? ny - 1 - jj : jj;
      for (std::size_t ii = 0; ii < nx; ++ii)
        changed |= relax((xrev ? nx - 1 - ii : ii) + nx * j);
    }
    if (!changed) {
      converged = true;
      break;
    }
  }
  if (!converged)
    throw std::runtime_error("extend_normal: not converged after max_sweeps = " +
                             std::to_string(max_sweeps) + " rounds of sweeps");

  // Fallback: layers of the remaining nodes take the mean of their filled 4-neighbours.
  // The grid is connected and a node is known, so this ends.
  std::vector<std::size_t> layer;
  for (;;) {
    layer.clear();
    for (std::size_t k = 0; k < n; ++k) {
      if (filled[k])
        continue;
      std::fill(q.begin(), q.end(), 0.0);
      int cnt = 0;
      for (int d = 0; d < gdim; ++d) {
        const std::size_t i = L.index(k, d), s = L.stride[d];
        for (std::size_t nbk : {i > 0 ? k - s : k, i + 1 < L.n[d] ? k + s : k})
          if (nbk != k and filled[nbk] == 1) {
            for (std::size_t c = 0; c < m; ++c)
              q[c] += values[nbk * m + c];
            ++cnt;
          }
      }
      if (cnt > 0) {
        for (std::size_t c = 0; c < m; ++c)
          values[k * m + c] = q[c] / cnt;
        layer.push_back(k);
      }
    }
    if (layer.empty())
      break;
    for (std::size_t k : layer)
      filled[k] = 1; // only after the layer, so a layer reads the previous ones only
    info.fallback += layer.size();
  }
  return info;
}
//-----------------------------------------------------------------------------
double contact::weno5(double v1, double v2, double v3, double v4, double v5) {
  // Third-order ENO candidates
  const double p1 = v1 / 3 - 7 * v2 / 6 + 11 * v3 / 6;
  const double p2 = -v2 / 6 + 5 * v3 / 6 + v4 / 3;
  const double p3 = v3 / 3 + 5 * v4 / 6 - v5 / 6;
  // Smoothness indicators
  const double a = v1 - 2 * v2 + v3, b = v1 - 4 * v2 + 3 * v3;
  const double c = v2 - 2 * v3 + v4, d = v2 - v4;
  const double e = v3 - 2 * v4 + v5, f = 3 * v3 - 4 * v4 + v5;
  const double s1 = 13.0 / 12 * a * a + 0.25 * b * b;
  const double s2 = 13.0 / 12 * c * c + 0.25 * d * d;
  const double s3 = 13.0 / 12 * e * e + 0.25 * f * f;
  const double eps = 1e-6 * std::max({v1 * v1, v2 * v2, v3 * v3, v4 * v4, v5 * v5}) + 1e-99;
  const double a1 = 0.1 / ((s1 + eps) * (s1 + eps));
  const double a2 = 0.6 / ((s2 + eps) * (s2 + eps));
  const double a3 = 0.3 / ((s3 + eps) * (s3 + eps));
  return (a1 * p1 + a2 * p2 + a3 * p3) / (a1 + a2 + a3);
}
//-----------------------------------------------------------------------------
void contact::weno5_derivatives(std::span<const double> line, double h, std::span<double> minus,
                                std::span<double> plus) {
  const std::size_t n = line.size();
  if (n < 2)
    throw std::invalid_argument("weno5_derivatives: line must have at least 2 values, got " +
                                std::to_string(n));
  if (!(h > 0) or !std::isfinite(h))
    throw std::invalid_argument("weno5_derivatives: h must be positive and finite");
  check_size(minus.size(), n, "weno5_derivatives", "minus", "one entry per value");
  check_size(plus.size(), n, "weno5_derivatives", "plus", "one entry per value");
  check_finite(line, "weno5_derivatives", "line");
  WenoLine w;
  w.load(line.data(), 1, n, h);
  for (std::size_t i = 0; i < n; ++i) {
    minus[i] = w.minus(i);
    plus[i] = w.plus(i);
  }
}
//-----------------------------------------------------------------------------
AdvectResult contact::advect(const StructuredGrid& grid, std::span<const double> phi,
                             std::span<const double> velocity, double time, double cfl) {
  constexpr const char* fn = "advect";
  const std::size_t n = grid.num_nodes();
  for (int d = 0; d < gdim; ++d)
    if (!is_uniform(grid.axis(d)))
      throw std::invalid_argument("advect: grid axis " + std::to_string(d) +
                                  " is graded; HJ-WENO5 needs a uniform grid");
  check_size(phi.size(), n, fn, "phi", "one value per node");
  check_size(velocity.size(), gdim * n, fn, "velocity", "shape (nodes, 2)");
  check_finite(phi, fn, "phi");
  check_finite(velocity, fn, "velocity");
  if (!(time >= 0) or !std::isfinite(time))
    throw std::invalid_argument("advect: time must be finite and >= 0");
  if (!(cfl > 0 and cfl <= 1))
    throw std::invalid_argument("advect: cfl must lie in (0, 1]");

  const Layout L(grid);
  std::array<double, gdim> h;
  double hmin = std::numeric_limits<double>::max();
  for (int d = 0; d < gdim; ++d) {
    h[d] = (grid.axis(d).back() - grid.axis(d).front()) / double(L.n[d] - 1);
    hmin = std::min(hmin, h[d]);
  }
  double vmax = 0;
  for (std::size_t k = 0; k < n; ++k) {
    double s = 0;
    for (int d = 0; d < gdim; ++d)
      s += std::abs(velocity[gdim * k + d]);
    vmax = std::max(vmax, s);
  }
  // dt <= cfl h / max(|vx| + |vy|): the sum bounds the 2D (3D) dimension-by-dimension scheme
  const double steps = std::ceil(time * vmax / (cfl * hmin) * (1 - 1e-12));
  const int substeps = std::max(1, int(std::min(steps, 1e9)));
  const double dt = time / substeps;

  // rate = -v . grad phi, the one-sided WENO derivative per axis picked by the sign of v_d
  WenoLine line;
  auto rate = [&](const std::vector<double>& u, std::vector<double>& r) {
    std::fill(r.begin(), r.end(), 0.0);
    for (int d = 0; d < gdim; ++d)
      for_each_line(L, d, [&](std::size_t k0, std::size_t s, std::size_t len) {
        line.load(u.data() + k0, s, len, h[d]);
        for (std::size_t i = 0; i < len; ++i) {
          const std::size_t k = k0 + i * s;
          const double vd = velocity[gdim * k + d];
          if (vd > 0)
            r[k] -= vd * line.minus(i);
          else if (vd < 0)
            r[k] -= vd * line.plus(i);
        }
      });
  };

  // TVD-RK3 (Shu & Osher 1988) as convex combinations of forward Euler steps
  std::vector<double> u(phi.begin(), phi.end()), u1(n), u2(n), r(n);
  if (time == 0 or vmax == 0)
    return {std::move(u), substeps};
  for (int step = 0; step < substeps; ++step) {
    rate(u, r);
    for (std::size_t k = 0; k < n; ++k)
      u1[k] = u[k] + dt * r[k];
    rate(u1, r);
    for (std::size_t k = 0; k < n; ++k)
      u2[k] = 0.75 * u[k] + 0.25 * (u1[k] + dt * r[k]);
    rate(u2, r);
    for (std::size_t k = 0; k < n; ++k)
      u[k] = u[k] / 3 + 2.0 / 3 * (u2[k] + dt * r[k]);
  }
  return {std::move(u), substeps};
}
//-----------------------------------------------------------------------------
double contact::gradient_drift(const StructuredGrid& grid, std::span<const double> phi,
                               double band) {
  check_size(phi.size(), grid.num_nodes(), "gradient_drift", "phi", "one value per node");
  if (!(band >= 0))
    throw std::invalid_argument("gradient_drift: band must be >= 0");
  const Layout L(grid);
  const std::size_t n = phi.size();
  double drift = 0;
  for (std::size_t k = 0; k < n; ++k) {
    double g2 = 0;
    for (int d = 0; d < gdim; ++d) {
      const auto& a = grid.axis(d);
      const std::size_t i = L.index(k, d), s = L.stride[d], len = L.n[d];
      double g;
      if (i == 0)
        g = (phi[k + s] - phi[k]) / (a[1] - a[0]);
      else if (i + 1 == len)
        g = (phi[k] - phi[k - s]) / (a[i] - a[i - 1]);
      else {
        // Three-point formula, second order on graded axes, central on uniform ones
        const double hm = a[i] - a[i - 1], hp = a[i + 1] - a[i];
        g = (hm * hm * (phi[k + s] - phi[k]) + hp * hp * (phi[k] - phi[k - s])) /
            (hm * hp * (hm + hp));
      }
      g2 += g * g;
    }
    const double gn = std::sqrt(g2);
    if (std::abs(phi[k]) <= band * gn)
      drift = std::max(drift, std::abs(gn - 1));
  }
  return drift;
}
//-----------------------------------------------------------------------------
double contact::inside_area(const StructuredGrid& grid, std::span<const double> phi) {
  check_size(phi.size(), grid.num_nodes(), "inside_area", "phi", "one value per node");
  const auto& x = grid.axis(0);
  const auto& y = grid.axis(1);
  double area = 0;
  for (std::size_t j = 0; j + 1 < y.size(); ++j) {
    double row = 0;
    for (std::size_t i = 0; i + 1 < x.size(); ++i) {
      // Vertices in the tensor order of cut_cell.h: (0,0), (1,0), (0,1), (1,1)
      const std::array<double, 4> v = {phi[grid.node(i, j)], phi[grid.node(i + 1, j)],
                                       phi[grid.node(i, j + 1)], phi[grid.node(i + 1, j + 1)]};
      row += cut::inside_fraction(v) * (x[i + 1] - x[i]);
    }
    area += row * (y[j + 1] - y[j]);
  }
  return area;
}
