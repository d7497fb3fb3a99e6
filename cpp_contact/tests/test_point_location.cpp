// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Point location on unstructured triangle and (distorted, convex) quadrilateral meshes,
// checked against brute force over all cells with an independent distance and forward map.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <contact/point_location.h>
#include <gtest/gtest.h>
#include <limits>
#include <numeric>
#include <random>

using namespace contact;

namespace {
using P = std::array<double, 2>;

/// P1 mesh as DOLFINx stores it
struct Mesh {
  std::vector<double> x;
  int gdim;
  std::vector<std::int32_t> cells;
  int nverts;
  std::int32_t num_cells() const { return std::int32_t(cells.size()) / nverts; }
  P vertex(std::int32_t c, int i) const {
    const auto v = std::size_t(cells[std::size_t(c * nverts + i)]);
    return {x[v * std::size_t(gdim)], x[v * std::size_t(gdim) + 1]};
  }
  std::vector<std::int32_t> all() const {
    std::vector<std::int32_t> s(static_cast<std::size_t>(num_cells()));
    std::iota(s.begin(), s.end(), 0);
    return s;
  }
};

/// n x n mesh of [0,1]^2; interior vertices moved by up to distortion * h along each axis
/// (quads stay convex for distortion < 0.25). Triangles of both orientations; quads in
/// DOLFINx tensor order; cells numbered in a random order as DOLFINx reorders them.
Mesh unit_square(int n, int nverts, double distortion, int gdim = 2, unsigned seed = 1) {
  Mesh m{{}, gdim, {}, nverts};
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> U(-distortion, distortion);
  const double h = 1.0 / n;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const bool interior = i > 0 and i < n and j > 0 and j < n;
      m.x.push_back(i * h + (interior ? U(gen) * h : 0.0));
      m.x.push_back(j * h + (interior ? U(gen) * h : 0.0));
      if (gdim == 3)
        m.x.push_back(0.25); // ignored
    }
  std::vector<std::array<std::int32_t, 4>> cells;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const std::int32_t v0 = i + (n + 1) * j, v1 = v0 + 1, v2 = v0 + n + 1, v3 = v2 + 1;
      if (nverts == 4)
        cells.push_back({v0, v1, v2, v3});
      else {
        cells.push_back({v0, v1, v3, 0}); // counter-clockwise
        cells.push_back({v0, v2, v3, 0}); // clockwise
      }
    }
  std::shuffle(cells.begin(), cells.end(), gen);
  for (auto& c : cells)
    m.cells.insert(m.cells.end(), c.begin(), c.begin() + nverts);
  return m;
}

CellLocator make_locator(const Mesh& m, const std::vector<std::int32_t>& subset) {
  return CellLocator(m.x, m.gdim, m.cells, m.nverts, subset);
}

