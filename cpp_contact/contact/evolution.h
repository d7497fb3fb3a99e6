// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

// Level-set evolution of the implicit MPM (section 3.1): constant normal extension of the
// displacement off the body (eq 20), HJ-WENO5 / TVD-RK3 advection of phi (eq 19), and the
// diagnostics that decide when to reinitialise (gradient drift) and check conservation (area).
// The numerics are per-axis 1D stencils inside loops over axes, so 3D is an extension.

#include "grid.h"
#include "levelset.h"
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace contact {

/// What `extend_normal` did.
struct ExtensionInfo {
  int sweeps = 0;           ///< Gauss-Seidel sweeps run (4 per round)
  std::size_t fallback = 0; ///< nodes without a filled upwind neighbour, filled by averaging
};

/// @brief Constant extension of node fields along the normal: grad q . grad phi = 0 (eq 20).
///
/// Nodes with known != 0 keep their values; every other node is filled from its upwind
/// neighbours, which are the neighbours with strictly smaller phi: information flows along
/// +grad phi, outward from the body {phi < 0}. One direction everywhere keeps the dependency
/// graph acyclic (phi decreases along every chain), so Gauss-Seidel sweeps converge in a finite
/// number of rounds. An unknown node with phi < 0 (e.g. of a dropped small cut cell) is thereby
/// filled from the deeper, more negative neighbours, i.e. extrapolated outward from the body's
/// interior along the same characteristics. The upwind update is the discrete
/// sum_d (phi_k - phi_d)/h_d (q_k - q_d)/h_d = 0 of Adalsteinsson & Sethian (1999) and Zhao (2005),
/// a convex combination with weights from the upwind components of grad phi (graded grids too).
/// Nodes still unfilled after the sweeps (local minima of phi without a known node, or chains
/// ending in one) are filled by breadth-first averaging of their filled 4-neighbours and counted
/// in ExtensionInfo::fallback.
/// @param[in] grid Background grid
/// @param[in] phi Level-set node values (x-fastest)
/// @param[in] known Flags of the nodes whose values are given (one per node)
/// @param[in,out] values Flattened (nodes, m) fields, row-major; unknown rows are overwritten
/// @param[in] m Number of fields (>= 1)
/// @param[in] max_sweeps Cap on rounds of the 4 sweep orderings
/// @throws std::invalid_argument naming the argument for wrong sizes, m < 1, max_sweeps < 1,
///   non-finite phi or known values, or no known node
/// @throws std::runtime_error if the sweeps have not converged after max_sweeps rounds
ExtensionInfo extend_normal(const StructuredGrid& grid, std::span<const double> phi,
                            std::span<const std::int8_t> known, std::span<double> values,
                            std::size_t m, int max_sweeps = 20);

/// @brief HJ-WENO5 approximation of a derivative from 5 divided differences (Jiang & Peng 2000).
///
/// For phi_x^- at node i pass v = (D-phi_{i-2}, ..., D-phi_{i+2}); for phi_x^+ pass
/// v = (D+phi_{i+2}, ..., D+phi_{i-2}) (reversed), with D-phi_j = (phi_j - phi_{j-1}) / h.
/// Convex combination of the three third-order ENO candidates with the smoothness weights;
/// epsilon = 1e-6 max(v^2) + 1e-99 (Osher & Fedkiw 2003), scale-invariant.
double weno5(double v1, double v2, double v3, double v4, double v5);

/// @brief One-sided HJ-WENO5 derivatives D-phi and D+phi at every node of a uniform line.
///
/// Three ghost values at each end come from linear extrapolation of the two end values, so a
/// linear function is differentiated exactly up to the boundary (boundary nodes are first
/// order for curved data).
/// @param[in] line n >= 2 values with spacing h
/// @param[in] h Spacing (> 0)
/// @param[out] minus D-phi (n)
/// @param[out] plus D+phi (n)
void weno5_derivatives(std::span<const double> line, double h, std::span<double> minus,
                       std::span<double> plus);

/// Result of `advect`.
struct AdvectResult {
  std::vector<double> values; ///< phi at the end time (x-fastest)
  int substeps;               ///< TVD-RK3 steps taken
};

/// @brief Advect phi with a steady node velocity: phi_t + v . grad phi = 0 (eq 19).
///
/// HJ-WENO5 in space, upwinded per axis by the sign of the velocity component, TVD-RK3
/// (Shu & Osher 1988) in pseudo-time with substeps = max(1, ceil(time max_k(|v_x| + |v_y|) /
/// (cfl h))) of equal length, h the smallest spacing. Boundary: ghost values by linear
/// extrapolation (see weno5_derivatives); inflow boundary nodes follow the extrapolated slope.
/// For the quasi-static steps, v is the (extended) displacement increment and time = 1.
/// @param[in] grid Uniform grid (each axis uniform; hx != hy allowed)
/// @param[in] phi Node values (x-fastest)
/// @param[in] velocity Flattened (nodes, 2) node velocities
/// @param[in] time Pseudo-time (>= 0)
/// @param[in] cfl Courant number in (0, 1]
/// @throws std::invalid_argument naming the argument for a graded axis, wrong sizes,
///   non-finite input, time < 0 or cfl outside (0, 1]
AdvectResult advect(const StructuredGrid& grid, std::span<const double> phi,
                    std::span<const double> velocity, double time = 1.0, double cfl = 0.5);

/// @brief Largest | |grad phi| - 1 | over the nodes near the zero contour.
///
/// Gradients by central differences (second-order three-point formula on graded axes,
/// one-sided at the boundary). A node counts if its first-order distance estimate
/// |phi| / |grad phi| is at most `band`. The caller reinitialises (`reinitialize`) when this
/// exceeds its threshold. Returns 0 if no node qualifies.
/// @throws std::invalid_argument for a wrong size or band < 0
double gradient_drift(const StructuredGrid& grid, std::span<const double> phi, double band);

/// @brief Area of {phi < 0}: the sum over cells of the inside polygon of `cut::clip_square`.
///
/// The same polygon as the cut-cell integration, so this is the body area that the mechanics
/// sees; O(h^2) from the piecewise-linear contour.
/// @throws std::invalid_argument for a wrong size
double inside_area(const StructuredGrid& grid, std::span<const double> phi);

} // namespace contact
