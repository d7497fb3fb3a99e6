// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

#include <span>

namespace contact {

/// @brief Initial normal gap g_n0 = (P_j - P_i) . n at one point (eq 28), from the closest
/// points P_i, P_j (eq 25) and the contact normal n (from body i towards body j).
inline double initial_normal_gap(std::span<const double, 2> p_i, std::span<const double, 2> p_j,
                                 std::span<const double, 2> n) {
  return (p_j[0] - p_i[0]) * n[0] + (p_j[1] - p_i[1]) * n[1];
}

/// @brief Gaps at one contact point (eqs 27, 29, 30).
struct PointGaps {
  double j_int; ///< normal displacement jump (u_j - u_i) . n (eq 29)
  double g_n;   ///< normal gap g_n0 + j_int (eq 27)
  double g_t;   ///< tangential gap (u_j - u_i) . t (eq 30)
};

/// @brief Gaps at one point from the initial normal gap g_n0 (eq 28) and the displacement
/// jump du = u_j(P_j) - u_i(P_i) (eq 26): the one place these equations are written; the
/// contact kernel (eq 48) and `compute_gaps` both call it.
/// @param[in] g_n0 Initial normal gap (`initial_normal_gap`)
/// @param[in] du Displacement jump (2 values)
/// @param[in] n Unit normal (body i -> body j)
/// @param[in] t Unit tangent (any unit vector orthogonal to n; the sign of g_t follows it)
inline PointGaps point_gaps(double g_n0, std::span<const double, 2> du,
                            std::span<const double, 2> n, std::span<const double, 2> t) {
  const double j_int = du[0] * n[0] + du[1] * n[1];
  return {j_int, g_n0 + j_int, du[0] * t[0] + du[1] * t[1]};
}

/// @brief Gap functions at contact points (eqs 26-31), 2D, vectorised over points
/// (`initial_normal_gap` and `point_gaps` at each point).
///
/// For each point with projections P_i, P_j, displacements u_i(P_i), u_j(P_j),
/// contact normal n (from body i towards body j) and tangent t (the contact surface
/// uses t = (-n_y, n_x); any unit t orthogonal to n works, the sign of g_t follows it):
///   g_n0  = (P_j - P_i) . n                 (eq 28)
///   j_int = (u_j - u_i) . n                 (eq 29)
///   g_n   = g_n0 + j_int                    (eq 27)
///   g_t   = (u_j - u_i) . t                 (eq 30)
/// All arrays are flattened (n, 2) except the scalar outputs (n).
/// @throws std::invalid_argument if sizes disagree
void compute_gaps(std::span<const double> p_i, std::span<const double> p_j,
                  std::span<const double> u_i, std::span<const double> u_j,
                  std::span<const double> normals, std::span<const double> tangents,
                  std::span<double> g_n0, std::span<double> j_int, std::span<double> g_n,
                  std::span<double> g_t);

} // namespace contact