double cross(P a, P b, P c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

double segment_distance(P p, P a, P b) {
  const double e[2] = {b[0] - a[0], b[1] - a[1]};
  const double t = std::clamp(
      ((p[0] - a[0]) * e[0] + (p[1] - a[1]) * e[1]) / (e[0] * e[0] + e[1] * e[1]), 0.0, 1.0);
  return std::hypot(p[0] - a[0] - t * e[0], p[1] - a[1] - t * e[1]);
}

// Barycentric containment (either orientation), with a round-off tolerance
bool in_triangle(P p, P a, P b, P c) {
  const double det = cross(a, b, c);
  const double l1 = cross(a, p, c) / det, l2 = cross(a, b, p) / det;
  return l1 >= -1e-14 and l2 >= -1e-14 and l1 + l2 <= 1 + 1e-14;
}

/// Distance from p to cell c, independent of the locator: a quad is split in two triangles
double brute_distance(const Mesh& m, std::int32_t c, P p) {
  std::vector<P> v;
  for (int i = 0; i < m.nverts; ++i)
    v.push_back(m.vertex(c, i));
  if (m.nverts == 3) {
    if (in_triangle(p, v[0], v[1], v[2]))
      return 0;
    return std::min({segment_distance(p, v[0], v[1]), segment_distance(p, v[1], v[2]),
                     segment_distance(p, v[2], v[0])});
  }
  if (in_triangle(p, v[0], v[1], v[3]) or in_triangle(p, v[0], v[3], v[2]))
    return 0;
  return std::min({segment_distance(p, v[0], v[1]), segment_distance(p, v[1], v[3]),
                   segment_distance(p, v[3], v[2]), segment_distance(p, v[2], v[0])});
}

/// Forward map of cell c through the P1 basis functions
P forward(const Mesh& m, std::int32_t c, P X) {
  std::vector<double> phi;
  if (m.nverts == 3)
    phi = {1 - X[0] - X[1], X[0], X[1]};
  else
    phi = {(1 - X[0]) * (1 - X[1]), X[0] * (1 - X[1]), (1 - X[0]) * X[1], X[0] * X[1]};
  P x = {0, 0};
  for (int i = 0; i < m.nverts; ++i)
    for (int d = 0; d < 2; ++d)
      x[d] += phi[std::size_t(i)] * m.vertex(c, i)[d];
  return x;
}

bool in_reference(int nverts, P X, double tol) {
  if (nverts == 3)
    return X[0] >= -tol and X[1] >= -tol and X[0] + X[1] <= 1 + tol;
  return X[0] >= -tol and X[1] >= -tol and X[0] <= 1 + tol and X[1] <= 1 + tol;
}

struct Brute {
  double dmin = std::numeric_limits<double>::infinity();
  std::int32_t lowest_containing = -1; // lowest index with distance 0 (round-off aside)
};
Brute brute_force(const Mesh& m, const std::vector<std::int32_t>& subset, P p) {
  Brute b;
  for (std::int32_t c : subset) {
    const double d = brute_distance(m, c, p);
    b.dmin = std::min(b.dmin, d);
    if (d == 0 and (b.lowest_containing < 0 or c < b.lowest_containing))
      b.lowest_containing = c;
  }
  return b;
}

/// Check one located point against brute force over `subset`
void check_point(const Mesh& m, const std::vector<std::int32_t>& subset, const LocatedPoints& r,
                 std::size_t p, P pt, double max_distance) {
  const Brute b = brute_force(m, subset, pt);
  const std::int32_t c = r.cells[p];
  const P X = {r.X[2 * p], r.X[2 * p + 1]};
  SCOPED_TRACE("point " + std::to_string(p) + " (" + std::to_string(pt[0]) + ", " +
               std::to_string(pt[1]) + ")");
  if (b.dmin > max_distance + 1e-13) {
    EXPECT_EQ(c, -1);
    EXPECT_TRUE(std::isnan(X[0]) and std::isnan(X[1]));
    EXPECT_EQ(r.outside[p], std::numeric_limits<double>::infinity());
    return;
  }
  if (b.dmin > max_distance - 1e-13)
    return; // at the search radius up to round-off: either answer is right
  ASSERT_GE(c, 0);
  EXPECT_TRUE(std::binary_search(subset.begin(), subset.end(), c)) << "cell not in subset";
  const P y = forward(m, c, X);
  EXPECT_NEAR(y[0], pt[0], 1e-12);
  EXPECT_NEAR(y[1], pt[1], 1e-12);
  if (b.dmin == 0) {
    EXPECT_EQ(r.outside[p], 0.0);
    EXPECT_TRUE(in_reference(m.nverts, X, 1e-12));
    EXPECT_LE(brute_distance(m, c, pt), 1e-13) << "found cell does not contain the point";
    EXPECT_LE(c, b.lowest_containing) << "not the lowest-index containing cell";
  } else {
    EXPECT_NEAR(r.outside[p], b.dmin, 1e-14) << "not the distance to the nearest cell";
    EXPECT_NEAR(brute_distance(m, c, pt), b.dmin, 1e-14) << "not the nearest cell";
    EXPECT_GT(r.outside[p], 0.0);
    EXPECT_FALSE(in_reference(m.nverts, X, 1e-12)) << "X should be extrapolated";
  }
}
} // namespace

