// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "contact_surface.h"
#include "contour.h"
#include "reinit.h"
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

using namespace contact;

namespace {
void check_same_grid(const LevelSet& a, const LevelSet& b, const char* fn) {
  for (int d = 0; d < 2; ++d)
    if (a.grid().axis(d) != b.grid().axis(d))
      throw std::invalid_argument(std::string(fn) + ": the two level sets must share one grid");
}

LevelSet combine(const LevelSet& a, const LevelSet& b, double (*op)(double, double)) {
  std::vector<double> v(a.values().size());
  for (std::size_t k = 0; k < v.size(); ++k)
    v[k] = op(a.values()[k], b.values()[k]);
  return LevelSet(a.grid(), std::move(v));
}

/// Root of f on [0, 1] with f(0) f(1) <= 0 (Illinois variant of regula falsi:
/// superlinear and bracketed, so it cannot leave the edge).
template <typename F> double bracketed_root(F&& f, double f0, double f1) {
  if (f0 == 0)
    return 0.0;
  if (f1 == 0)
    return 1.0;
  double t0 = 0, t1 = 1;
  int side = 0;
  for (int it = 0; it < 100 and t1 - t0 > 1e-15; ++it) {
    const double t = (t0 * f1 - t1 * f0) / (f1 - f0);
    const double ft = f(t);
    if (ft == 0)
      return t;
    if ((ft < 0) == (f0 < 0)) {
      t0 = t, f0 = ft;
      if (side == -1)
        f1 *= 0.5;
      side = -1;
    } else {
      t1 = t, f1 = ft;
      if (side == 1)
        f0 *= 0.5;
      side = 1;
    }
  }
  return (t0 * f1 - t1 * f0) / (f1 - f0);
}

// Gauss-Legendre points and weights on [0, 1]
void gauss_legendre(int n, std::vector<double>& x, std::vector<double>& w) {
  static const double p[5][5] = {
      {0.0},
      {-0.5773502691896257, 0.5773502691896257},
      {-0.7745966692414834, 0.0, 0.7745966692414834},
      {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526},
      {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640}};
  static const double q[5][5] = {
      {2.0},
      {1.0, 1.0},
      {0.5555555555555556, 0.8888888888888888, 0.5555555555555556},
      {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538},
      {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
       0.2369268850561891}};
  x.resize(n);
  w.resize(n);
  for (int k = 0; k < n; ++k) {
    x[k] = 0.5 * (p[n - 1][k] + 1.0);
    w[k] = 0.5 * q[n - 1][k];
  }
}

/// Segment [p, q] of Gamma_c in grid cell `cell` and its Gauss points (abscissae gx on [0, 1],
/// weights gw), with unit normals grad phi_int / |grad phi_int| (body i -> j) appended to s
void add_segment(const LevelSet& phi, std::int32_t cell, std::array<double, 2> p,
                 std::array<double, 2> q, const std::vector<double>& gx,
                 const std::vector<double>& gw, ContactSurface& s) {
  const double h = phi.grid().min_spacing();
  const double len = std::hypot(q[0] - p[0], q[1] - p[1]);
  const std::int32_t seg = std::int32_t(s.cells.size());
  s.segments.insert(s.segments.end(), {p[0], p[1], q[0], q[1]});
  s.cells.push_back(cell);
  // Unit normal of the segment, for the rare point where grad phi_int vanishes
  const double sn[2] = {-(q[1] - p[1]) / len, (q[0] - p[0]) / len};
  for (std::size_t k = 0; k < gx.size(); ++k) {
    const double x[2] = {p[0] + gx[k] * (q[0] - p[0]), p[1] + gx[k] * (q[1] - p[1])};
    double g[2];
    phi.eval(std::span<const double, 2>(x, 2), std::span<double, 2>(g, 2));
    const double gn = std::hypot(g[0], g[1]);
    double n[2];
    if (gn > 1e-12)
      n[0] = g[0] / gn, n[1] = g[1] / gn;
    else {
      // Orient the segment normal towards increasing phi_int (body i -> body j)
      const double xp[2] = {x[0] + 1e-3 * h * sn[0], x[1] + 1e-3 * h * sn[1]};
      const double xm[2] = {x[0] - 1e-3 * h * sn[0], x[1] - 1e-3 * h * sn[1]};
      const double sgn =
          phi.eval(std::span<const double, 2>(xp, 2)) >= phi.eval(std::span<const double, 2>(xm, 2))
              ? 1.0
              : -1.0;
      n[0] = sgn * sn[0], n[1] = sgn * sn[1];
    }
    s.points.insert(s.points.end(), {x[0], x[1]});
    s.weights.push_back(gw[k] * len);
    s.normals.insert(s.normals.end(), {n[0], n[1]});
    s.tangents.insert(s.tangents.end(), {-n[1], n[0]});
    s.segment.push_back(seg);
  }
}
} // namespace

