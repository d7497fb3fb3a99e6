// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Unit tests of the penalty Coulomb return mapping (Algorithm 1), its consistent tangent,
// the friction history and the gap functions (eqs 26-31).
#include <algorithm>
#include <cmath>
#include <contact/gaps.h>
#include <contact/return_mapping.h>
#include <gtest/gtest.h>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

using contact::ContactState;
using contact::CoulombPenalty;

namespace {
constexpr double eps_mach = std::numeric_limits<double>::epsilon();

/// Outputs of one vectorised call, sized for n points.
struct Result {
  std::vector<double> tau_n, tau_t, gtp_trial, tangent;
  std::vector<ContactState> state;
};

Result run(const CoulombPenalty& law, int tdim, const std::vector<double>& g_n,
           const std::vector<double>& g_t, const std::vector<double>& gtp_old) {
  const std::size_t n = g_n.size(), td = tdim, nd = 1 + td;
  Result r{std::vector<double>(n), std::vector<double>(n * td), std::vector<double>(n * td),
           std::vector<double>(n * nd * nd), std::vector<ContactState>(n)};
  contact::return_mapping(law, tdim, g_n, g_t, gtp_old, r.tau_n, r.tau_t, r.gtp_trial, r.state,
                          r.tangent);
  return r;
}

/// Tangent entry d(tau)_row / d(g)_col of point p.
double D(const Result& r, int tdim, std::size_t p, int row, int col) {
  const std::size_t nd = 1 + tdim;
  return r.tangent[p * nd * nd + row * nd + col];
}

// Hand-computed cases use eps_n = 0.5, eps_t = 0.25, mu = 0.5: the inputs and expected values
// are short binary fractions or need one rounding, so 1e-14 absolute (values are O(1)) only
// allows for a few ulps.
constexpr CoulombPenalty hand_law{0.5, 0.25, 0.5};
constexpr double hand_tol = 1e-14;
} // namespace

//-----------------------------------------------------------------------------
TEST(ReturnMapping, OpenBranch) {
  for (int tdim : {1, 2}) {
    // g_n > 0 and exactly 0 are both open (active set is tau_n < 0, eq 32)
    const std::vector<double> g_n{0.5, 0.0};
    std::vector<double> g_t(2 * tdim), gtp(2 * tdim);
    for (int k = 0; k < 2 * tdim; ++k) {
      g_t[k] = 0.3 * (k + 1);
      gtp[k] = -0.7 + 0.1 * k;
    }
    const Result r = run(hand_law, tdim, g_n, g_t, gtp);
    for (std::size_t p = 0; p < 2; ++p) {
      EXPECT_EQ(r.state[p], ContactState::open);
      EXPECT_EQ(r.tau_n[p], 0.0);
    }
    for (int k = 0; k < 2 * tdim; ++k) {
      EXPECT_EQ(r.tau_t[k], 0.0);
      // History follows the gap so that re-contact starts without tangential traction
      EXPECT_EQ(r.gtp_trial[k], g_t[k]);
    }
    for (double d : r.tangent)
      EXPECT_EQ(d, 0.0);
  }
}

TEST(ReturnMapping, StickBranchTdim1) {
  // tau_n = -1/0.5 = -2, mu|tau_n| = 1, tau_tr = (0.3 - 0.1)/0.25 = 0.8 < 1
  const Result r = run(hand_law, 1, {-1.0}, {0.3}, {0.1});
  EXPECT_EQ(r.state[0], ContactState::stick);
  EXPECT_NEAR(r.tau_n[0], -2.0, hand_tol);
  EXPECT_NEAR(r.tau_t[0], 0.8, hand_tol);
  EXPECT_EQ(r.gtp_trial[0], 0.1);
  EXPECT_NEAR(D(r, 1, 0, 0, 0), 2.0, hand_tol);
  EXPECT_NEAR(D(r, 1, 0, 1, 1), 4.0, hand_tol);
  EXPECT_EQ(D(r, 1, 0, 0, 1), 0.0);
  EXPECT_EQ(D(r, 1, 0, 1, 0), 0.0);
}

