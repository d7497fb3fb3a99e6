// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

#include "levelset.h"
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace contact {

/// @brief Reinitialise phi to a signed distance while keeping its zero contour in place.
///
/// Nodes of cells crossed by the zero contour, and their 8 neighbours, get their
/// exact distance to the zero contour of the C1 interpolant of phi (closest-point
/// projection, eq 25). The neighbours matter: the Hermite slopes of a crossed cell
/// use them, and with swept values there the interface drifts by O(h^2) instead of
/// O(h^3). All other nodes are filled by the fast sweeping method (Zhao 2005;
/// Godunov upwind update valid on graded grids), with the sign of phi kept.
/// @param[in] phi Level set with at least one sign change
/// @param[in] max_sweeps Cap on Gauss-Seidel sweep rounds (4 orderings each)
/// @param[in] cap Largest distance swept to: farther nodes get +-cap (a narrow band; the
/// values below it are those of the whole sweep)
/// @return The reinitialised level set on the same grid
/// @throws std::invalid_argument if phi has no zero contour
LevelSet reinitialize(const LevelSet& phi, int max_sweeps = 8,
                      double cap = std::numeric_limits<double>::infinity());

/// @brief Signed distance to a closed polyline (e.g. a gmsh boundary curve).
///
/// Exact distance to the segments in a band of `band` cells around the curve,
/// sign from a scanline crossing count (even-odd rule, inside < 0; a
/// self-intersecting polyline gets even-odd inside/outside), fast sweeping beyond.
/// Cost O(nodes + segments * band^2) instead of O(nodes * segments).
/// @param[in] grid Background grid
/// @param[in] vertices Flattened (m, 2) vertices, m >= 3, closing edge implied
/// @param[in] band Half-width of the exact band in cells (>= 1)
/// @throws std::invalid_argument for fewer than 3 vertices, an odd-length array,
/// non-finite coordinates, band < 1, or no grid node within the band of the curve
LevelSet levelset_from_polyline(const StructuredGrid& grid, std::span<const double> vertices,
                                int band = 3);

/// @brief Fast sweeping solution of |grad d| = 1 from fixed nodes.
///
/// Nodes with fixed[k] != 0 keep their value; the others get the first-order
/// upwind distance (unsigned: callers apply the sign).
/// Exposed for the level-set constructors and for tests.
/// @param[in] grid Background grid
/// @param[in,out] d Distances (>= 0); values at non-fixed nodes are overwritten
/// @param[in] fixed Flags of the nodes that keep their value
/// @param[in] max_sweeps Cap on sweep rounds
/// @param[in] cap Largest distance swept to: the other nodes start there and keep it
/// @throws std::invalid_argument for a size mismatch, no fixed node, max_sweeps < 1,
/// or a non-finite fixed value
void fast_sweep(const StructuredGrid& grid, std::span<double> d, std::span<const std::int8_t> fixed,
                int max_sweeps, double cap = std::numeric_limits<double>::infinity());

} // namespace contact
