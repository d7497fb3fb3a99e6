// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

#include "levelset.h"
#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace contact {

/// @brief Minimum level set phi_min = min(phi_i, phi_j) at the nodes (eq 21), the union of
/// the two bodies; `closing_levelset` builds on it.
/// @throws std::invalid_argument if the grids differ
LevelSet min_levelset(const LevelSet& phi_i, const LevelSet& phi_j);

/// @brief Intermediate level set phi_int = (phi_i - phi_j) / 2 at the nodes (eq 23).
///
/// Its zero contour is equidistant from both boundaries; grad phi_int points
/// from body i towards body j.
/// @throws std::invalid_argument if the grids differ
LevelSet intermediate_levelset(const LevelSet& phi_i, const LevelSet& phi_j);

/// @brief Closing level set psi = reinitialize(phi_min - eps) + eps (eq 22), phi_min from
/// `min_levelset` (eq 21).
///
/// psi < 0 on the union of the bodies and on the "liquid bridges" narrower than
/// about 2 eps between them. With a finite `cap` the distances are swept to cap only
/// (`reinitialize`): psi is exact where |psi - eps| < cap and keeps its sign elsewhere.
LevelSet closing_levelset(const LevelSet& phi_i, const LevelSet& phi_j, double eps,
                          double cap = std::numeric_limits<double>::infinity());

/// @brief Contact-region indicator (eq 22, extended to overlaps): the one definition of the
/// contact region Omega_c.
///
/// From the values of phi_i, phi_j and the closing psi (`closing_levelset`) at a point,
///   r = min(psi, max(phi_i, phi_j))   unless exactly one of phi_i, phi_j is < 0,
///   r = -min(phi_i, phi_j) > 0       inside exactly one body,
/// which is negative exactly on
///   Omega_c = {phi_i >= 0 and phi_j >= 0 and psi < 0} U {phi_i < 0 and phi_j < 0}:
/// the "liquid bridge" outside both bodies (boundaries included, so bodies that touch along a
/// line keep it) but close to both, and the penetrated overlap. It is continuous on Gamma_int
/// (phi_i = phi_j, where it is min(psi, phi_i)), so Gamma_c is clipped by root finding.
/// `contact_region` flags the nodes where r < 0; `contact_surface` clips Gamma_int where r
/// changes sign.
inline double region_indicator(double phi_i, double phi_j, double psi) {
  if ((phi_i < 0) != (phi_j < 0))
    return -std::min(phi_i, phi_j);
  return std::min(psi, std::max(phi_i, phi_j));
}

/// @brief Node flags of the contact region (eq 22) extended to overlaps:
/// `region_indicator` < 0 at the node.
std::vector<std::int8_t> contact_region(const LevelSet& phi_i, const LevelSet& phi_j, double eps);

/// @brief Candidate contact surface Gamma_c (eq 24) with its quadrature.
struct ContactSurface {
  std::vector<double> segments;      ///< (ns, 2, 2) segment end points
  std::vector<std::int32_t> cells;   ///< (ns,) grid cell of each segment
  std::vector<double> points;        ///< (nq, 2) quadrature points
  std::vector<double> weights;       ///< (nq,) quadrature weights (length measure)
  std::vector<double> normals;       ///< (nq, 2) unit grad phi_int / |grad phi_int| (i -> j)
  std::vector<double> tangents;      ///< (nq, 2) t = (-n_y, n_x)
  std::vector<std::int32_t> segment; ///< (nq,) segment of each quadrature point
};

/// @brief Zero contour of phi_int restricted to the contact region (eqs 22-24).
///
/// In each grid cell crossed by phi_int = 0 the contour is a straight segment
/// between its edge crossings (`cell_contour`, the marching squares of the cut cells; here the
/// crossings are roots of the C1 interpolant by bracketed root finding and saddle cells are
/// resolved by its value at the cell centre). Each segment is clipped to the contact region
/// where `region_indicator` changes sign, evaluated with phi_i = phi_j = (phi_i + phi_j) / 2
/// (their common value on Gamma_int): in the bridge it changes sign with psi, and
/// overlapping (penetrated) parts are always kept.
/// Each segment carries `num_gauss` Gauss-Legendre points.
/// @param[in] phi_i, phi_j Level sets of the two bodies on the same grid
/// @param[in] eps Shift parameter of eq 22 (> 0), a length
/// @param[in] num_gauss Gauss points per segment (1..5)
ContactSurface contact_surface(const LevelSet& phi_i, const LevelSet& phi_j, double eps,
                               int num_gauss = 2);

/// @brief Quadrature of given segments of Gamma_c (eq 24): `num_gauss` Gauss-Legendre points
/// per segment with the normals of `contact_surface` (unit grad phi_int, body i -> j).
///
/// `contact_surface` builds its segments with it; callers use it on segments split further,
/// e.g. where a closest point crosses into another cell of a body or at the ends of the
/// multiplier elements, so that each segment integrates smooth integrands.
/// @param[in] phi_int Intermediate level set (`intermediate_levelset`)
/// @param[in] segments (ns, 2, 2) end points
/// @param[in] cells (ns,) grid cell of each segment (carried, not used)
/// @param[in] num_gauss Gauss points per segment (1..5)
ContactSurface segment_quadrature(const LevelSet& phi_int, std::span<const double> segments,
                                  std::span<const std::int32_t> cells, int num_gauss = 2);

} // namespace contact
