// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// One function per equation: the marching squares shared by Gamma_c (eq 24) and the cut-cell
// clipping (`cell_contour`), the contact-region indicator (eq 22) behind both the node flags and
// the clipping of Gamma_c, phi_min (eq 21) inside the closing level set, and the point gaps
// (eqs 26-30) that both `compute_gaps` and the contact kernel (eq 48) evaluate.
#include <algorithm>
#include <cmath>
#include <contact/contact_kernel.h>
#include <contact/contact_surface.h>
#include <contact/contour.h>
#include <contact/cut_cell.h>
#include <contact/gaps.h>
#include <contact/reinit.h>
#include <contact/shapes.h>
#include <gtest/gtest.h>
#include <random>

using namespace contact;

namespace {
constexpr std::array<std::array<double, 2>, 4> unit_square = {{{0, 0}, {1, 0}, {0, 1}, {1, 1}}};
}

TEST(CellContour, StraightCutOneSegmentLinearCrossings) {
  // phi = X - 0.3 + 0.2 Y: crosses the bottom (e0) and the top (e2)
  const std::array<double, 4> phi = {-0.3, 0.7, -0.1, 0.9};
  const CellContour c = cell_contour(phi);
  EXPECT_EQ(c.num_segments, 1);
  EXPECT_TRUE(c.crossed[0] and c.crossed[2] and not c.crossed[1] and not c.crossed[3]);
  EXPECT_EQ(c.segments[0][0], 0);
  EXPECT_EQ(c.segments[0][1], 2);
  EXPECT_DOUBLE_EQ(c.t[0], 0.3);
  EXPECT_DOUBLE_EQ(c.t[2], 0.1);
  // all inside, all outside, and a zero vertex (outside): no contour
  EXPECT_EQ(cell_contour(std::array<double, 4>{-1, -1, -1, -1}).num_segments, 0);
  EXPECT_EQ(cell_contour(std::array<double, 4>{1, 2, 3, 4}).num_segments, 0);
  EXPECT_EQ(cell_contour(std::array<double, 4>{0, 1, 1, 1}).num_segments, 0);
  // a zero vertex next to an inside one: the crossing is that vertex (t = 1 on e0)
  const CellContour z = cell_contour(std::array<double, 4>{-1, 0, -1, 0});
  EXPECT_EQ(z.num_segments, 1);
  EXPECT_EQ(z.t[0], 1.0);
  EXPECT_EQ(z.t[2], 1.0);
}

TEST(CellContour, SaddlesByTheCentreValueOnlyWhenNeeded) {
  const std::array<double, 4> phi = {0.25, -0.25, -0.25, 0.25}; // v1, v2 inside
  int calls = 0;
  auto root = [](int, double fa, double fb) { return linear_root(fa, fb); };
  // centre on the side of v0 (outside): v0 and v3 connected, v1 and v2 cut off
  const CellContour a = cell_contour(phi, root, [&] { return ++calls, 0.1; });
  EXPECT_EQ(a.num_segments, 2);
  EXPECT_FALSE(a.centre_inside);
  EXPECT_EQ(a.segments[0], (std::array<int, 2>{0, 1}));
  EXPECT_EQ(a.segments[1], (std::array<int, 2>{3, 2}));
  // centre inside: v1 and v2 connected, v0 and v3 cut off
  const CellContour b = cell_contour(phi, root, [&] { return ++calls, -0.1; });
  EXPECT_TRUE(b.centre_inside);
  EXPECT_EQ(b.segments[0], (std::array<int, 2>{3, 0}));
  EXPECT_EQ(b.segments[1], (std::array<int, 2>{1, 2}));
  EXPECT_EQ(calls, 2);
  // no saddle: the centre is never asked for, the edge root once per crossed edge
  int roots = 0;
  cell_contour(
      std::array<double, 4>{-1, 1, -1, 1},
      [&](int, double fa, double fb) { return ++roots, linear_root(fa, fb); },
      [&] { return ++calls, 0.0; });
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(roots, 2);
}

