// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "contact_kernel.h"
#include "gaps.h"
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace contact {
namespace {
void check(std::size_t size, std::size_t expected, const char* name) {
  if (size != expected) {
    throw std::invalid_argument(std::string("ContactQuadrature: ") + name + " has size " +
                                std::to_string(size) + ", expected " + std::to_string(expected));
  }
}

/// Signed basis values [-N_i, N_j] and block dofs of point p.
void point_basis(const ContactQuadrature& q, std::size_t p, std::span<std::int32_t> dofs,
                 std::span<double> N) {
  const std::size_t ni = q.nodes_i, nj = q.nodes_j;
  for (std::size_t a = 0; a < ni; ++a) {
    dofs[a] = q.dofs_i[p * ni + a];
    N[a] = -q.basis_i[p * ni + a];
  }
  for (std::size_t a = 0; a < nj; ++a) {
    dofs[ni + a] = q.dofs_j[p * nj + a];
    N[ni + a] = q.basis_j[p * nj + a];
  }
}

/// Tractions and their derivative at one point: frictionless shortcut or Algorithm 1.
/// D is row-major 2x2 d[tau_n, tau_t]/d[g_n, g_t].
void point_law(const CoulombPenalty& law, double g_n, double g_t, double gtp_old, double& tau_n,
               double& tau_t, double& gtp, ContactState& state, std::array<double, 4>& D) {
  if (law.mu == 0.0) {
    D = {0.0, 0.0, 0.0, 0.0};
    tau_t = 0.0;
    gtp = g_t;
    if (g_n < 0.0) {
      tau_n = g_n / law.eps_n;
      D[0] = 1.0 / law.eps_n;
      state = ContactState::slip; // the convention of return_mapping for mu = 0
    } else {
      tau_n = 0.0;
      state = ContactState::open;
    }
    return;
  }
  return_mapping(law, 1, {&g_n, 1}, {&g_t, 1}, {&gtp_old, 1}, {&tau_n, 1}, {&tau_t, 1}, {&gtp, 1},
                 {&state, 1}, D);
}
} // namespace

//-----------------------------------------------------------------------------
void ContactQuadrature::validate() const {
  if (nodes_i <= 0 or nodes_j < 0)
    throw std::invalid_argument("ContactQuadrature: need nodes_i > 0 and nodes_j >= 0");
  const std::size_t nq = weights.size();
  check(normals.size(), 2 * nq, "normals");
  check(tangents.size(), 2 * nq, "tangents");
  check(g_n0.size(), nq, "g_n0");
  check(dofs_i.size(), nq * nodes_i, "dofs_i");
  check(dofs_j.size(), nq * nodes_j, "dofs_j");
  check(basis_i.size(), nq * nodes_i, "basis_i");
  check(basis_j.size(), nq * nodes_j, "basis_j");
  if (!u_j_prescribed.empty())
    check(u_j_prescribed.size(), 2 * nq, "u_j_prescribed");
}

//-----------------------------------------------------------------------------
std::vector<std::int32_t> coupling_dofs(const ContactQuadrature& q) {
  q.validate();
  const std::size_t nd = q.nodes_i + q.nodes_j;
  std::vector<std::int32_t> dofs(q.size() * nd);
  std::vector<double> N(nd);
  for (std::size_t p = 0; p < q.size(); ++p)
    point_basis(q, p, std::span(dofs).subspan(p * nd, nd), N);
  return dofs;
}

//-----------------------------------------------------------------------------
ContactPointState assemble_contact(const ContactQuadrature& q, const CoulombPenalty& law,
                                   std::span<const double> u, std::span<const double> gtp_old,
                                   std::span<double> b, const BlockInserter& insert,
                                   TangentMode mode, double fd_step, double closed_gap) {
  q.validate();
  if (!(law.eps_n > 0) or !(law.eps_t > 0) or !(law.mu >= 0) or !std::isfinite(law.mu))
    throw std::invalid_argument("assemble_contact: need eps_n > 0, eps_t > 0, finite mu >= 0");
  const bool friction = law.mu > 0.0;
  const std::size_t nq = q.size();
  if (friction and gtp_old.size() != nq)
    throw std::invalid_argument("assemble_contact: gtp_old must have one value per point");
  if (!b.empty() and b.size() != u.size())
    throw std::invalid_argument("assemble_contact: b must have the size of u");
  if (mode == TangentMode::finite_difference and !(fd_step > 0))
    throw std::invalid_argument("assemble_contact: fd_step must be > 0");

  const std::size_t nd = q.nodes_i + q.nodes_j, ne = 2 * nd;
  ContactPointState s;
  s.g_n.resize(nq);
  s.g_t.resize(nq);
  s.tau_n.resize(nq);
  s.tau_t.resize(nq);
  s.state.resize(nq);
  if (friction)
    s.gtp_trial.resize(nq);

  std::vector<std::int32_t> dofs(nd);
  std::vector<double> N(nd), Bn(ne), Bt(ne), Ke(ne * ne), rp(ne), rm(ne);
  for (std::size_t p = 0; p < nq; ++p) {
    point_basis(q, p, dofs, N);
    const double* n = &q.normals[2 * p];
    const double* t = &q.tangents[2 * p];
    // B rows: jump of u projected on n and t
    for (std::size_t a = 0; a < nd; ++a) {
      for (std::size_t c = 0; c < 2; ++c) {
        Bn[2 * a + c] = N[a] * n[c];
        Bt[2 * a + c] = N[a] * t[c];
      }
    }
    // Displacement jump u_j(P_j) - u_i(P_i) (eq 26) and the gaps (eqs 27-30)
    std::array<double, 2> du = {0.0, 0.0};
    for (std::size_t a = 0; a < nd; ++a)
      for (std::size_t c = 0; c < 2; ++c)
        du[c] += N[a] * u[2 * std::size_t(dofs[a]) + c];
    if (!q.u_j_prescribed.empty())
      for (std::size_t c = 0; c < 2; ++c)
        du[c] += q.u_j_prescribed[2 * p + c];
    const PointGaps gaps = point_gaps(q.g_n0[p], du, std::span<const double, 2>(n, 2),
                                      std::span<const double, 2>(t, 2));
    const double gtp0 = friction ? gtp_old[p] : 0.0;
    const double w = q.weights[p];
    double gtp = 0.0;
    std::array<double, 4> D;
    s.g_n[p] = gaps.g_n;
    s.g_t[p] = gaps.g_t;
    point_law(law, s.g_n[p], s.g_t[p], gtp0, s.tau_n[p], s.tau_t[p], gtp, s.state[p], D);
    if (friction)
      s.gtp_trial[p] = gtp;
    bool predictor = false;
    if (s.state[p] == ContactState::open) {
      // A touching point (0 <= g_n < closed_gap) lends the tangent of a closed, sticking point
      // (no traction): the predictor of a step whose bodies are held by contacts not yet closed
      if (!insert or !(s.g_n[p] < closed_gap))
        continue;
      predictor = true;
      D = {1.0 / law.eps_n, 0.0, 0.0, friction ? 1.0 / law.eps_t : 0.0};
    } else if (closed_gap > 0 and s.state[p] == ContactState::slip and friction) {
      // ... and in that predictor a slipping point sticks: a grain whose contacts all slip
      // has no tangential stiffness in its first iterate (the residual stays exact)
      D = {1.0 / law.eps_n, 0.0, 0.0, 1.0 / law.eps_t};
    }

    if (!b.empty() and !predictor) {
      for (std::size_t a = 0; a < nd; ++a)
        for (std::size_t c = 0; c < 2; ++c)
          b[2 * std::size_t(dofs[a]) + c] +=
              w * (Bn[2 * a + c] * s.tau_n[p] + Bt[2 * a + c] * s.tau_t[p]);
    }
    if (!insert)
      continue;

    if (mode == TangentMode::exact or predictor) {
      // K = w B^T D B with B = [Bn; Bt]
      for (std::size_t r = 0; r < ne; ++r) {
        const double dn = w * (Bn[r] * D[0] + Bt[r] * D[2]);
        const double dt = w * (Bn[r] * D[1] + Bt[r] * D[3]);
        for (std::size_t c = 0; c < ne; ++c)
          Ke[r * ne + c] = dn * Bn[c] + dt * Bt[c];
      }
    } else {
      // Central differences of the point residual r(u_e) = w B^T tau(g(u_e)), column by column
      auto residual = [&](double djn, double djt, std::span<double> r) {
        double tn, tt, gp;
        ContactState st;
        std::array<double, 4> Dp;
        point_law(law, s.g_n[p] + djn, s.g_t[p] + djt, gtp0, tn, tt, gp, st, Dp);
        for (std::size_t k = 0; k < ne; ++k)
          r[k] = w * (Bn[k] * tn + Bt[k] * tt);
      };
      for (std::size_t c = 0; c < ne; ++c) {
        residual(Bn[c] * fd_step, Bt[c] * fd_step, rp);
        residual(-Bn[c] * fd_step, -Bt[c] * fd_step, rm);
        for (std::size_t r = 0; r < ne; ++r)
          Ke[r * ne + c] = (rp[r] - rm[r]) / (2.0 * fd_step);
      }
    }
    insert(dofs, Ke);
  }
  return s;
}

} // namespace contact