TEST(ReturnMapping, SlipBranchTdim1) {
  // Point 0: tau_tr = (0.6 - 0.1)/0.25 = 2 > 1: phi_tr = 1, dgamma = 0.25, tau_t = 1,
  // gtp = 0.35. Point 1: tau_tr = -2 (opposite slip): tau_t = -1, gtp = 0.1 - 0.25.
  const Result r = run(hand_law, 1, {-1.0, -1.0}, {0.6, -0.4}, {0.1, 0.1});
  for (std::size_t p = 0; p < 2; ++p) {
    const double s = p == 0 ? 1.0 : -1.0;
    EXPECT_EQ(r.state[p], ContactState::slip);
    EXPECT_NEAR(r.tau_n[p], -2.0, hand_tol);
    EXPECT_NEAR(r.tau_t[p], s, hand_tol);
    EXPECT_NEAR(r.gtp_trial[p], 0.1 + s * 0.25, hand_tol);
    EXPECT_NEAR(D(r, 1, p, 0, 0), 2.0, hand_tol);
    EXPECT_EQ(D(r, 1, p, 0, 1), 0.0);
    // d tau_t/d g_n = -mu/eps_n m = -s; d tau_t/d g_t = 0 in 1D (I - m m^T = 0)
    EXPECT_NEAR(D(r, 1, p, 1, 0), -s, hand_tol);
    EXPECT_NEAR(D(r, 1, p, 1, 1), 0.0, hand_tol);
    // Non-symmetric tangent
    EXPECT_NE(D(r, 1, p, 1, 0), D(r, 1, p, 0, 1));
  }
}

