// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

// The zero contour of a level set in one quadrilateral cell (marching squares), shared by the
// contact surface Gamma_c (eq 24, `contact_surface.h`) and the cut-cell clipping (section 4.2,
// `cut_cell.h`). Pure topology plus one root per crossed edge: how the crossings are found
// (linear interpolation of the vertex values, or a root of a smoother interpolant) and what the
// value at the cell centre is (for saddles) are the caller's.

#include <array>
#include <span>

namespace contact {

/// @brief Edges of a quadrilateral cell, vertices in tensor order v0 (0,0), v1 (1,0), v2 (0,1),
/// v3 (1,1): e0 bottom (v0,v1), e1 right (v1,v3), e2 top (v2,v3), e3 left (v0,v2).
///
/// Each edge runs from its lower vertex to its higher one, so the two cells sharing an edge
/// compute its crossing from the same data in the same order (bitwise the same point). The
/// order e0, e1, e2, e3 also walks the boundary counter-clockwise.
constexpr std::array<std::array<int, 2>, 4> cell_edges = {{{0, 1}, {1, 3}, {2, 3}, {0, 2}}};

/// @brief Zero of the linear interpolant between the values fa (at t = 0) and fb (at t = 1) of
/// opposite signs: t = fa / (fa - fb), in [0, 1].
inline double linear_root(double fa, double fb) {
  return fa / (fa - fb);
}

/// @brief Point at parameter t on edge e of a cell whose vertices X are in tensor order:
/// X[a] + t (X[b] - X[a]) with (a, b) = cell_edges[e].
inline std::array<double, 2> edge_point(std::span<const std::array<double, 2>, 4> X, int e,
                                        double t) {
  const std::array<double, 2>& a = X[cell_edges[e][0]];
  const std::array<double, 2>& b = X[cell_edges[e][1]];
  return {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])};
}

/// @brief Zero contour of a level set in one cell: which edges it crosses, where, and how the
/// crossings are joined into straight segments.
struct CellContour {
  std::array<bool, 4> crossed{}; ///< edge e (`cell_edges`) joins an inside and an outside vertex
  std::array<double, 4> t{};     ///< crossing of a crossed edge at parameter t (`edge_point`)
  int num_segments = 0;          ///< 0 (no sign change), 1, or 2 (saddle)
  std::array<std::array<int, 2>, 2> segments{}; ///< the two crossed edges each segment joins
  bool centre_inside = false;                   ///< saddles only: the centre value is < 0
};

/// @brief Marching squares in one cell: the zero contour of phi as straight segments between
/// the edge crossings, saddles resolved by the value at the cell centre.
///
/// The inside is phi < 0; a zero vertex counts as outside (eq 17: phi = 0 is the boundary, of
/// zero measure). An edge whose vertices differ in that sense is crossed at the parameter
/// `edge_root(e, phi[a], phi[b])` (from its lower vertex a, see `cell_edges`). One segment joins
/// the two crossed edges of a cell with 2 crossings (e.g. (e0, e1) for the edge order). With 4
/// crossings (a saddle: v0, v3 on one side, v1, v2 on the other) `centre_value()` decides:
/// if the centre is on the side of v0, v0 and v3 are connected through the centre and the
/// segments (e0, e1), (e3, e2) cut off v1 and v2; otherwise (e3, e0), (e1, e2) cut off v0 and v3.
/// @param[in] phi Level-set values at the 4 vertices (tensor order)
/// @param[in] edge_root Callable (int e, double fa, double fb) -> t in [0, 1], the crossing of
/// edge e with values fa at its lower vertex and fb at its higher one; called once per crossed
/// edge
/// @param[in] centre_value Callable () -> value at the cell centre; called for saddles only
/// @return The contour of the cell
template <typename EdgeRoot, typename CentreValue>
CellContour cell_contour(std::span<const double, 4> phi, EdgeRoot&& edge_root,
                         CentreValue&& centre_value) {
  const std::array<bool, 4> in = {phi[0] < 0, phi[1] < 0, phi[2] < 0, phi[3] < 0};
  CellContour c;
  int n = 0;
  for (int e = 0; e < 4; ++e) {
    const int a = cell_edges[e][0], b = cell_edges[e][1];
    c.crossed[e] = in[a] != in[b];
    if (c.crossed[e]) {
      c.t[e] = edge_root(e, phi[a], phi[b]);
      if (n < 2)
        c.segments[0][n] = e; // the two crossed edges, in edge order
      ++n;
    }
  }
  if (n == 2)
    c.num_segments = 1;
  else if (n == 4) {
    c.num_segments = 2;
    c.centre_inside = centre_value() < 0;
    if (c.centre_inside == in[0])
      c.segments = {{{0, 1}, {3, 2}}}; // v0 and v3 connected: cut off v1 and v2
    else
      c.segments = {{{3, 0}, {1, 2}}}; // v1 and v2 connected: cut off v0 and v3
  }
  return c;
}

/// @brief Marching squares for the bilinear interpolant of the vertex values: linear crossings
/// on the edges, centre value the mean of the four (the bilinear value there).
inline CellContour cell_contour(std::span<const double, 4> phi) {
  return cell_contour(
      phi, [](int, double fa, double fb) { return linear_root(fa, fb); },
      [phi]() { return 0.25 * (phi[0] + phi[1] + phi[2] + phi[3]); });
}

} // namespace contact