TEST(CellContour, NeighboursShareEdgeCrossingsBitwise) {
  // Two cells side by side on a row of a grid: the right edge of one is the left edge of the
  // other, both computed from the lower vertex
  std::mt19937 gen(5);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int k = 0; k < 1000; ++k) {
    const double v[6] = {U(gen), U(gen), U(gen), U(gen), U(gen), U(gen)}; // 3 x 2 nodes
    const CellContour l = cell_contour(std::array<double, 4>{v[0], v[1], v[3], v[4]});
    const CellContour r = cell_contour(std::array<double, 4>{v[1], v[2], v[4], v[5]});
    ASSERT_EQ(l.crossed[1], r.crossed[3]);
    if (l.crossed[1]) {
      EXPECT_EQ(l.t[1], r.t[3]);
    }
  }
}

TEST(CellContour, CutCellClippingUsesTheContour) {
  // Every vertex of the clipped triangles is a corner of the square or a crossing of
  // cell_contour, bitwise; and the inside area agrees with the contour's polygon (shoelace)
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> U(-1, 1);
  int saddles = 0;
  for (int k = 0; k < 2000; ++k) {
    std::array<double, 4> phi = {U(gen), U(gen), U(gen), U(gen)};
    if (k % 4 == 0) // many saddles
      phi = {std::abs(phi[0]), -std::abs(phi[1]), -std::abs(phi[2]), std::abs(phi[3])};
    const CellContour c = cell_contour(phi);
    saddles += c.num_segments == 2;
    std::vector<std::array<double, 2>> allowed(unit_square.begin(), unit_square.end());
    for (int e = 0; e < 4; ++e)
      if (c.crossed[e])
        allowed.push_back(edge_point(unit_square, e, c.t[e]));
    std::array<double, 6 * cut::max_triangles> tri;
    const int nt = cut::clip_square(phi, tri);
    for (int v = 0; v < 3 * nt; ++v) {
      const std::array<double, 2> x = {tri[2 * v], tri[2 * v + 1]};
      EXPECT_NE(std::find(allowed.begin(), allowed.end(), x), allowed.end())
          << "cell " << k << " vertex (" << x[0] << ", " << x[1] << ")";
    }
  }
  EXPECT_GT(saddles, 200);
}

TEST(ContactRegion, MinLevelsetIsTheNodewiseMinimumOfEq21) {
  // phi_min = min(phi_i, phi_j) at every node, exactly; grids that differ are refused
  const StructuredGrid g = StructuredGrid::uniform({-2, -1}, {2, 1}, {40, 20});
  const LevelSet a = levelset_from_shape(g, Circle({-0.55, 0}, 0.5));
  const LevelSet b = levelset_from_shape(g, Circle({0.55, 0}, 0.5));
  const LevelSet m = min_levelset(a, b);
  ASSERT_EQ(m.values().size(), a.values().size());
  for (std::size_t k = 0; k < m.values().size(); ++k)
    EXPECT_EQ(m.values()[k], std::min(a.values()[k], b.values()[k])) << k;
  const StructuredGrid other = StructuredGrid::uniform({-2, -1}, {2, 1}, {41, 20});
  EXPECT_THROW(min_levelset(a, levelset_from_shape(other, Circle({0, 0}, 0.5))),
               std::invalid_argument);
}

TEST(ContactRegion, IndicatorIsTheSetOfEq22) {
  // r < 0 exactly on {phi_i >= 0, phi_j >= 0, psi < 0} U {phi_i < 0, phi_j < 0}
  const double v[5] = {-1.0, -1e-300, 0.0, 1e-300, 2.0};
  for (double a : v)
    for (double b : v)
      for (double c : v) {
        const bool in = (a >= 0 and b >= 0 and c < 0) or (a < 0 and b < 0);
        EXPECT_EQ(region_indicator(a, b, c) < 0, in) << a << " " << b << " " << c;
      }
}

