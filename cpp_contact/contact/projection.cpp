// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "projection.h"
#include "shapes.h"
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

using namespace contact;

ProjectionResult contact::closest_point_projection(const LevelSet& phi, std::span<const double> x0,
                                                   const ProjectionOptions& opts) {
  if (x0.size() % 2 != 0)
    throw std::invalid_argument("closest_point_projection: points must have shape (n, 2)");
  if (!(opts.rtol > 0) or opts.max_iterations < 1 or !(opts.grad_tol > 0))
    throw std::invalid_argument("closest_point_projection: need rtol > 0, max_iterations >= 1, "
                                "grad_tol > 0");
  const StructuredGrid& grid = phi.grid();
  const std::size_t n = x0.size() / 2;
  for (std::size_t p = 0; p < n; ++p) {
    std::span<const double, 2> x(x0.data() + 2 * p, 2);
    if (!std::isfinite(x[0]) or !std::isfinite(x[1]))
      throw std::invalid_argument("closest_point_projection: point " + std::to_string(p) +
                                  " is not finite");
    if (!grid.contains(x))
      throw std::out_of_range("closest_point_projection: point " + std::to_string(p) + " (" +
                              std::to_string(x[0]) + ", " + std::to_string(x[1]) +
                              ") is outside the grid");
  }

  const double tol = opts.rtol * grid.min_spacing();
  ProjectionResult r;
  r.points.assign(x0.begin(), x0.end());
  r.status.assign(n, ProjectionStatus::max_iterations);
  r.iterations.assign(n, 0);

  for (std::size_t p = 0; p < n; ++p) {
    const double a[2] = {x0[2 * p], x0[2 * p + 1]};
    double x[2] = {a[0], a[1]};
    // Damping of the tangential step d2 when the residual grows (start points far
    // from a curved boundary, where the plain iteration overshoots)
    double alpha = 1.0;
    double prev_res = std::numeric_limits<double>::max();
    int k = 0;
    for (; k < opts.max_iterations; ++k) {
      double g[2], H[3];
      const double f = phi.eval(std::span<const double, 2>(x, 2), std::span<double, 2>(g, 2),
                                std::span<double, 3>(H, 3));
      const double g2 = g[0] * g[0] + g[1] * g[1];
      if (std::sqrt(g2) < opts.grad_tol) {
        r.status[p] = ProjectionStatus::vanishing_gradient;
        break;
      }
      // Eq 25: d1 onto phi = 0 along grad phi; d2 slides in the tangent plane towards x0
      const double d1[2] = {-f * g[0] / g2, -f * g[1] / g2};
      const double rr[2] = {a[0] - x[0], a[1] - x[1]};
      const double lam = (rr[0] * g[0] + rr[1] * g[1]) / g2; // least-squares multiplier
      const double d2[2] = {rr[0] - lam * g[0], rr[1] - lam * g[1]};
      // d1 and d2 are orthogonal: |d1| = |phi|/|grad phi| is the distance residual and
      // |d2| the residual of the optimality condition (x0 - x) || grad phi
      const double res = std::sqrt(d1[0] * d1[0] + d1[1] * d1[1] + d2[0] * d2[0] + d2[1] * d2[1]);
      if (res > prev_res and alpha > 1e-3)
        alpha *= 0.5;
      prev_res = res;
      double step[2] = {d1[0] + alpha * d2[0], d1[1] + alpha * d2[1]};

      // Newton on the optimality system x - x0 - m grad phi = 0, phi = 0 (m = -lam):
      //   M dx - g dm = d2, g.dx = -f, M = I + lam H.
      // The plain iteration (eq 25) contracts the tangential error only by
      // kappa * dist per step (and stalls near the evolute); Newton is quadratic.
      // Taken when M is well conditioned and the step is not much longer than eq 25's.
      const double M[3] = {1.0 + lam * H[0], lam * H[1], 1.0 + lam * H[2]};
      const double det = M[0] * M[2] - M[1] * M[1];
      if (std::abs(det) > 1e-6) {
        auto solve = [&](const double* rhs, double* y) {
          y[0] = (M[2] * rhs[0] - M[1] * rhs[1]) / det;
          y[1] = (M[0] * rhs[1] - M[1] * rhs[0]) / det;
        };
        double Mg[2], Md2[2];
        solve(g, Mg);
        solve(d2, Md2);
        const double gMg = g[0] * Mg[0] + g[1] * Mg[1];
        if (std::abs(gMg) > 1e-12 * g2) {
          // dx = M^-1 (d2 + g dl) with g.dx = -f
          const double dl = -(f + g[0] * Md2[0] + g[1] * Md2[1]) / gMg;
          const double dn[2] = {Md2[0] + dl * Mg[0], Md2[1] + dl * Mg[1]};
          if (std::hypot(dn[0], dn[1]) <= 2.0 * std::hypot(d1[0] + d2[0], d1[1] + d2[1]))
            step[0] = dn[0], step[1] = dn[1];
        }
      }

      const double xn[2] = {x[0] + step[0], x[1] + step[1]};
      const bool inside = grid.contains(std::span<const double, 2>(xn, 2));
      if (inside) {
        x[0] = xn[0];
        x[1] = xn[1];
      }
      if (res < tol) {
        // A last update that would leave the grid (by round-off at its edge) is dropped
        r.status[p] = ProjectionStatus::converged;
        ++k;
        break;
      }
      if (!inside) {
        r.status[p] = ProjectionStatus::left_grid;
        break;
      }
    }
    r.points[2 * p] = x[0];
    r.points[2 * p + 1] = x[1];
    r.iterations[p] = k;
  }
  return r;
}