TEST(PointLocation, InsidePointsMatchBruteForce) {
  for (int nverts : {3, 4})
    for (int gdim : {2, 3}) {
      SCOPED_TRACE("nverts " + std::to_string(nverts) + " gdim " + std::to_string(gdim));
      const Mesh m = unit_square(12, nverts, 0.2, gdim, unsigned(nverts + gdim));
      const auto subset = m.all();
      const CellLocator loc = make_locator(m, subset);
      EXPECT_EQ(loc.num_cells(), subset.size());
      std::mt19937 gen(7);
      std::uniform_real_distribution<double> U(0, 1);
      std::vector<double> pts;
      for (int k = 0; k < 2000; ++k)
        pts.push_back(U(gen));
      // Vertices (shared by up to 6 cells) and edge midpoints (shared by 2): tie-breaking
      for (std::size_t v = 0; v < m.x.size(); v += std::size_t(gdim))
        pts.insert(pts.end(), {m.x[v], m.x[v + 1]});
      for (std::int32_t c = 0; c < m.num_cells(); ++c) {
        const P a = m.vertex(c, 0), b = m.vertex(c, 1);
        pts.insert(pts.end(), {0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])});
      }
      const LocatedPoints r = loc.locate(pts, 0.0);
      for (std::size_t p = 0; p < pts.size() / 2; ++p) {
        check_point(m, subset, r, p, {pts[2 * p], pts[2 * p + 1]}, 0.0);
        EXPECT_EQ(r.outside[p], 0.0);
      }
    }
}

TEST(PointLocation, PointsJustOutsideGetNearestCellAndExactDistance) {
  for (int nverts : {3, 4}) {
    SCOPED_TRACE("nverts " + std::to_string(nverts));
    // The boundary vertices are not moved: the domain is exactly [0,1]^2
    const Mesh m = unit_square(10, nverts, 0.2);
    const auto subset = m.all();
    const CellLocator loc = make_locator(m, subset);
    std::mt19937 gen(3);
    std::uniform_real_distribution<double> U(0.001, 0.999), D(1e-9, 1e-2);
    std::vector<double> pts, exact;
    for (int k = 0; k < 200; ++k) {
      const double t = U(gen), d = D(gen);
      pts.insert(pts.end(), {t, -d, t, 1 + d, -d, t, 1 + d, t});
      exact.insert(exact.end(), {d, d, d, d});
    }
    pts.insert(pts.end(), {-3e-3, -4e-3, 1 + 3e-3, 1 + 4e-3, 1 + 1e-10, 0.5}); // corners, ~edge
    exact.insert(exact.end(), {5e-3, 5e-3, 1e-10});
    const double max_distance = 0.02;
    const LocatedPoints r = loc.locate(pts, max_distance);
    for (std::size_t p = 0; p < exact.size(); ++p) {
      check_point(m, subset, r, p, {pts[2 * p], pts[2 * p + 1]}, max_distance);
      EXPECT_NEAR(r.outside[p], exact[p], 1e-15 + 1e-12 * exact[p]);
    }
  }
}

TEST(PointLocation, RandomPointsAroundTheMeshMatchBruteForce) {
  // Quads: a search radius of about half a cell (the bilinear map of a distorted quad folds
  // ~2 cells away, beyond which points have no pull-back: QuadPullBackBeyondTheFoldThrows)
  for (int nverts : {3, 4})
    for (double max_distance : {0.0, 0.03, nverts == 3 ? 0.3 : 0.05}) {
      SCOPED_TRACE("nverts " + std::to_string(nverts) + " max_distance " +
                   std::to_string(max_distance));
      const Mesh m = unit_square(9, nverts, 0.2);
      const auto subset = m.all();
      const CellLocator loc = make_locator(m, subset);
      std::mt19937 gen(5);
      std::uniform_real_distribution<double> U(-0.4, 1.4);
      std::vector<double> pts;
      for (int k = 0; k < 3000; ++k)
        pts.push_back(U(gen));
      const LocatedPoints r = loc.locate(pts, max_distance);
      for (std::size_t p = 0; p < pts.size() / 2; ++p)
        check_point(m, subset, r, p, {pts[2 * p], pts[2 * p + 1]}, max_distance);
    }
}

