// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

#include <span>

namespace contact {

/// @brief Gap functions at contact points (eqs 26-31), 2D.
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