TEST(ContactRegion, NodeFlagsAndGammaCUseTheIndicator) {
  const StructuredGrid g = StructuredGrid::uniform({-2, -1}, {2, 1}, {80, 40});
  const LevelSet a = levelset_from_shape(g, Circle({-0.55, 0}, 0.5));
  const LevelSet b = levelset_from_shape(g, Circle({0.55, 0}, 0.5)); // gap 0.1
  const double eps = 0.15;
  // phi_min (eq 21) is the one inside the closing level set (eq 22)
  const LevelSet m = min_levelset(a, b);
  std::vector<double> shifted(m.values().begin(), m.values().end());
  for (double& x : shifted)
    x -= eps;
  const LevelSet r = reinitialize(LevelSet(g, shifted));
  const LevelSet psi = closing_levelset(a, b, eps);
  for (std::size_t k = 0; k < g.num_nodes(); ++k)
    ASSERT_EQ(psi.values()[k], r.values()[k] + eps);
  // node flags
  const std::vector<std::int8_t> flags = contact_region(a, b, eps);
  int n_in = 0;
  for (std::size_t k = 0; k < g.num_nodes(); ++k) {
    EXPECT_EQ(flags[k], region_indicator(a.values()[k], b.values()[k], psi.values()[k]) < 0);
    n_in += flags[k];
  }
  EXPECT_GT(n_in, 10);
  // Gamma_c: every segment end is in the closed region (clipped where the indicator is 0)
  const ContactSurface s = contact_surface(a, b, eps);
  ASSERT_GT(s.cells.size(), 4u);
  for (std::size_t p = 0; p < s.segments.size() / 2; ++p) {
    const std::span<const double, 2> x(s.segments.data() + 2 * p, 2);
    const double mean = 0.5 * (a.eval(x) + b.eval(x));
    EXPECT_LE(region_indicator(mean, mean, psi.eval(x)), 1e-12);
  }
}

TEST(ContactRegion, TouchingBodiesKeepTheirContactLine) {
  // Two blocks touching along y = y0 (phi_i = phi_j = 0 on Gamma_int): the whole line is in
  // the region, on a grid line as well as between grid lines
  for (double y0 : {0.0, 0.013}) {
    const StructuredGrid g = StructuredGrid::uniform({-0.5, -0.5}, {0.5, 0.5}, {40, 40});
    const LevelSet a = levelset_from_shape(g, Box({-1, -1}, {1, y0}));
    const LevelSet b = levelset_from_shape(g, Box({-1, y0}, {1, 1}));
    const ContactSurface s = contact_surface(a, b, 0.05);
    double length = 0;
    for (double w : s.weights)
      length += w;
    EXPECT_NEAR(length, 1.0, 1e-12) << "y0 = " << y0;
    for (std::size_t p = 0; p < s.points.size() / 2; ++p)
      EXPECT_NEAR(s.points[2 * p + 1], y0, 1e-12);
  }
}

TEST(ContactSurface, SegmentQuadratureIsTheSurfacesOwnAndSplitsExactly) {
  // segment_quadrature on contact_surface's segments gives its points, weights and normals;
  // each segment split in three integrates x^3 along the flat Gamma_c as exactly
  const StructuredGrid g = StructuredGrid::uniform({-0.5, -0.5}, {0.5, 0.5}, {20, 20});
  const LevelSet a = levelset_from_shape(g, Box({-1, -1}, {1, 0.013}));
  const LevelSet b = levelset_from_shape(g, Box({-1, 0.013}, {1, 1}));
  const ContactSurface s = contact_surface(a, b, 0.05, 2);
  const LevelSet phi = intermediate_levelset(a, b);
  const ContactSurface q = segment_quadrature(phi, s.segments, s.cells, 2);
  EXPECT_EQ(q.points, s.points);
  EXPECT_EQ(q.weights, s.weights);
  EXPECT_EQ(q.normals, s.normals);
  std::vector<double> thirds;
  std::vector<std::int32_t> cells;
  for (std::size_t k = 0; k < s.cells.size(); ++k) {
    const double* e = s.segments.data() + 4 * k;
    for (int i = 0; i < 3; ++i)
      for (double t : {i / 3.0, (i + 1) / 3.0})
        thirds.insert(thirds.end(), {e[0] + t * (e[2] - e[0]), e[1] + t * (e[3] - e[1])});
    cells.insert(cells.end(), 3, s.cells[k]);
  }
  const ContactSurface r = segment_quadrature(phi, thirds, cells, 2);
  ASSERT_EQ(r.weights.size(), 3 * s.weights.size());
  auto cubic = [](const ContactSurface& c) {
    double sum = 0;
    for (std::size_t p = 0; p < c.weights.size(); ++p)
      sum += c.weights[p] * std::pow(c.points[2 * p], 3);
    return sum;
  };
  EXPECT_NEAR(cubic(r), cubic(s), 1e-14);
  for (std::size_t p = 0; p < r.weights.size(); ++p)
    EXPECT_NEAR(r.normals[2 * p + 1], 1.0, 1e-12); // body i (below) -> j
  EXPECT_THROW(segment_quadrature(phi, s.segments, s.cells, 6), std::invalid_argument);
  EXPECT_THROW(segment_quadrature(phi, thirds, s.cells, 2), std::invalid_argument);
}