//-----------------------------------------------------------------------------
contact::ProjectionResult contact::closest_point_projection(const Shape& shape,
                                                            std::span<const double> x0,
                                                            double length_scale,
                                                            const ProjectionOptions& opts) {
  if (x0.size() % 2 != 0)
    throw std::invalid_argument("closest_point_projection: points must have shape (n, 2)");
  if (!(length_scale > 0) or !std::isfinite(length_scale))
    throw std::invalid_argument("closest_point_projection: length_scale must be finite and > 0");
  const std::size_t n = x0.size() / 2;
  const double tol = opts.rtol * length_scale, step = 1e-7 * length_scale;
  ProjectionResult r;
  r.points.assign(x0.begin(), x0.end());
  r.status.assign(n, ProjectionStatus::max_iterations);
  r.iterations.assign(n, 0);
  for (std::size_t p = 0; p < n; ++p) {
    std::array<double, 2> x{x0[2 * p], x0[2 * p + 1]};
    if (!std::isfinite(x[0]) or !std::isfinite(x[1])) {
      throw std::invalid_argument("closest_point_projection: point " + std::to_string(p) +
                                  " is not finite");
    }
    for (int k = 0; k <= opts.max_iterations; ++k) {
      const double d = shape(x);
      if (std::abs(d) <= tol) {
        r.status[p] = ProjectionStatus::converged;
        break;
      }
      if (k == opts.max_iterations)
        break;
      const double gx = (shape({x[0] + step, x[1]}) - shape({x[0] - step, x[1]})) / (2 * step);
      const double gy = (shape({x[0], x[1] + step}) - shape({x[0], x[1] - step})) / (2 * step);
      const double g2 = gx * gx + gy * gy;
      if (g2 < opts.grad_tol * opts.grad_tol) {
        r.status[p] = ProjectionStatus::vanishing_gradient;
        break;
      }
      x = {x[0] - d * gx / g2, x[1] - d * gy / g2};
      r.iterations[p] = k + 1;
    }
    r.points[2 * p] = x[0];
    r.points[2 * p + 1] = x[1];
  }
  return r;
}