TEST(ReturnMapping, StickBranchTdim2) {
  // tau_tr = (0.1, 0.05)/0.25 = (0.4, 0.2), |tau_tr| = 0.447 < mu|tau_n| = 1
  const Result r = run(hand_law, 2, {-1.0}, {0.1, 0.05}, {0.0, 0.0});
  EXPECT_EQ(r.state[0], ContactState::stick);
  EXPECT_NEAR(r.tau_n[0], -2.0, hand_tol);
  EXPECT_NEAR(r.tau_t[0], 0.4, hand_tol);
  EXPECT_NEAR(r.tau_t[1], 0.2, hand_tol);
  EXPECT_EQ(r.gtp_trial[0], 0.0);
  EXPECT_EQ(r.gtp_trial[1], 0.0);
  const double expected[3][3] = {{2, 0, 0}, {0, 4, 0}, {0, 0, 4}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(D(r, 2, 0, i, j), expected[i][j], hand_tol);
}

TEST(ReturnMapping, SlipBranchTdim2) {
  // gtp_old = (0.1, -0.2), g_t = gtp_old + 0.25 (3, 4): tau_tr = (3, 4), |tau_tr| = 5,
  // phi_tr = 5 - 1 = 4, m = (0.6, 0.8), tau_t = (0.6, 0.8), dgamma = 1,
  // gtp = (0.7, 0.6), d tau_t/d g_t = 1/(0.25*5) (I - m m^T) = 0.8 (I - m m^T).
  const Result r = run(hand_law, 2, {-1.0}, {0.85, 0.8}, {0.1, -0.2});
  EXPECT_EQ(r.state[0], ContactState::slip);
  EXPECT_NEAR(r.tau_n[0], -2.0, hand_tol);
  EXPECT_NEAR(r.tau_t[0], 0.6, hand_tol);
  EXPECT_NEAR(r.tau_t[1], 0.8, hand_tol);
  EXPECT_NEAR(r.gtp_trial[0], 0.7, hand_tol);
  EXPECT_NEAR(r.gtp_trial[1], 0.6, hand_tol);
  const double expected[3][3] = {
      {2, 0, 0}, {-0.6, 0.8 * 0.64, -0.8 * 0.48}, {-0.8, -0.8 * 0.48, 0.8 * 0.36}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(D(r, 2, 0, i, j), expected[i][j], hand_tol) << i << "," << j;
  EXPECT_NE(D(r, 2, 0, 1, 0), D(r, 2, 0, 0, 1));
  EXPECT_NE(D(r, 2, 0, 2, 0), D(r, 2, 0, 0, 2));
}

TEST(ReturnMapping, Frictionless) {
  // mu == 0: active points slip freely, tau_t = 0, all tangential gap is plastic
  const CoulombPenalty law{0.5, 0.25, 0.0};
  for (int tdim : {1, 2}) {
    std::vector<double> g_t(2 * tdim, 0.3), gtp(2 * tdim, 0.3);
    g_t[0] = 0.7; // point 0 with nonzero trial traction, point 1 with tau_tr == 0
    const Result r = run(law, tdim, {-1.0, -1.0}, g_t, gtp);
    const std::size_t nd = 1 + tdim;
    for (std::size_t p = 0; p < 2; ++p) {
      EXPECT_EQ(r.state[p], ContactState::slip);
      EXPECT_EQ(r.tau_n[p], -2.0);
      EXPECT_EQ(r.tangent[p * nd * nd], 2.0);
      for (std::size_t k = 1; k < nd * nd; ++k)
        EXPECT_EQ(r.tangent[p * nd * nd + k], 0.0);
    }
    for (int k = 0; k < 2 * tdim; ++k) {
      EXPECT_EQ(r.tau_t[k], 0.0);
      EXPECT_EQ(r.gtp_trial[k], g_t[k]);
    }
  }
}

TEST(ReturnMapping, InPlaceHistoryUpdate) {
  // gtp_trial may alias gtp_old: same result as with separate buffers
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int tdim : {1, 2}) {
    const std::size_t n = 100;
    std::vector<double> g_n(n), g_t(n * tdim), gtp(n * tdim);
    for (auto& v : g_n)
      v = U(rng);
    for (auto& v : g_t)
      v = U(rng);
    for (auto& v : gtp)
      v = U(rng);
    const Result ref = run(hand_law, tdim, g_n, g_t, gtp);
    Result r = ref;
    contact::return_mapping(hand_law, tdim, g_n, g_t, gtp, r.tau_n, r.tau_t, gtp, r.state,
                            r.tangent);
    EXPECT_EQ(gtp, ref.gtp_trial);
    EXPECT_EQ(r.tau_t, ref.tau_t);
    EXPECT_EQ(r.tangent, ref.tangent);
  }
}

//-----------------------------------------------------------------------------
namespace {
/// Random states of all three branches: laws with compliances over six decades, gaps scaled so
/// that |tau| = O(1) and slip and stick are both frequent.
struct RandomStates {
  CoulombPenalty law;
  std::vector<double> g_n, g_t, gtp;
};

/// The committed slip is 5 gtp_scale U(-1, 1), gtp_scale = eps_t when unset.
RandomStates random_states(std::mt19937_64& rng, int tdim, std::size_t n, bool frictional = true,
                           double gtp_scale = 0.0) {
  std::uniform_real_distribution<double> U(-1.0, 1.0), logU(-3.0, 3.0), muU(0.05, 1.5);
  RandomStates s{
      {std::pow(10.0, logU(rng)), std::pow(10.0, logU(rng)), frictional ? muU(rng) : 0.0},
      std::vector<double>(n),
      std::vector<double>(n * tdim),
      std::vector<double>(n * tdim)};
  for (std::size_t p = 0; p < n; ++p) {
    s.g_n[p] = s.law.eps_n * 2.0 * U(rng);
    for (int k = 0; k < tdim; ++k) {
      s.gtp[p * tdim + k] = 5.0 * (gtp_scale > 0 ? gtp_scale : s.law.eps_t) * U(rng);
      s.g_t[p * tdim + k] = s.gtp[p * tdim + k] + s.law.eps_t * 2.0 * U(rng);
    }
  }
  return s;
}
} // namespace

TEST(ReturnMapping, CoulombConeAndConsistency) {
  std::mt19937_64 rng(2026);
  for (int tdim : {1, 2}) {
    std::size_t counts[3] = {0, 0, 0};
    for (int batch = 0; batch < 50; ++batch) {
      const std::size_t n = 200;
      // Slip history O(1) independent of eps_t: stresses the cancellation in g_t - gtp
      const RandomStates s = random_states(rng, tdim, n, batch % 10 != 0, 1.0);
      const Result r = run(s.law, tdim, s.g_n, s.g_t, s.gtp);
      for (std::size_t p = 0; p < n; ++p) {
        ++counts[int(r.state[p])];
        double nt = 0.0;
        for (int k = 0; k < tdim; ++k)
          nt += r.tau_t[p * tdim + k] * r.tau_t[p * tdim + k];
        nt = std::sqrt(nt);
        const double bound = s.law.mu * std::abs(r.tau_n[p]);
        // Cone: the slip branch puts |tau_t| on the cone up to a few roundings of |m| = 1
        EXPECT_LE(nt, bound * (1 + 1e-14));
        if (r.state[p] == ContactState::slip) {
          // |m| = 1 to a few ulps, so equality holds to 1e-14 relative
          EXPECT_NEAR(nt, bound, 1e-14 * bound);
        }
        if (r.state[p] != ContactState::open) {
          EXPECT_LT(r.tau_n[p], 0.0);
        }
        for (int k = 0; k < tdim; ++k) {
          const std::size_t i = p * tdim + k;
          const double rebuilt = (s.g_t[i] - r.gtp_trial[i]) / s.law.eps_t;
          if (r.state[p] == ContactState::slip) {
            // gtp_old + dgamma m, g_t - gtp_trial and |tau_tr| each round at the magnitude of
            // g_t, gtp_old, gtp_trial (divided by eps_t in traction units): 8 ulps of their sum
            const double tol =
                8 * eps_mach *
                ((std::abs(s.g_t[i]) + std::abs(s.gtp[i]) + std::abs(r.gtp_trial[i])) /
                     s.law.eps_t +
                 std::abs(r.tau_t[i]));
            EXPECT_NEAR(r.tau_t[i], rebuilt, tol);
          } else // stick and open store the history so that the formula holds bitwise
            EXPECT_EQ(r.tau_t[i], rebuilt);
        }
      }
    }
    EXPECT_GT(counts[0], 500u);
    EXPECT_GT(counts[1], 500u);
    EXPECT_GT(counts[2], 500u);
  }
}

//-----------------------------------------------------------------------------
TEST(ReturnMapping, TangentMatchesFiniteDifferences) {
  std::mt19937_64 rng(42);
  for (int tdim : {1, 2}) {
    const std::size_t nd = 1 + tdim;
    std::size_t counts[3] = {0, 0, 0};
    std::size_t asymmetric = 0;
    for (int batch = 0; batch < 100 and std::ranges::min(counts) < 200; ++batch) {
      const std::size_t n = 50;
      const RandomStates s = random_states(rng, tdim, n);
      const CoulombPenalty& law = s.law;
      const Result r = run(law, tdim, s.g_n, s.g_t, s.gtp);
      for (std::size_t p = 0; p < n; ++p) {
        double ntr = 0.0; // |tau_tr|
        for (int k = 0; k < tdim; ++k) {
          const double t = (s.g_t[p * tdim + k] - s.gtp[p * tdim + k]) / law.eps_t;
          ntr += t * t;
        }
        ntr = std::sqrt(ntr);
        // Keep a margin from the kinks g_n = 0 and phi_tr = 0: 1e-3 in traction units is
        // >= 30 times the change of tau_n or phi_tr caused by the FD steps below
        if (std::abs(s.g_n[p]) < 1e-3 * law.eps_n)
          continue;
        if (r.state[p] != ContactState::open and
            std::abs(ntr - law.mu * std::abs(r.tau_n[p])) < 1e-3)
          continue;
        const int branch = int(r.state[p]);
        ++counts[branch];

        // FD steps. tau_n and the slip radius are linear in g_n: h_n = 1e-6 eps_n leaves only
        // roundoff, ~1e-10 relative. tau_t varies on the scale |tau_tr| in traction units
        // (h^2/|tau_tr|^2 truncation) and |g_t|/eps_t <= 7 gives ~1e-15 absolute roundoff
        // (1e-15/h): h = 1e-5 |tau_tr|^(2/3) balances both to <= 1e-8 relative for
        // |tau_tr| >= 1e-3 (the random slip history is O(eps_t) here for the same reason).
        const double h_n = 1e-6 * law.eps_n;
        const double h_t = 1e-5 * law.eps_t * std::cbrt(std::pow(std::max(ntr, 1e-3), 2));

        // Central differences column by column on a single-point copy
        std::vector<double> gn{s.g_n[p]};
        std::vector<double> gt(s.g_t.begin() + p * tdim, s.g_t.begin() + (p + 1) * tdim);
        std::vector<double> gp(s.gtp.begin() + p * tdim, s.gtp.begin() + (p + 1) * tdim);
        std::vector<double> fd(nd * nd);
        for (std::size_t col = 0; col < nd; ++col) {
          const double h = col == 0 ? h_n : h_t;
          double& x = col == 0 ? gn[0] : gt[col - 1];
          const double x0 = x;
          // Divide by the step actually taken after rounding x0 +- h
          const double xp = x0 + h, xm = x0 - h, dx = xp - xm;
          x = xp;
          const Result rp = run(law, tdim, gn, gt, gp);
          x = xm;
          const Result rm = run(law, tdim, gn, gt, gp);
          x = x0;
          ASSERT_EQ(rp.state[0], r.state[p]);
          ASSERT_EQ(rm.state[0], r.state[p]);
          fd[0 * nd + col] = (rp.tau_n[0] - rm.tau_n[0]) / dx;
          for (int k = 0; k < tdim; ++k)
            fd[(1 + k) * nd + col] = (rp.tau_t[k] - rm.tau_t[k]) / dx;
        }

        // 1e-6 relative to the magnitude of the block (nn, nt, tn, tt) holding the entry:
        // single entries such as c (1 - m_k^2) may vanish inside a nonzero block. Blocks
        // that are exactly zero (open; d tau_n/d g_t; tt in 1D slip) must have FD == 0.
        const double* Dp = r.tangent.data() + p * nd * nd;
        auto block = [&](std::size_t i, std::size_t j) {
          double m = 0.0;
          for (std::size_t a = 0; a < nd; ++a)
            for (std::size_t b = 0; b < nd; ++b)
              if ((a == 0) == (i == 0) and (b == 0) == (j == 0))
                m = std::max({m, std::abs(Dp[a * nd + b]), std::abs(fd[a * nd + b])});
          return m;
        };
        for (std::size_t i = 0; i < nd; ++i)
          for (std::size_t j = 0; j < nd; ++j)
            EXPECT_NEAR(Dp[i * nd + j], fd[i * nd + j], 1e-6 * block(i, j))
                << "branch " << branch << " tdim " << tdim << " entry " << i << "," << j;

        if (r.state[p] == ContactState::slip) {
          // d tau_t/d g_n = -mu/eps_n m has norm mu/eps_n while d tau_n/d g_t = 0;
          // |m| = 1 to a few ulps, hence 1e-12 relative
          double asym = 0.0;
          for (int k = 0; k < tdim; ++k) {
            const double a = D(r, tdim, p, 1 + k, 0) - D(r, tdim, p, 0, 1 + k);
            asym += a * a;
          }
          EXPECT_NEAR(std::sqrt(asym), law.mu / law.eps_n, 1e-12 * law.mu / law.eps_n);
          asymmetric += std::sqrt(asym) > 0.0;
        }
      }
    }
    EXPECT_GE(counts[0], 200u) << "open, tdim " << tdim;
    EXPECT_GE(counts[1], 200u) << "stick, tdim " << tdim;
    EXPECT_GE(counts[2], 200u) << "slip, tdim " << tdim;
    EXPECT_EQ(asymmetric, counts[2]);
  }
}

//-----------------------------------------------------------------------------
TEST(ReturnMapping, RejectsBadInputs) {
  const std::vector<double> g_n{-1.0, 0.5};
  const std::vector<double> g_t{0.1, 0.2}, gtp{0.0, 0.0};
  auto call = [&](const CoulombPenalty& law, int tdim, std::vector<double> gn,
                  std::vector<double> gt, std::vector<double> gp, std::size_t n_tn = 2,
                  std::size_t n_tt = 2, std::size_t n_gp = 2, std::size_t n_st = 2,
                  std::size_t n_D = 8) {
    std::vector<double> tn(n_tn), tt(n_tt), gpt(n_gp), Dm(n_D);
    std::vector<ContactState> st(n_st);
    contact::return_mapping(law, tdim, gn, gt, gp, tn, tt, gpt, st, Dm);
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_NO_THROW(call(hand_law, 1, g_n, g_t, gtp));
  EXPECT_THROW(call({0.0, 1.0, 0.5}, 1, g_n, g_t, gtp), std::invalid_argument);
  EXPECT_THROW(call({-1.0, 1.0, 0.5}, 1, g_n, g_t, gtp), std::invalid_argument);
  EXPECT_THROW(call({nan, 1.0, 0.5}, 1, g_n, g_t, gtp), std::invalid_argument);
  EXPECT_THROW(call({inf, 1.0, 0.5}, 1, g_n, g_t, gtp), std::invalid_argument);
  EXPECT_THROW(call({1.0, 0.0, 0.5}, 1, g_n, g_t, gtp), std::invalid_argument);
  EXPECT_THROW(call({1.0, -2.0, 0.5}, 1, g_n, g_t, gtp), std::invalid_argument);
  EXPECT_THROW(call({1.0, 1.0, -0.1}, 1, g_n, g_t, gtp), std::invalid_argument);
  EXPECT_THROW(call({1.0, 1.0, nan}, 1, g_n, g_t, gtp), std::invalid_argument);
  EXPECT_THROW(call({1.0, 1.0, inf}, 1, g_n, g_t, gtp), std::invalid_argument);
  EXPECT_THROW(call(hand_law, 1, {nan, 0.5}, g_t, gtp), std::invalid_argument);
  EXPECT_THROW(call(hand_law, 1, g_n, {0.1, nan}, gtp), std::invalid_argument);
  EXPECT_THROW(call(hand_law, 1, g_n, g_t, {inf, 0.0}), std::invalid_argument);
  // Size mismatches, one span at a time
  EXPECT_THROW(call(hand_law, 1, {-1.0}, g_t, gtp, 1, 2, 2, 1, 4), std::invalid_argument);
  EXPECT_THROW(call(hand_law, 1, g_n, {0.1}, gtp), std::invalid_argument);
  EXPECT_THROW(call(hand_law, 1, g_n, g_t, {0.0}), std::invalid_argument);
  EXPECT_THROW(call(hand_law, 1, g_n, g_t, gtp, 3), std::invalid_argument);
  EXPECT_THROW(call(hand_law, 1, g_n, g_t, gtp, 2, 1), std::invalid_argument);
  EXPECT_THROW(call(hand_law, 1, g_n, g_t, gtp, 2, 2, 4), std::invalid_argument);
  EXPECT_THROW(call(hand_law, 1, g_n, g_t, gtp, 2, 2, 2, 0), std::invalid_argument);
  EXPECT_THROW(call(hand_law, 1, g_n, g_t, gtp, 2, 2, 2, 2, 18), std::invalid_argument);
  // tdim: 2 makes the tdim = 1 sized spans inconsistent; 0 and 3 are unsupported
  EXPECT_THROW(call(hand_law, 2, g_n, g_t, gtp), std::invalid_argument);
  EXPECT_THROW(call(hand_law, 3, g_n, g_t, gtp), std::invalid_argument);
  EXPECT_THROW(call(hand_law, 0, g_n, g_t, gtp), std::invalid_argument);
  // n = 0 is valid and does nothing
  EXPECT_NO_THROW(call(hand_law, 2, {}, {}, {}, 0, 0, 0, 0, 0));
}

//-----------------------------------------------------------------------------
TEST(FrictionHistory, Construction) {
  const contact::FrictionHistory h(5, 2);
  EXPECT_EQ(h.size(), 5u);
  EXPECT_EQ(h.tdim(), 2);
  EXPECT_EQ(h.committed().size(), 10u);
  EXPECT_EQ(h.trial().size(), 10u);
  for (double v : h.committed())
    EXPECT_EQ(v, 0.0);
  for (double v : h.trial())
    EXPECT_EQ(v, 0.0);
  EXPECT_THROW(contact::FrictionHistory(5, 3), std::invalid_argument);
  EXPECT_THROW(contact::FrictionHistory(5, 0), std::invalid_argument);
  EXPECT_THROW(contact::FrictionHistory(5, -1), std::invalid_argument);
  EXPECT_NO_THROW(contact::FrictionHistory(0, 1));
}

namespace {
/// One Newton-iteration-like call that reads the committed slip and writes the trial slip.
Result step(const CoulombPenalty& law, contact::FrictionHistory& h, const std::vector<double>& g_n,
            const std::vector<double>& g_t) {
  const std::size_t n = h.size(), td = h.tdim(), nd = 1 + td;
  Result r{std::vector<double>(n),
           std::vector<double>(n * td),
           {},
           std::vector<double>(n * nd * nd),
           std::vector<ContactState>(n)};
  contact::return_mapping(law, h.tdim(), g_n, g_t, h.committed(), r.tau_n, r.tau_t, h.trial(),
                          r.state, r.tangent);
  r.gtp_trial.assign(h.trial().begin(), h.trial().end());
  return r;
}
} // namespace

TEST(FrictionHistory, TrialCommitRestore) {
  for (int tdim : {1, 2}) {
    std::mt19937_64 rng(11 + tdim);
    const std::size_t n = 300;
    const RandomStates s = random_states(rng, tdim, n);
    contact::FrictionHistory h(n, tdim);
    std::ranges::copy(s.gtp, h.trial().begin());
    h.commit();
    const std::vector<double> c0(h.committed().begin(), h.committed().end());
    EXPECT_EQ(c0, s.gtp);

    // Trial values are written, committed ones untouched
    const Result r = step(s.law, h, s.g_n, s.g_t);
    const Result ref = run(s.law, tdim, s.g_n, s.g_t, s.gtp);
    EXPECT_EQ(r.gtp_trial, ref.gtp_trial);
    EXPECT_EQ(std::vector<double>(h.committed().begin(), h.committed().end()), c0);
    EXPECT_TRUE(std::ranges::any_of(r.state, [](auto st) { return st == ContactState::slip; }));
    EXPECT_NE(std::vector<double>(h.trial().begin(), h.trial().end()), c0);

    // restore() returns the committed values exactly
    h.restore();
    for (std::size_t i = 0; i < n * tdim; ++i)
      EXPECT_EQ(h.trial()[i], c0[i]);

    // commit() accepts the trial values exactly
    step(s.law, h, s.g_n, s.g_t);
    h.commit();
    for (std::size_t i = 0; i < n * tdim; ++i) {
      EXPECT_EQ(h.committed()[i], ref.gtp_trial[i]);
      EXPECT_EQ(h.trial()[i], ref.gtp_trial[i]);
    }
  }
}

TEST(FrictionHistory, RejectedStepLeavesNoTrace) {
  for (int tdim : {1, 2}) {
    std::mt19937_64 rng(99 + tdim);
    const std::size_t n = 300;
    const RandomStates s1 = random_states(rng, tdim, n);
    RandomStates bad = random_states(rng, tdim, n);
    for (auto& v : bad.g_t)
      v *= 50.0; // a diverged iterate: large slips everywhere
    RandomStates s2 = random_states(rng, tdim, n);
    const CoulombPenalty law = s1.law;

    contact::FrictionHistory a(n, tdim), b(n, tdim);
    // Step 1, accepted by both
    step(law, a, s1.g_n, s1.g_t);
    a.commit();
    step(law, b, s1.g_n, s1.g_t);
    b.commit();
    // a sees a rejected step (two iterations, then cut back)
    step(law, a, bad.g_n, bad.g_t);
    step(law, a, s2.g_n, bad.g_t);
    a.restore();
    // Step 2 on both: bitwise identical
    const Result ra = step(law, a, s2.g_n, s2.g_t);
    const Result rb = step(law, b, s2.g_n, s2.g_t);
    EXPECT_EQ(ra.tau_n, rb.tau_n);
    EXPECT_EQ(ra.tau_t, rb.tau_t);
    EXPECT_EQ(ra.gtp_trial, rb.gtp_trial);
    EXPECT_EQ(ra.tangent, rb.tangent);
    EXPECT_EQ(ra.state, rb.state);
    a.commit();
    b.commit();
    for (std::size_t i = 0; i < n * tdim; ++i)
      EXPECT_EQ(a.committed()[i], b.committed()[i]);
  }
}

//-----------------------------------------------------------------------------
TEST(Gaps, AxisAlignedHandValues) {
  // Body i below, body j above, n = +y (from i towards j), t = (-1, 0) (n rotated by +90 deg)
  // P_j - P_i = (0.25, 0.5): g_n0 = 0.5; u_j - u_i = (0.5, -0.75): j_int = -0.75,
  // g_n = -0.25 (penetration), g_t = -0.5. All values exact in binary.
  const std::vector<double> p_i{1.0, 2.0}, p_j{1.25, 2.5}, u_i{0.25, 0.5}, u_j{0.75, -0.25},
      nrm{0.0, 1.0}, tng{-1.0, 0.0};
  std::vector<double> g_n0(1), j_int(1), g_n(1), g_t(1);
  contact::compute_gaps(p_i, p_j, u_i, u_j, nrm, tng, g_n0, j_int, g_n, g_t);
  EXPECT_EQ(g_n0[0], 0.5);
  EXPECT_EQ(j_int[0], -0.75);
  EXPECT_EQ(g_n[0], -0.25);
  EXPECT_EQ(g_t[0], -0.5);
}

TEST(Gaps, RotatedFrames) {
  // Build P_j - P_i = a n + b t and u_j - u_i = c n + d t in frames rotated by theta; then
  // g_n0 = a, j_int = c, g_t = d. Inputs are O(10), so 1e-13 absolute is a few ulps of
  // the products and sums.
  const std::size_t n = 12;
  std::vector<double> p_i(2 * n), p_j(2 * n), u_i(2 * n), u_j(2 * n), nrm(2 * n), tng(2 * n);
  std::vector<double> a(n), c(n), d(n);
  for (std::size_t p = 0; p < n; ++p) {
    const double th = 2 * std::numbers::pi * double(p) / n + 0.1;
    const double nx = std::cos(th), ny = std::sin(th), tx = -ny, ty = nx;
    a[p] = 0.1 * (double(p) - 5.0);
    const double b = 0.3 - 0.05 * double(p);
    c[p] = -0.02 * double(p) + 0.07;
    d[p] = 0.011 * double(p * p) - 0.4;
    nrm[2 * p] = nx;
    nrm[2 * p + 1] = ny;
    tng[2 * p] = tx;
    tng[2 * p + 1] = ty;
    p_i[2 * p] = 3.0 + p;
    p_i[2 * p + 1] = -2.0 + 0.5 * p;
    p_j[2 * p] = p_i[2 * p] + a[p] * nx + b * tx;
    p_j[2 * p + 1] = p_i[2 * p + 1] + a[p] * ny + b * ty;
    u_i[2 * p] = 0.01 * p;
    u_i[2 * p + 1] = -0.02 * p;
    u_j[2 * p] = u_i[2 * p] + c[p] * nx + d[p] * tx;
    u_j[2 * p + 1] = u_i[2 * p + 1] + c[p] * ny + d[p] * ty;
  }
  std::vector<double> g_n0(n), j_int(n), g_n(n), g_t(n);
  contact::compute_gaps(p_i, p_j, u_i, u_j, nrm, tng, g_n0, j_int, g_n, g_t);
  for (std::size_t p = 0; p < n; ++p) {
    EXPECT_NEAR(g_n0[p], a[p], 1e-13);
    EXPECT_NEAR(j_int[p], c[p], 1e-13);
    EXPECT_NEAR(g_n[p], a[p] + c[p], 1e-13);
    EXPECT_EQ(g_n[p], g_n0[p] + j_int[p]);
    EXPECT_NEAR(g_t[p], d[p], 1e-13);
  }
}

TEST(Gaps, RejectsSizeMismatch) {
  const std::vector<double> two{0.0, 0.0}, three{0.0, 0.0, 0.0};
  std::vector<double> one(1), zero;
  auto call = [&](const std::vector<double>& pi, const std::vector<double>& pj,
                  const std::vector<double>& nrm, std::vector<double>& gn0,
                  std::vector<double>& gt) {
    std::vector<double> ji(1), gn(1);
    contact::compute_gaps(pi, pj, two, two, nrm, two, gn0, ji, gn, gt);
  };
  EXPECT_NO_THROW(call(two, two, two, one, one));
  EXPECT_THROW(call(three, two, two, one, one), std::invalid_argument);
  EXPECT_THROW(call(two, three, two, one, one), std::invalid_argument);
  EXPECT_THROW(call(two, two, three, one, one), std::invalid_argument);
  EXPECT_THROW(call(two, two, two, zero, one), std::invalid_argument);
  EXPECT_THROW(call(two, two, two, one, zero), std::invalid_argument);
}