TEST(Gaps, PointGapsOwnEqs26To30) {
  const double p_i[2] = {1.0, 2.0}, p_j[2] = {1.25, 2.5}, n[2] = {0.0, 1.0}, t[2] = {-1.0, 0.0};
  const double g0 = initial_normal_gap(p_i, p_j, n);
  EXPECT_EQ(g0, 0.5);
  const double du[2] = {0.5, -0.75};
  const PointGaps g = point_gaps(g0, du, n, t);
  EXPECT_EQ(g.j_int, -0.75);
  EXPECT_EQ(g.g_n, -0.25);
  EXPECT_EQ(g.g_t, -0.5);
}

TEST(Gaps, KernelGapsAreThePointGapsOfTheInterpolatedJump) {
  // The kernel's g_n, g_t equal compute_gaps with u_i = sum N_i u, u_j = sum N_j u
  std::mt19937 gen(11);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  ContactQuadrature q;
  q.nodes_i = q.nodes_j = 2;
  const std::size_t nq = 30;
  std::vector<double> u(8);
  for (double& x : u)
    x = 0.02 * (U(gen) - 0.5);
  std::vector<double> pi(2 * nq, 0.0), pj(2 * nq, 0.0), ui(2 * nq), uj(2 * nq);
  for (std::size_t p = 0; p < nq; ++p) {
    const double th = 6.283185307179586 * U(gen), s = U(gen);
    q.weights.push_back(1.0);
    q.normals.insert(q.normals.end(), {std::cos(th), std::sin(th)});
    q.tangents.insert(q.tangents.end(), {-std::sin(th), std::cos(th)});
    q.dofs_i.insert(q.dofs_i.end(), {0, 1});
    q.dofs_j.insert(q.dofs_j.end(), {2, 3});
    q.basis_i.insert(q.basis_i.end(), {s, 1 - s});
    q.basis_j.insert(q.basis_j.end(), {1 - s, s});
    pj[2 * p] = 0.01 * (U(gen) - 0.5) * std::cos(th); // g_n0 from the closest points
    pj[2 * p + 1] = 0.01 * (U(gen) - 0.5) * std::sin(th);
    for (int c = 0; c < 2; ++c) {
      ui[2 * p + c] = s * u[c] + (1 - s) * u[2 + c];
      uj[2 * p + c] = (1 - s) * u[4 + c] + s * u[6 + c];
    }
  }
  std::vector<double> g_n0(nq), j_int(nq), g_n(nq), g_t(nq);
  compute_gaps(pi, pj, std::vector<double>(2 * nq, 0.0), std::vector<double>(2 * nq, 0.0),
               q.normals, q.tangents, g_n0, j_int, g_n, g_t);
  q.g_n0 = g_n0;
  compute_gaps(pi, pj, ui, uj, q.normals, q.tangents, g_n0, j_int, g_n, g_t);
  const ContactPointState s =
      assemble_contact(q, {1e-3, 1e-3, 0.3}, u, std::vector<double>(nq), {}, BlockInserter{});
  for (std::size_t p = 0; p < nq; ++p) {
    EXPECT_NEAR(s.g_n[p], g_n[p], 1e-15);
    EXPECT_NEAR(s.g_t[p], g_t[p], 1e-15);
  }
}