LevelSet contact::min_levelset(const LevelSet& phi_i, const LevelSet& phi_j) {
  check_same_grid(phi_i, phi_j, "min_levelset");
  return combine(phi_i, phi_j, [](double a, double b) { return std::min(a, b); });
}

LevelSet contact::intermediate_levelset(const LevelSet& phi_i, const LevelSet& phi_j) {
  check_same_grid(phi_i, phi_j, "intermediate_levelset");
  return combine(phi_i, phi_j, [](double a, double b) { return 0.5 * (a - b); });
}

LevelSet contact::closing_levelset(const LevelSet& phi_i, const LevelSet& phi_j, double eps,
                                   double cap) {
  if (!(eps > 0) or !std::isfinite(eps))
    throw std::invalid_argument("contact region: eps must be a finite length > 0");
  check_same_grid(phi_i, phi_j, "closing_levelset");
  // Dilate the union (eq 21) by eps, make it a distance again, erode by eps (eq 22)
  const LevelSet phi_min = min_levelset(phi_i, phi_j);
  std::vector<double> v(phi_min.values().begin(), phi_min.values().end());
  for (double& x : v)
    x -= eps;
  // Without a zero contour in the grid, the dilated union covers all of it (every
  // node is then in the closing) or none of it: a constant of the right sign
  // larger than any distance in the grid says so without a reinitialisation.
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  if (*hi < 0 or *lo > 0) {
    const StructuredGrid& g = phi_i.grid();
    const double diag =
        std::hypot(g.axis(0).back() - g.axis(0).front(), g.axis(1).back() - g.axis(1).front());
    std::fill(v.begin(), v.end(), *hi < 0 ? -diag : diag + eps);
    return LevelSet(phi_i.grid(), std::move(v));
  }
  LevelSet psi = reinitialize(LevelSet(phi_i.grid(), std::move(v)), 8, cap);
  std::vector<double> w(psi.values().begin(), psi.values().end());
  for (double& x : w)
    x += eps;
  return LevelSet(phi_i.grid(), std::move(w));
}

std::vector<std::int8_t> contact::contact_region(const LevelSet& phi_i, const LevelSet& phi_j,
                                                 double eps) {
  const LevelSet psi = closing_levelset(phi_i, phi_j, eps);
  const auto a = phi_i.values(), b = phi_j.values(), c = psi.values();
  std::vector<std::int8_t> flags(a.size());
  for (std::size_t k = 0; k < a.size(); ++k)
    flags[k] = region_indicator(a[k], b[k], c[k]) < 0;
  return flags;
}

