// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace contact {

/// @brief Quadratic spline weight of the MLS projection (eq 45).
///
/// w(r) = 3/4 - r^2 for r <= 1/2, (3/2 - r)^2 / 2 for 1/2 <= r <= 3/2, 0 beyond, with the
/// RADIAL distance r = |x - x_p| / h (the paper's L2 norm, not a tensor product of 1D weights
/// per axis). C1 at r = 1/2 and r = 3/2; support radius 3/2. Negative r is treated as |r|.
/// Inline and branch-free: the projection evaluates it ~60 times per target.
inline double quadratic_spline_weight(double r) {
  r = std::abs(r);
  const double s = std::max(1.5 - r, 0.0);
  const double inner = 0.75 - r * r, outer = 0.5 * s * s;
  return r <= 0.5 ? inner : outer;
}

/// @brief Options of MLSProjector: when a target's fit counts as singular and how the support
/// is widened.
struct MLSOptions {
  /// A fit with reciprocal 1-norm condition number of the moment matrix (on the scaled basis)
  /// below this is singular. 1e-8 keeps the solve's relative error below ~1e-8 (eps / rcond).
  double rcond_min = 1e-8;
  /// Factor applied to the support length at each widening (> 1).
  double widen_factor = 1.5;
  /// Cap on the number of widenings (>= 0): the largest factor is widen_factor^max_widenings
  /// (1.5^4 ~ 5.1 h). Past it the projector throws rather than extrapolate from far away.
  int max_widenings = 4;
};

/// @brief Per-target result of MLSProjector::project.
struct MLSResult {
  std::vector<double> values;           ///< (k, m) projected values, row-major
  std::vector<double> widening;         ///< (k,) support factor used (1 = none)
  std::vector<double> rcond;            ///< (k,) reciprocal 1-norm condition number of M
  std::vector<std::int32_t> neighbours; ///< (k,) sources with positive weight
};

/// @brief Moving-least-squares projection from scattered material points to target points
/// (eqs 38-45): the material-point values are recovered at the new integration points.
///
/// At a target x_t the linear fit u^h(x) = P^T(x) a minimises sum_p w(|x_t - x_p| / H)
/// (P^T(x_p) a - u_p)^2 (eqs 39-40) with the quadratic spline w of eq 45 and H = h (the grid
/// spacing) times the widening factor. The basis is centred and scaled at the target,
/// P(x) = [1, (x - x_t)/H] (d + 1 terms), which spans the same space as the paper's [1, x]
/// (so the fit is that of eq 44) but keeps the moment matrix M (eq 42) O(1)-conditioned
/// independently of h and of the position. Then u^h(x_t) = a_0, the first coefficient.
///
/// The fit is singular when fewer than d + 1 sources lie within the support radius 1.5 H or
/// they are (nearly) collinear / coplanar; such a target is retried with H widened by
/// MLSOptions::widen_factor and the factor used is reported. A target still singular after
/// MLSOptions::max_widenings widenings makes project() throw.
///
/// The k-d tree (nanoflann) over the sources is built once in the constructor; the sources
/// are copied. project() is const and keeps its scratch buffers local: it may be called
/// concurrently. Consecutive targets within h of a run's first (at most 64: the Gauss points
/// of a cell) share one radius search; project() splits these runs among its threads, and the
/// runs depend on the targets alone, so the results do not depend on the thread count.
class MLSProjector {
public:
  /// @brief Index the source points.
  /// @param[in] sources Flattened (n, dim) source (material point) coordinates, n >= dim + 1
  /// @param[in] dim Spatial dimension: 2 or 3
  /// @param[in] h Support length (the grid spacing), finite and > 0
  /// @param[in] options Singularity threshold and widening policy
  /// @throws std::invalid_argument naming the argument for a bad dim, a size that is not a
  /// multiple of dim, too few points, non-finite coordinates, a bad h or bad options
  MLSProjector(std::span<const double> sources, int dim, double h, MLSOptions options = {});
  ~MLSProjector();
  MLSProjector(MLSProjector&&) noexcept;
  MLSProjector& operator=(MLSProjector&&) noexcept;

  /// @brief Number of source points n.
  std::size_t num_points() const;

  /// @brief Spatial dimension d.
  int dim() const { return _dim; }

  /// @brief Support length h.
  double h() const { return _h; }

  /// @brief Options in use.
  const MLSOptions& options() const { return _options; }

  /// @brief Project m fields at once onto the targets, with one set of MLS weights per target
  /// (eq 44).
  /// @param[in] values Flattened (n, m) source values, row-major, finite
  /// @param[in] m Number of fields (>= 1)
  /// @param[in] targets Flattened (k, d) target coordinates, finite
  /// @param[in] threads Threads sharing the targets (>= 1; the results do not depend on it)
  /// @return Values (k, m) and per target the widening factor, rcond and neighbour count
  /// @throws std::invalid_argument naming the argument for size mismatches or non-finite input
  /// @throws std::runtime_error naming the target index and coordinates if its fit is still
  /// singular at the widening cap (e.g. a target far from every source)
  MLSResult project(std::span<const double> values, std::size_t m, std::span<const double> targets,
                    int threads = 1) const;

private:
  struct Impl;
  std::unique_ptr<Impl> _impl;
  int _dim;
  double _h;
  MLSOptions _options;
};

} // namespace contact
