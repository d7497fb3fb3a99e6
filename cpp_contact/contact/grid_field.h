// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <span>

namespace contact {

/// @brief Value and gradient of a Q1 vector field at points of axis-aligned grid cells: the
/// FE interpolant that moves the material points and updates their state after a step
/// (seed paper section 4.4).
///
/// Cell vertices in tensor order, axis 0 fastest (basix's quadrilateral and hexahedron order):
/// vertex v has reference coordinate bit a of v along axis a, and
/// N_v(X) = prod_a (bit_a ? X_a : 1 - X_a). On an axis-aligned cell of extents e,
/// d/dx_a = (1 / e_a) d/dX_a. X outside [0, 1]^d extrapolates.
/// @param[in] u Field values per dof, (num_dofs, bs) row-major
/// @param[in] bs Components of the field (>= 1)
/// @param[in] dofs (n, 2^dim) dofs of each point's cell, in the vertex order above
/// @param[in] X (n, dim) reference coordinates of the points in their cells
/// @param[in] extent (n, dim) edge lengths of each point's cell (> 0)
/// @param[in] dim 2 or 3
/// @param[out] out (n, bs (1 + dim)): the bs values, then grad[c][a] = du_c / dx_a row-major
/// @throws std::invalid_argument on sizes that do not match or a dof out of range
void q1_evaluate(std::span<const double> u, int bs, std::span<const std::int32_t> dofs,
                 std::span<const double> X, std::span<const double> extent, int dim,
                 std::span<double> out);

} // namespace contact
