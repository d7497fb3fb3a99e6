// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

#include "levelset.h"
#include <cstdint>
#include <span>
#include <vector>

namespace contact {
class Shape;

/// @brief Outcome of the closest-point iteration at one point.
enum class ProjectionStatus : std::int8_t {
  converged = 0,          ///< step and residual below tolerance
  max_iterations = 1,     ///< iteration cap reached
  vanishing_gradient = 2, ///< |grad phi| too small (e.g. medial axis): direction undefined
  left_grid = 3           ///< an iterate left the grid
};

/// @brief Controls of the closest-point iteration.
struct ProjectionOptions {
  double rtol =
      1e-10; ///< tolerance on the step and on |phi|/|grad phi|, relative to min grid spacing
  int max_iterations = 50; ///< iteration cap
  double grad_tol = 1e-8;  ///< |grad phi| below this (relative to 1, phi being ~ a distance) fails
};

/// @brief Result of closest_point_projection for n points.
struct ProjectionResult {
  std::vector<double> points;           ///< (n, 2) projected points P(x0)
  std::vector<ProjectionStatus> status; ///< per point
  std::vector<std::int32_t> iterations; ///< iterations used per point
};

/// @brief Closest-point projection onto the zero contour of phi (eq 25, Rycroft & Gibou).
///
/// Iterates x^{k+1} = x^k + d1 + d2 with d1 = -phi grad phi/|grad phi|^2 (onto phi = 0)
/// and d2 the component of (x0 - x^k) tangent to the level set at x^k, until
/// |x^{k+1} - x^k| and |phi|/|grad phi| are below rtol * h. Each point gets a status;
/// a failed point keeps its last iterate and is never reported as converged.
/// @param[in] phi Level set
/// @param[in] x0 Flattened (n, 2) start points, all inside the grid
/// @param[in] opts Tolerances
/// @throws std::invalid_argument for a malformed array or a non-finite point
/// @throws std::out_of_range naming the first start point outside the grid
ProjectionResult closest_point_projection(const LevelSet& phi, std::span<const double> x0,
                                          const ProjectionOptions& opts = {});

/// @brief Closest-point projection onto the boundary of an exact signed-distance shape.
///
/// For an exact signed distance d, P(x) = x - d(x) grad d(x) in one step; the step is
/// repeated until |d| <= tol (a composite shape is only a distance on one side). grad d is a
/// central difference of step 1e-7 * length_scale (d is piecewise smooth; away from the medial
/// axis the difference is exact to O(step^2)). Unlike eq 25 on a grid interpolant this is
/// exact at corners: the reference (body-fitted) path uses it where the shape is analytic.
/// @param[in] shape Exact signed distance (negative inside)
/// @param[in] x0 Flattened (n, 2) start points
/// @param[in] length_scale Tolerances are relative to it (e.g. the mesh size)
/// @param[in] opts rtol (relative to length_scale), max_iterations, grad_tol
ProjectionResult closest_point_projection(const Shape& shape, std::span<const double> x0,
                                          double length_scale, const ProjectionOptions& opts = {});

} // namespace contact
