// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "return_mapping.h"
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace contact {
namespace {
/// Throw unless a span has the expected number of entries.
void check_size(std::size_t size, std::size_t expected, const char* name, const char* shape) {
  if (size != expected) {
    throw std::invalid_argument(std::string("return_mapping: ") + name + " has size " +
                                std::to_string(size) + ", expected " + shape + " = " +
                                std::to_string(expected));
  }
}

/// Throw unless every entry is finite (a NaN gap would otherwise silently take the
/// open branch, because every comparison with NaN is false).
void check_finite(std::span<const double> x, const char* name) {
  if (!std::ranges::all_of(x, [](double v) { return std::isfinite(v); })) {
    throw std::invalid_argument(std::string("return_mapping: ") + name +
                                " must be finite (found NaN or inf)");
  }
}
} // namespace

//-----------------------------------------------------------------------------
void return_mapping(const CoulombPenalty& law, int tdim, std::span<const double> g_n,
                    std::span<const double> g_t, std::span<const double> gtp_old,
                    std::span<double> tau_n, std::span<double> tau_t, std::span<double> gtp_trial,
                    std::span<ContactState> state, std::span<double> tangent) {
  if (tdim != 1 and tdim != 2) {
    throw std::invalid_argument("return_mapping: tdim must be 1 (2D) or 2 (3D), got " +
                                std::to_string(tdim));
  }
  // Written as !(x > 0) so that NaN is rejected as well
  if (!(law.eps_n > 0) or !std::isfinite(law.eps_n))
    throw std::invalid_argument("return_mapping: eps_n must be finite and > 0");
  if (!(law.eps_t > 0) or !std::isfinite(law.eps_t))
    throw std::invalid_argument("return_mapping: eps_t must be finite and > 0");
  if (!(law.mu >= 0) or !std::isfinite(law.mu))
    throw std::invalid_argument("return_mapping: mu must be finite and >= 0");

  const std::size_t n = g_n.size();
  const std::size_t td = tdim;
  const std::size_t nd = 1 + td; // size of [tau_n, tau_t]
  check_size(g_t.size(), n * td, "g_t", "n*tdim");
  check_size(gtp_old.size(), n * td, "gtp_old", "n*tdim");
  check_size(tau_n.size(), n, "tau_n", "n");
  check_size(tau_t.size(), n * td, "tau_t", "n*tdim");
  check_size(gtp_trial.size(), n * td, "gtp_trial", "n*tdim");
  check_size(state.size(), n, "state", "n");
  check_size(tangent.size(), n * nd * nd, "tangent", "n*(1+tdim)^2");
  check_finite(g_n, "g_n");
  check_finite(g_t, "g_t");
  check_finite(gtp_old, "gtp_old");

  const double eps_n = law.eps_n, eps_t = law.eps_t, mu = law.mu;
  for (std::size_t p = 0; p < n; ++p) {
    // Copy the point's inputs first: gtp_trial may then alias gtp_old (in-place update)
    std::array<double, 2> gt{}, gtp{};
    std::copy_n(g_t.begin() + p * td, td, gt.begin());
    std::copy_n(gtp_old.begin() + p * td, td, gtp.begin());

    std::span<double> tt = tau_t.subspan(p * td, td);
    std::span<double> gp = gtp_trial.subspan(p * td, td);
    std::span<double> D = tangent.subspan(p * nd * nd, nd * nd);
    std::ranges::fill(D, 0.0);

    // Open (g_n == 0 included, so the active set is tau_n < 0 strictly, eq 32): the
    // plastic slip follows the tangential gap so that re-contact starts from zero
    // tangential traction and tau_t = (g_t - g_t^p)/eps_t = 0 holds here too.
    if (g_n[p] >= 0.0) {
      tau_n[p] = 0.0;
      std::ranges::fill(tt, 0.0);
      std::copy_n(gt.begin(), td, gp.begin());
      state[p] = ContactState::open;
      continue;
    }

    const double tn = g_n[p] / eps_n; // eq 8, < 0
    tau_n[p] = tn;
    D[0] = 1.0 / eps_n;

    // Frictionless: the tangential traction vanishes, so all tangential gap is plastic
    if (mu == 0.0) {
      std::ranges::fill(tt, 0.0);
      std::copy_n(gt.begin(), td, gp.begin());
      state[p] = ContactState::slip;
      continue;
    }

    // Elastic trial state (eq 12 with the committed slip)
    std::array<double, 2> ttr{};
    double norm2 = 0.0;
    for (std::size_t k = 0; k < td; ++k) {
      ttr[k] = (gt[k] - gtp[k]) / eps_t;
      norm2 += ttr[k] * ttr[k];
    }
    const double norm = std::sqrt(norm2);
    const double bound = -mu * tn; // mu |tau_n| > 0
    const double phi_tr = norm - bound;

    // Stick. The norm > 0 test only guards the division below: phi_tr > 0 already
    // implies norm > mu |tau_n| > 0.
    if (phi_tr <= 0.0 or !(norm > 0.0)) {
      for (std::size_t k = 0; k < td; ++k) {
        tt[k] = ttr[k];
        gp[k] = gtp[k];
        D[(1 + k) * nd + 1 + k] = 1.0 / eps_t;
      }
      state[p] = ContactState::stick;
      continue;
    }

    // Slip: radial return onto the cone |tau_t| = mu |tau_n| (Algorithm 1)
    const double dgamma = eps_t * phi_tr;
    const double c = bound / (eps_t * norm); // d tau_t / d g_t scaling
    std::array<double, 2> m{};
    for (std::size_t k = 0; k < td; ++k)
      m[k] = ttr[k] / norm;
    for (std::size_t k = 0; k < td; ++k) {
      tt[k] = bound * m[k];
      gp[k] = gtp[k] + dgamma * m[k];
      // d tau_t / d g_n: the cone radius grows with compression (d|tau_n|/dg_n = -1/eps_n)
      D[(1 + k) * nd] = -mu / eps_n * m[k];
      for (std::size_t l = 0; l < td; ++l)
        D[(1 + k) * nd + 1 + l] = c * ((k == l ? 1.0 : 0.0) - m[k] * m[l]);
    }
    state[p] = ContactState::slip;
  }
}
//-----------------------------------------------------------------------------
FrictionHistory::FrictionHistory(std::size_t n, int tdim) : _tdim(tdim) {
  if (tdim != 1 and tdim != 2) {
    throw std::invalid_argument("FrictionHistory: tdim must be 1 (2D) or 2 (3D), got " +
                                std::to_string(tdim));
  }
  _committed.assign(n * std::size_t(tdim), 0.0);
  _trial = _committed;
}
//-----------------------------------------------------------------------------
} // namespace contact
