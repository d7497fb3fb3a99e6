// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

#include "levelset.h"
#include <cstdint>
#include <span>
#include <vector>

namespace contact {

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

} // namespace contact
