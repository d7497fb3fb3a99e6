// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "cut_cell.h"
#include <cmath>

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
  constexpr double a = 0.445948490915965, b = 0.091576213509771;
  constexpr double wa = 0.223381589678011, wb = 0.109951743655322;
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

/// Q1 reference gradients at (X, Y), tensor order.
void q1_gradients(double X, double Y, double dX[4], double dY[4]) {
  dX[0] = -(1 - Y), dX[1] = 1 - Y, dX[2] = -Y, dX[3] = Y;
  dY[0] = -(1 - X), dY[1] = -X, dY[2] = 1 - X, dY[3] = X;
}

/// Facet -> its two vertices (DOLFINx quadrilateral).
constexpr std::array<std::array<int, 2>, 4> facet_vertices = {{{0, 1}, {0, 2}, {1, 3}, {2, 3}}};
} // namespace

int clip_square(std::span<const double, 4> phi, std::span<double, 6 * max_triangles> tri) {
  bool in[4];
  int n_in = 0;
  for (int k = 0; k < 4; ++k)
    n_in += (in[k] = phi[k] < 0);
  if (n_in == 0)
    return 0;

  // Walk the boundary counter-clockwise from an inside corner: inside corners and the edge
  // crossings, so poly[0] is a corner.
  int k0 = 0;
  while (not in[ccw[k0]])
    ++k0;
  std::array<double, 16> poly; // at most 8 points
  int np = 0, n_cross = 0;
  for (int k = k0; k < k0 + 4; ++k) {
    const int a = ccw[k % 4], b = ccw[(k + 1) % 4];
    if (in[a]) {
      poly[2 * np] = corner[a][0], poly[2 * np + 1] = corner[a][1], ++np;
    }
    if (in[a] != in[b]) {
      const double t = phi[a] / (phi[a] - phi[b]);
      poly[2 * np] = corner[a][0] + t * (corner[b][0] - corner[a][0]);
      poly[2 * np + 1] = corner[a][1] + t * (corner[b][1] - corner[a][1]);
      ++np, ++n_cross;
    }
  }

  int nt = 0;
  auto emit = [&](const double* p, const double* q, const double* r) {
    double* t = tri.data() + 6 * nt;
    t[0] = p[0], t[1] = p[1], t[2] = q[0], t[3] = q[1], t[4] = r[0], t[5] = r[1];
    if (area(t) > 0) // drop the zero-area triangles of crossings at a vertex
      ++nt;
  };
  const double centre = 0.25 * (phi[0] + phi[1] + phi[2] + phi[3]);
  if (n_cross == 4 and centre >= 0) {
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
  const double t = phi0 / (phi0 - phi1);
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

void elasticity_q1(double* A, const double* w, const double*, const double* x, const int*,
                   const std::uint8_t*) {
  const std::span<const double, 4> phi(w + Layout::phi, 4);
  const double mu = w[Layout::lame], lambda = w[Layout::lame + 1];
  thread_local std::vector<double> pts, wts;
  pts.clear(), wts.clear();
  cut_square_rule(phi, 2, pts, wts); // Q1 stiffness on a parallelogram is quadratic
  for (std::size_t q = 0; q < wts.size(); ++q) {
    double dX[4], dY[4];
    q1_gradients(pts[2 * q], pts[2 * q + 1], dX, dY);
    double J[2][2] = {{0, 0}, {0, 0}};
    for (int n = 0; n < 4; ++n) {
      J[0][0] += x[3 * n] * dX[n], J[0][1] += x[3 * n] * dY[n];
      J[1][0] += x[3 * n + 1] * dX[n], J[1][1] += x[3 * n + 1] * dY[n];
    }
    const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
    double g[4][2]; // physical gradients: J^{-T} (dX, dY)
    for (int n = 0; n < 4; ++n) {
      g[n][0] = (J[1][1] * dX[n] - J[1][0] * dY[n]) / det;
      g[n][1] = (-J[0][1] * dX[n] + J[0][0] * dY[n]) / det;
    }
    const double s = wts[q] * std::abs(det);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) {
        const double dot = g[a][0] * g[b][0] + g[a][1] * g[b][1];
        for (int i = 0; i < 2; ++i)
          for (int k = 0; k < 2; ++k)
            A[(2 * a + i) * 8 + 2 * b + k] +=
                s * (mu * ((i == k) * dot + g[a][k] * g[b][i]) + lambda * g[a][i] * g[b][k]);
      }
  }
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
