// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

// Cut-cell geometry and quadrature on the reference square (section 4.2): clipping, rules,
// moment-fitted weights for FFCx's Gauss points, and the clipped traction kernel. Pure numerics: no
// DOLFINx here; the kernels only follow the ufcx tabulate_tensor ABI so that DOLFINx can call them
// as custom integrals.
//
// Conventions (DOLFINx quadrilateral): reference square [0,1]^2, vertices in tensor order
// v0 (0,0), v1 (1,0), v2 (0,1), v3 (1,1); facets f0 (v0,v1), f1 (v0,v2), f2 (v1,v3),
// f3 (v2,v3). The level set phi is given by its values at the four vertices; the body is
// {phi < 0}. Inside a cut cell the zero contour is the straight segment between the zero
// crossings of phi on the cell edges (linear interpolation along each edge); when the four
// edges all carry a crossing (saddle) the centre value (mean of the four) decides whether the
// two inside corners are connected. That contour is `contact::cell_contour` (contour.h), the
// marching squares that the contact surface Gamma_c uses too.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace contact::cut {

/// Largest number of triangles `clip_square` returns.
constexpr int max_triangles = 4;

/// Layout of the packed coefficients `w` that the cut kernels read (one source of truth: the
/// Python forms are built to match it and check it). Traction form: w = [phi(4), t(18)] with t
/// a vector Q2 function (9 nodes x 2, interleaved). Cell integrals of any UFL form on cut cells
/// do not need a kernel: FFCx's rule with `moment_fitted_weights` (dolfinx_forms/fem/cut.py).
struct Layout {
  static constexpr int phi = 0;      ///< offset of the 4 vertex values of phi
  static constexpr int traction = 4; ///< offset of the Q2 vector traction (linear form)
  static constexpr int traction_size = 22;
};

/// @brief Triangulate the inside part {phi_h < 0} of the reference square.
/// @param phi level-set values at the 4 vertices (tensor order)
/// @param triangles output: up to `max_triangles` triangles, 6 reference coordinates each
///   (X0, Y0, X1, Y1, X2, Y2), counter-clockwise
/// @return the number of triangles (0 if the cell is outside, 2 if it is entirely inside)
int clip_square(std::span<const double, 4> phi, std::span<double, 6 * max_triangles> triangles);

/// @brief Quadrature rule on the inside part of the reference square.
/// @param phi vertex values (tensor order)
/// @param degree polynomial degree integrated exactly on each sub-triangle (1, 2 or 4)
/// @param points appended reference points (X, Y)
/// @param weights appended weights (reference area: the full square has total weight 1)
void cut_square_rule(std::span<const double, 4> phi, int degree, std::vector<double>& points,
                     std::vector<double>& weights);

/// @brief Inside part of a reference segment [0, 1] with end values phi0, phi1.
/// @return the sub-interval [s0, s1] (s0 == s1 when the segment is outside)
std::array<double, 2> clip_segment(double phi0, double phi1);

/// @brief Area fraction of the inside part of the reference square (0..1).
double inside_fraction(std::span<const double, 4> phi);

/// Largest number of points per direction that `moment_fitted_weights` accepts.
constexpr int max_fitted_points = 6;

/// @brief Moment-fitted weights of a fixed tensor rule on a cut cell (cut-cell integration of
/// the ILS-MPM paper, section 4.2, for any integrand).
///
/// The points (e.g. FFCx's tensor Gauss rule) stay where they are; only the weights change, so
/// that sum_k W_k p(X_k) = int_{inside} p for every p in Q_{mx-1} x Q_{my-1}. W_k is the integral
/// over the inside part (exactly the triangles of `clip_square`) of the tensor Lagrange
/// polynomial of point k, computed with a triangle rule exact for degree mx + my - 2. The weights
/// can be negative, but they integrate Q_{m-1} exactly: with m = 3 the elastic energy of Q1 fields
/// (in Q2 on rectangles) is exact and so stays positive semi-definite. A fully inside cell gives
/// the tensor Gauss weights (to round-off), a fully outside cell zeros.
/// @param phi level-set values at the 4 vertices (tensor order)
/// @param points nq reference points (X, Y interleaved) forming a full tensor grid of
///   mx x my points in any order (coordinates equal to 1e-10 count as one grid line),
///   1 <= mx, my <= `max_fitted_points`
/// @param weights output (nq): weights in the order of `points` (the full square has total 1)
/// @throws std::invalid_argument if the points are not a full tensor grid or sizes mismatch
void moment_fitted_weights(std::span<const double, 4> phi, std::span<const double> points,
                           std::span<double> weights);

/// @brief Traction load on the inside part of a boundary facet of a cut cell (ufcx ABI).
///
/// b (8, dof = node*2 + component) += int_{facet, phi_h<0} t . v ds, where t is a vector Q2
/// function (its trace on the facet is the quadratic through the two vertex values and the
/// edge-midpoint value) and phi_h is linear along the facet. entity_local_index[0] = facet.
void traction_q1(double* A, const double* w, const double* c, const double* coordinate_dofs,
                 const int* entity_local_index, const std::uint8_t* quad_perm);

} // namespace contact::cut
