// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "cut_cell.h"
#include "contour.h"
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace contact::cut {
namespace {

struct TriangleRule {
  int n;
  std::array<double, 6> xi, eta, w; // weights sum to 1 (fraction of the triangle's area)
};

/// Symmetric rules on the reference triangle: centroid (degree 1), Strang-Fix 3 points
/// (degree 2), Dunavant 6 points (degree 4).
const TriangleRule& triangle_rule(int degree) {
  static const TriangleRule r1{1, {1.0 / 3}, {1.0 / 3}, {1.0}};
  static const TriangleRule r2{
      3, {1.0 / 6, 2.0 / 3, 1.0 / 6}, {1.0 / 6, 1.0 / 6, 2.0 / 3}, {1.0 / 3, 1.0 / 3, 1.0 / 3}};
  // Full double precision: the moment-fitted weights rely on this rule being exact to
  // round-off (15-digit constants leave the weights' sum 1e-15 off).
  constexpr double a = 0.44594849091596488632, b = 0.091576213509770743460;
  constexpr double wa = 0.22338158967801146570, wb = 0.10995174365532186764;
  static const TriangleRule r4{6,
                               {a, 1 - 2 * a, a, b, 1 - 2 * b, b},
                               {a, a, 1 - 2 * a, b, b, 1 - 2 * b},
                               {wa, wa, wa, wb, wb, wb}};
  return degree <= 1 ? r1 : (degree == 2 ? r2 : r4);
}

/// Vertices of the reference square in counter-clockwise order (tensor indices 0, 1, 3, 2).
constexpr std::array<int, 4> ccw = {0, 1, 3, 2};
constexpr std::array<std::array<double, 2>, 4> corner = {{{0, 0}, {1, 0}, {0, 1}, {1, 1}}};

/// Triangle area (signed, counter-clockwise positive) of 6 packed coordinates.
double area(const double* t) {
  return 0.5 * ((t[2] - t[0]) * (t[5] - t[1]) - (t[4] - t[0]) * (t[3] - t[1]));
}

/// Facet -> its two vertices (DOLFINx quadrilateral).
constexpr std::array<std::array<int, 2>, 4> facet_vertices = {{{0, 1}, {0, 2}, {1, 3}, {2, 3}}};

struct GaussRule {
  std::array<double, max_fitted_points> x, w; // on [0, 1], weights sum to 1
};

/// Gauss-Legendre rule on [0, 1] with n = 1..max_fitted_points points (Newton on P_n, once).
const GaussRule& gauss_legendre(int n) {
  static const std::array<GaussRule, max_fitted_points> rules = [] {
    std::array<GaussRule, max_fitted_points> r{};
    for (int np = 1; np <= max_fitted_points; ++np)
      for (int i = 0; i < np; ++i) {
        double z = std::cos(std::numbers::pi * (i + 0.75) / (np + 0.5)), dp = 1;
        for (int it = 0; it < 100; ++it) {
          double p = 1, p_prev = 0; // P_np(z) by the three-term recurrence
          for (int j = 1; j <= np; ++j) {
            const double p_next = ((2 * j - 1) * z * p - (j - 1) * p_prev) / j;
            p_prev = p, p = p_next;
          }
          dp = np * (z * p - p_prev) / (z * z - 1);
          const double dz = p / dp;
          z -= dz;
          if (std::abs(dz) < 1e-16)
            break;
        }
        r[np - 1].x[i] = 0.5 * (1 - z);
        r[np - 1].w[i] = 1 / ((1 - z * z) * dp * dp);
      }
    return r;
  }();
  return rules[n - 1];
}

/// Calls f(xi, eta, w) for the points of a rule on the reference triangle exact for total
/// `degree` (weights sum to 1): Dunavant up to degree 4, above it collapsed (Duffy) Gauss,
/// xi = u, eta = v (1 - u), whose Jacobian 1 - u raises the degree in u by one.
template <typename F> void for_each_triangle_point(int degree, F f) {
  if (degree <= 4) {
    const TriangleRule& r = triangle_rule(degree);
    for (int q = 0; q < r.n; ++q)
      f(r.xi[q], r.eta[q], r.w[q]);
    return;
  }
  const int n = (degree + 3) / 2; // exact to 2n - 1 in u, i.e. total degree 2n - 2
  const GaussRule& g = gauss_legendre(n);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      f(g.x[a], g.x[b] * (1 - g.x[a]), 2 * g.w[a] * g.w[b] * (1 - g.x[a]));
}
} // namespace

int clip_square(std::span<const double, 4> phi, std::span<double, 6 * max_triangles> tri) {
  bool in[4];
  int n_in = 0;
  for (int k = 0; k < 4; ++k)
    n_in += (in[k] = phi[k] < 0);
  if (n_in == 0)
    return 0;

  // The zero contour (marching squares, shared with the contact surface Gamma_c)
  const CellContour contour = cell_contour(phi);

  // Walk the boundary counter-clockwise from an inside corner: inside corners and the contour's
  // edge crossings, so poly[0] is a corner. The edge from ccw[k] to ccw[k + 1] is cell edge k.
  int k0 = 0;
  while (not in[ccw[k0]])
    ++k0;
  std::array<double, 16> poly; // at most 8 points
  int np = 0;
  for (int k = k0; k < k0 + 4; ++k) {
    const int a = ccw[k % 4], e = k % 4;
    if (in[a]) {
      poly[2 * np] = corner[a][0], poly[2 * np + 1] = corner[a][1], ++np;
    }
    if (contour.crossed[e]) {
      const std::array<double, 2> x = edge_point(corner, e, contour.t[e]);
      poly[2 * np] = x[0], poly[2 * np + 1] = x[1], ++np;
    }
  }

  int nt = 0;
  auto emit = [&](const double* p, const double* q, const double* r) {
    double* t = tri.data() + 6 * nt;
    t[0] = p[0], t[1] = p[1], t[2] = q[0], t[3] = q[1], t[4] = r[0], t[5] = r[1];
    if (area(t) > 0) // drop the zero-area triangles of crossings at a vertex
      ++nt;
  };
  if (contour.num_segments == 2 and not contour.centre_inside) {
    // Saddle with the centre outside: two separate corner triangles. The walk gave
    // [corner, crossing, crossing, corner, crossing, crossing].
    emit(&poly[0], &poly[2], &poly[10]);
    emit(&poly[6], &poly[8], &poly[4]);
    return nt;
  }
  // Convex polygon (square cut by a line, or the connected saddle hexagon): fan.
  for (int k = 1; k + 1 < np; ++k)
    emit(&poly[0], &poly[2 * k], &poly[2 * k + 2]);
  return nt;
}

void cut_square_rule(std::span<const double, 4> phi, int degree, std::vector<double>& points,
                     std::vector<double>& weights) {
  std::array<double, 6 * max_triangles> tri;
  const int nt = clip_square(phi, tri);
  const TriangleRule& r = triangle_rule(degree);
  for (int k = 0; k < nt; ++k) {
    const double* t = tri.data() + 6 * k;
    const double A = area(t);
    for (int q = 0; q < r.n; ++q) {
      points.push_back(t[0] + r.xi[q] * (t[2] - t[0]) + r.eta[q] * (t[4] - t[0]));
      points.push_back(t[1] + r.xi[q] * (t[3] - t[1]) + r.eta[q] * (t[5] - t[1]));
      weights.push_back(A * r.w[q]);
    }
  }
}

std::array<double, 2> clip_segment(double phi0, double phi1) {
  const bool in0 = phi0 < 0, in1 = phi1 < 0;
  if (in0 and in1)
    return {0.0, 1.0};
  if (not in0 and not in1)
    return {0.0, 0.0};
  const double t = linear_root(phi0, phi1); // the crossing of `cell_contour` on this edge
  return in0 ? std::array<double, 2>{0.0, t} : std::array<double, 2>{t, 1.0};
}

double inside_fraction(std::span<const double, 4> phi) {
  std::array<double, 6 * max_triangles> tri;
  const int nt = clip_square(phi, tri);
  double s = 0;
  for (int k = 0; k < nt; ++k)
    s += area(tri.data() + 6 * k);
  return s;
}

void moment_fitted_weights(std::span<const double, 4> phi, std::span<const double> points,
                           std::span<double> weights) {
  constexpr int mmax = max_fitted_points;
  const std::size_t nq = points.size() / 2;
  if (points.size() % 2 != 0 or nq == 0)
    throw std::invalid_argument("moment_fitted_weights: points must hold nq > 0 (X, Y) pairs");
  if (weights.size() != nq)
    throw std::invalid_argument("moment_fitted_weights: weights must have one entry per point");
  if (nq > std::size_t(mmax * mmax))
    throw std::invalid_argument("moment_fitted_weights: at most 6 x 6 points");

  // Recover the grid lines of each direction and the grid position (i, j) of each point.
  constexpr double tol = 1e-10;
  std::array<std::array<double, mmax>, 2> nodes;
  std::array<int, 2> m = {0, 0};
  std::array<std::array<int, mmax * mmax>, 2> pos;
  for (std::size_t k = 0; k < nq; ++k)
    for (int d = 0; d < 2; ++d) {
      const double x = points[2 * k + d];
      int i = 0;
      while (i < m[d] and std::abs(x - nodes[d][i]) > tol)
        ++i;
      if (i == m[d]) {
        if (m[d] == mmax)
          throw std::invalid_argument(
              "moment_fitted_weights: more than 6 distinct coordinates in a direction");
        nodes[d][m[d]++] = x;
      }
      pos[d][k] = i;
    }
  // nq == mx * my distinct positions: the full grid (pigeonhole)
  if (std::size_t(m[0] * m[1]) != nq)
    throw std::invalid_argument("moment_fitted_weights: points do not form a full tensor grid");
  std::array<bool, mmax * mmax> seen{};
  for (std::size_t k = 0; k < nq; ++k) {
    bool& s = seen[pos[0][k] * m[1] + pos[1][k]];
    if (s)
      throw std::invalid_argument("moment_fitted_weights: points do not form a full tensor grid");
    s = true;
  }

  std::array<std::array<double, mmax>, 2> denom; // Lagrange denominators prod (x_i - x_j)
  for (int d = 0; d < 2; ++d)
    for (int i = 0; i < m[d]; ++i) {
      denom[d][i] = 1;
      for (int j = 0; j < m[d]; ++j)
        if (j != i)
          denom[d][i] *= nodes[d][i] - nodes[d][j];
    }

  // Moments of the tensor Lagrange polynomials l_i(X) l_j(Y) over the inside part; their
  // product has degree (mx - 1) + (my - 1), integrated exactly on each sub-triangle.
  std::array<double, mmax * mmax> M{};
  std::array<double, 6 * max_triangles> tri;
  const int nt = clip_square(phi, tri);
  for (int t = 0; t < nt; ++t) {
    const double* v = tri.data() + 6 * t;
    const double A = area(v);
    for_each_triangle_point(m[0] + m[1] - 2, [&](double xi, double eta, double w) {
      const double x[2] = {v[0] + xi * (v[2] - v[0]) + eta * (v[4] - v[0]),
                           v[1] + xi * (v[3] - v[1]) + eta * (v[5] - v[1])};
      std::array<std::array<double, mmax>, 2> l;
      for (int d = 0; d < 2; ++d)
        for (int i = 0; i < m[d]; ++i) {
          l[d][i] = 1 / denom[d][i];
          for (int j = 0; j < m[d]; ++j)
            if (j != i)
              l[d][i] *= x[d] - nodes[d][j];
        }
      for (int i = 0; i < m[0]; ++i)
        for (int j = 0; j < m[1]; ++j)
          M[i * m[1] + j] += A * w * l[0][i] * l[1][j];
    });
  }
  for (std::size_t k = 0; k < nq; ++k)
    weights[k] = M[pos[0][k] * m[1] + pos[1][k]];
}

void traction_q1(double* A, const double* w, const double*, const double* x,
                 const int* entity_local_index, const std::uint8_t*) {
  const int f = entity_local_index[0];
  const int va = facet_vertices[f][0], vb = facet_vertices[f][1];
  const auto [s0, s1] = clip_segment(w[Layout::phi + va], w[Layout::phi + vb]);
  if (s1 <= s0)
    return;
  const double L = std::hypot(x[3 * vb] - x[3 * va], x[3 * vb + 1] - x[3 * va + 1]);
  const double* t = w + Layout::traction; // Q2 nodes: vertices 0-3, edge midpoints 4 + edge
  const int vm = 4 + f;
  constexpr double g = 0.7745966692414834; // sqrt(3/5): 3-point Gauss, exact to degree 5
  constexpr double gx[3] = {-g, 0.0, g}, gw[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  for (int q = 0; q < 3; ++q) {
    const double s = s0 + 0.5 * (s1 - s0) * (1 + gx[q]);
    const double wq = 0.5 * (s1 - s0) * gw[q] * L;
    const double la = (1 - s) * (1 - 2 * s), lb = s * (2 * s - 1), lm = 4 * s * (1 - s);
    for (int i = 0; i < 2; ++i) {
      const double ti = la * t[2 * va + i] + lb * t[2 * vb + i] + lm * t[2 * vm + i];
      A[2 * va + i] += wq * ti * (1 - s);
      A[2 * vb + i] += wq * ti * s;
    }
  }
}

} // namespace contact::cut