TEST(PointLocation, FarPointsAreNotLocated) {
  for (int nverts : {3, 4}) {
    const Mesh m = unit_square(8, nverts, nverts == 3 ? 0.2 : 0.0);
    const CellLocator loc = make_locator(m, m.all());
    const std::vector<double> pts = {5, 5, 0.5, -0.2, -1e3, 0.5, 0.5, 1.05};
    const LocatedPoints r = loc.locate(pts, 0.1);
    for (std::size_t p = 0; p < 3; ++p) {
      EXPECT_EQ(r.cells[p], -1);
      EXPECT_TRUE(std::isnan(r.X[2 * p]) and std::isnan(r.X[2 * p + 1]));
      EXPECT_EQ(r.outside[p], std::numeric_limits<double>::infinity());
    }
    EXPECT_GE(r.cells[3], 0);
    EXPECT_NEAR(r.outside[3], 0.05, 1e-15);
    // An unbounded search radius finds the nearest cell of any point (affine cells here)
    const LocatedPoints ri = loc.locate(pts, std::numeric_limits<double>::infinity());
    EXPECT_NEAR(ri.outside[0], std::hypot(4, 4), 1e-12);
    EXPECT_NEAR(ri.outside[1], 0.2, 1e-15);
    EXPECT_NEAR(ri.outside[2], 1e3, 1e-12);
    for (std::size_t p = 0; p < 4; ++p) {
      const P y = forward(m, ri.cells[p], {ri.X[2 * p], ri.X[2 * p + 1]});
      EXPECT_NEAR(y[0], pts[2 * p], 1e-9);
      EXPECT_NEAR(y[1], pts[2 * p + 1], 1e-9);
    }
  }
}

TEST(PointLocation, SubsetIsRespected) {
  for (int nverts : {3, 4}) {
    SCOPED_TRACE("nverts " + std::to_string(nverts));
    const Mesh m = unit_square(10, nverts, 0.2);
    // One "body": the cells whose centroid is left of x = 0.5, given with duplicates
    std::vector<std::int32_t> subset, given;
    for (std::int32_t c = 0; c < m.num_cells(); ++c) {
      double xc = 0;
      for (int i = 0; i < nverts; ++i)
        xc += m.vertex(c, i)[0] / nverts;
      if (xc < 0.5)
        subset.push_back(c);
    }
    given = subset;
    given.insert(given.end(), subset.begin(), subset.begin() + 5);
    std::reverse(given.begin(), given.end());
    const CellLocator loc = make_locator(m, given);
    EXPECT_EQ(loc.num_cells(), subset.size());
    std::mt19937 gen(11);
    std::uniform_real_distribution<double> U(-0.1, 1.1);
    std::vector<double> pts;
    for (int k = 0; k < 2000; ++k)
      pts.push_back(U(gen));
    for (double max_distance : {0.0, 0.05, nverts == 3 ? 0.25 : 0.06}) {
      const LocatedPoints r = loc.locate(pts, max_distance);
      std::size_t in_right_half = 0;
      for (std::size_t p = 0; p < pts.size() / 2; ++p) {
        check_point(m, subset, r, p, {pts[2 * p], pts[2 * p + 1]}, max_distance);
        // The subset ends before x = 0.5 + 0.2 h (vertex distortion)
        in_right_half += r.cells[p] >= 0 and pts[2 * p] > 0.53 + max_distance;
      }
      EXPECT_EQ(in_right_half, 0u) << "points beyond the subset found a cell";
    }
  }
}

TEST(PointLocation, EmptySubsetLocatesNothing) {
  const Mesh m = unit_square(4, 3, 0.0);
  const CellLocator loc = make_locator(m, {});
  const LocatedPoints r = loc.locate(std::vector<double>{0.5, 0.5}, 1.0);
  EXPECT_EQ(r.cells[0], -1);
}

TEST(PointLocation, QuadPullBackBeyondTheFoldThrows) {
  // Trapezoid x(X) = (X0 (1 - X1/2), X1): the bilinear map folds at X1 = 2, where every
  // point has x0 = 0, so (3, 2) has no pre-image
  const std::vector<double> x = {0, 0, 1, 0, 0, 1, 0.5, 1};
  const std::vector<std::int32_t> cells = {0, 1, 2, 3}, subset = {0};
  const CellLocator loc(x, 2, cells, 4, subset);
  const LocatedPoints r = loc.locate(std::vector<double>{0.4, 0.5, 0.6, 1.2}, 1.0);
  EXPECT_EQ(r.outside[0], 0.0);
  EXPECT_NEAR(r.X[0], 0.4 / 0.75, 1e-14);
  EXPECT_NEAR(r.X[1], 0.5, 1e-14);
  EXPECT_NEAR(r.X[3], 1.2, 1e-14); // extrapolated below the fold: fine
  EXPECT_THROW(loc.locate(std::vector<double>{3, 2}, 10.0), std::runtime_error);
}