ContactSurface contact::contact_surface(const LevelSet& phi_i, const LevelSet& phi_j, double eps,
                                        int num_gauss) {
  if (num_gauss < 1 or num_gauss > 5)
    throw std::invalid_argument("contact_surface: num_gauss must be in 1..5, got " +
                                std::to_string(num_gauss));
  const LevelSet phi = intermediate_levelset(phi_i, phi_j);
  // psi is read through its Hermite interpolant (node values two cells away) on Gamma_int,
  // where only its sign matters but near psi = 0, at depth eps inside the dilated union: the
  // distances swept to eps + 4 cells are the whole sweep's there, and the region the same
  const LevelSet psi = closing_levelset(phi_i, phi_j, eps, eps + 4.0 * phi_i.grid().max_spacing());
  const StructuredGrid& grid = phi.grid();
  const auto& ax = grid.axis(0);
  const auto& ay = grid.axis(1);
  const auto v = phi.values();
  const double h = grid.min_spacing();

  // Region indicator (eq 22) on Gamma_int, where phi_i = phi_j: both at their mean
  auto region = [&](std::array<double, 2> x) {
    std::span<const double, 2> xs(x.data(), 2);
    const double m = 0.5 * (phi_i.eval(xs) + phi_j.eval(xs));
    return region_indicator(m, m, psi.eval(xs));
  };
  auto phi_at = [&](std::array<double, 2> x) {
    return phi.eval(std::span<const double, 2>(x.data(), 2));
  };

  ContactSurface s;
  std::vector<double> gx, gw;
  gauss_legendre(num_gauss, gx, gw);

  for (std::size_t j = 0; j + 1 < ay.size(); ++j)
    for (std::size_t i = 0; i + 1 < ax.size(); ++i) {
      // Corners in tensor order (0,0), (1,0), (0,1), (1,1)
      const std::array<double, 4> f = {v[grid.node(i, j)], v[grid.node(i + 1, j)],
                                       v[grid.node(i, j + 1)], v[grid.node(i + 1, j + 1)]};
      const std::array<std::array<double, 2>, 4> X = {
          {{ax[i], ay[j]}, {ax[i + 1], ay[j]}, {ax[i], ay[j + 1]}, {ax[i + 1], ay[j + 1]}}};
      // Marching squares on the C1 interpolant: edge crossings by bracketed root finding along
      // the edge (from its lower node, so both cells sharing it find bitwise the same point),
      // saddles by the interpolant at the cell centre
      auto edge_root = [&](int e, double fa, double fb) {
        auto fe = [&](double t) { return phi_at(edge_point(X, e, t)); };
        return bracketed_root(fe, fa, fb);
      };
      auto centre = [&]() {
        return phi_at({0.5 * (ax[i] + ax[i + 1]), 0.5 * (ay[j] + ay[j + 1])});
      };
      const CellContour contour = cell_contour(f, edge_root, centre);

      for (int sgm = 0; sgm < contour.num_segments; ++sgm) {
        const auto [ea, eb] = contour.segments[sgm];
        std::array<double, 2> p = edge_point(X, ea, contour.t[ea]);
        std::array<double, 2> q = edge_point(X, eb, contour.t[eb]);
        // Clip to the contact region (eqs 22, 24)
        const double rp = region(p), rq = region(q);
        if (rp >= 0 and rq >= 0)
          continue;
        if ((rp < 0) != (rq < 0)) {
          auto g = [&](double t) {
            return region({p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])});
          };
          const double t = bracketed_root(g, rp, rq);
          const std::array<double, 2> m{p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])};
          (rp < 0 ? q : p) = m;
        }
        const double len = std::hypot(q[0] - p[0], q[1] - p[1]);
        if (len <= 1e-12 * h)
          continue;
        add_segment(phi, grid.cell(i, j), p, q, gx, gw, s);
      }
    }
  return s;
}

ContactSurface contact::segment_quadrature(const LevelSet& phi_int,
                                           std::span<const double> segments,
                                           std::span<const std::int32_t> cells, int num_gauss) {
  if (num_gauss < 1 or num_gauss > 5)
    throw std::invalid_argument("segment_quadrature: num_gauss must be in 1..5, got " +
                                std::to_string(num_gauss));
  if (segments.size() != 4 * cells.size())
    throw std::invalid_argument("segment_quadrature: segments must be (ns, 2, 2) for ns cells");
  std::vector<double> gx, gw;
  gauss_legendre(num_gauss, gx, gw);
  ContactSurface s;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const double* e = segments.data() + 4 * k;
    add_segment(phi_int, cells[k], {e[0], e[1]}, {e[2], e[3]}, gx, gw, s);
  }
  return s;
}
