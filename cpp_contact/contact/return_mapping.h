// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace contact {

/// @brief Contact state of a quadrature point.
enum class ContactState : std::int8_t {
  open = 0,  ///< g_n >= 0: no traction
  stick = 1, ///< trial state admissible (phi_tr <= 0)
  slip = 2   ///< returned to the Coulomb cone
};

/// @brief Penalty-regularised Coulomb law (eqs 8, 11, 12). eps are compliances (length/stress).
struct CoulombPenalty {
  double eps_n; ///< normal penalty compliance, tau_n = g_n / eps_n (eq 8)
  double eps_t; ///< tangential compliance, tau_t = (g_t - g_t^p) / eps_t (eq 12)
  double mu;    ///< friction coefficient; mu == 0 skips the tangential branch entirely
                ///< (active points are reported as `slip` with tau_t = 0, see return_mapping)
};

/// @brief Return mapping (Algorithm 1) at n points with tangential dimension tdim (1 in 2D,
/// 2 in 3D), with the exact consistent tangent.
///
/// Per point, with g_t, g_t^p of size tdim:
///   tau_n = min(g_n, 0) / eps_n; open if g_n >= 0 (tau = 0, tangent 0, g_t^p <- g_t
///   so that contact resumes without stored tangential traction)
///   tau_tr = (g_t - g_t^p_old) / eps_t, phi_tr = |tau_tr| - mu |tau_n|
///   stick: tau_t = tau_tr,                      D = diag(1/eps_n, I/eps_t)
///   slip:  tau_t = mu |tau_n| tau_tr/|tau_tr|,  g_t^p = g_t^p_old + eps_t phi_tr tau_tr/|tau_tr|
///          d tau_t/d g_n = -mu/eps_n m, d tau_t/d g_t = mu|tau_n|/(eps_t |tau_tr|)(I - m m^T),
///          m = tau_tr/|tau_tr| (non-symmetric).
/// `tangent` is row-major (1 + tdim)^2 per point: d[tau_n, tau_t] / d[g_n, g_t].
/// The committed history gtp_old is only read; the new plastic slip goes to gtp_trial.
/// In every branch tau_t = (g_t - gtp_trial) / eps_t (up to rounding in slip).
/// Branch choices at the boundaries: g_n == 0 is open (active set tau_n < 0, eq 32);
/// phi_tr == 0 is stick. With mu == 0 every active point is `slip` with tau_t = 0,
/// gtp_trial = g_t and zero tau_t rows in the tangent (all tangential gap is plastic).
/// Sizes: g_n, tau_n, state: n; g_t, gtp_old, tau_t, gtp_trial: n*tdim (point-major);
/// tangent: n*(1+tdim)^2. gtp_trial may be the very same memory as gtp_old (in-place
/// update); no other outputs may overlap the inputs.
/// @throws std::invalid_argument on size mismatch, eps_n or eps_t not finite and > 0, mu not
/// finite and >= 0, non-finite g_n, g_t or gtp_old, tdim not in {1, 2}
void return_mapping(const CoulombPenalty& law, int tdim, std::span<const double> g_n,
                    std::span<const double> g_t, std::span<const double> gtp_old,
                    std::span<double> tau_n, std::span<double> tau_t, std::span<double> gtp_trial,
                    std::span<ContactState> state, std::span<double> tangent);

/// @brief Plastic slip history with committed and trial values kept apart.
///
/// Newton iterations write trial values; commit() accepts a converged step;
/// restore() discards trial values (rejected iteration or load-step cut-back)
/// and returns the exact committed state.
class FrictionHistory {
public:
  /// @brief n points, tangential dimension tdim, zero initial slip.
  /// @throws std::invalid_argument if tdim is not 1 or 2
  FrictionHistory(std::size_t n, int tdim);
  std::span<const double> committed() const { return _committed; }
  std::span<double> trial() { return _trial; }
  std::span<const double> trial() const { return _trial; }
  int tdim() const { return _tdim; }
  std::size_t size() const { return _committed.size() / std::size_t(_tdim); }
  /// @brief Accept the trial values.
  void commit() { _committed = _trial; }
  /// @brief Reset the trial values to the committed ones.
  void restore() { _trial = _committed; }

private:
  int _tdim;
  std::vector<double> _committed, _trial;
};

} // namespace contact