TEST(PointLocation, BadInputThrows) {
  const Mesh m = unit_square(3, 3, 0.0);
  const auto all = m.all();
  auto throws = [](auto f) { EXPECT_THROW(f(), std::invalid_argument); };
  throws([&] { CellLocator(m.x, 1, m.cells, 3, all); });                                  // gdim
  throws([&] { CellLocator(std::span(m.x).first(m.x.size() - 1), 2, m.cells, 3, all); }); // x
  throws([&] { CellLocator(m.x, 2, m.cells, 5, all); });                                  // nverts
  throws([&] { CellLocator(m.x, 2, std::span(m.cells).first(m.cells.size() - 1), 3, all); });
  throws([&] { CellLocator(m.x, 2, m.cells, 3, std::vector<std::int32_t>{0, 18}); }); // subset
  throws([&] { CellLocator(m.x, 2, m.cells, 3, std::vector<std::int32_t>{-1}); });
  auto bad = m.cells;
  bad[4] = 16; // vertex index out of range
  throws([&] { CellLocator(m.x, 2, bad, 3, all); });
  auto nan = m.x;
  nan[0] = std::numeric_limits<double>::quiet_NaN();
  throws([&] { CellLocator(nan, 2, m.cells, 3, all); });
  const std::vector<double> tri = {0, 0, 1, 1, 2, 2};
  EXPECT_NO_THROW(CellLocator(tri, 2, std::vector<std::int32_t>{0, 1, 2}, 3, {})); // not indexed
  EXPECT_THROW(
      CellLocator(tri, 2, std::vector<std::int32_t>{0, 1, 2}, 3, std::vector<std::int32_t>{0}),
      std::invalid_argument); // degenerate
  // Quads in polygon order instead of tensor order look like a bow tie
  const std::vector<double> sq = {0, 0, 1, 0, 0, 1, 1, 1};
  EXPECT_NO_THROW(
      CellLocator(sq, 2, std::vector<std::int32_t>{0, 1, 2, 3}, 4, std::vector<std::int32_t>{0}));
  EXPECT_THROW(
      CellLocator(sq, 2, std::vector<std::int32_t>{0, 1, 3, 2}, 4, std::vector<std::int32_t>{0}),
      std::invalid_argument);
  const std::vector<double> dart = {0, 0, 1, 0, 0, 1, 0.2, 0.2}; // non-convex
  EXPECT_THROW(
      CellLocator(dart, 2, std::vector<std::int32_t>{0, 1, 2, 3}, 4, std::vector<std::int32_t>{0}),
      std::invalid_argument);
  const CellLocator loc = make_locator(m, all);
  throws([&] { loc.locate(std::vector<double>{0.5, 0.5, 0.5}, 0.0); });
  throws([&] { loc.locate(std::vector<double>{0.5, 0.5}, -1.0); });
  throws([&] { loc.locate(std::vector<double>{0.5, 0.5}, std::nan("")); });
  throws([&] { loc.locate(std::vector<double>{0.5, std::nan("")}, 0.0); });
}

// Timing print (not asserted): 1e5 random points on a 200 x 200 mesh
TEST(PointLocation, ThroughputPrint) {
  for (int nverts : {3, 4}) {
    const Mesh m = unit_square(200, nverts, 0.2);
    const auto t0 = std::chrono::steady_clock::now();
    const CellLocator loc = make_locator(m, m.all());
    const auto t1 = std::chrono::steady_clock::now();
    std::mt19937 gen(1);
    std::uniform_real_distribution<double> U(-0.002, 1.002);
    std::vector<double> pts(200000);
    for (auto& v : pts)
      v = U(gen);
    const LocatedPoints r = loc.locate(pts, 0.002);
    const auto t2 = std::chrono::steady_clock::now();
    const double tb = std::chrono::duration<double>(t1 - t0).count();
    const double tl = std::chrono::duration<double>(t2 - t1).count();
    std::printf("[ timing ] %s: %d cells, %d x %d bins, build %.3f ms, locate 1e5 points %.3f ms "
                "(%.2e points/s)\n",
                nverts == 3 ? "triangles" : "quads", m.num_cells(), loc.num_bins()[0],
                loc.num_bins()[1], 1e3 * tb, 1e3 * tl, 1e5 / tl);
    EXPECT_EQ(std::count(r.cells.begin(), r.cells.end(), -1), 0);
  }
}
