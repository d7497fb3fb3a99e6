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
  if (!mult_nodes.empty() or !mult_weights.empty()) {
    check(mult_nodes.size(), 2 * nq, "mult_nodes");
    check(mult_weights.size(), 2 * nq, "mult_weights");
    for (std::size_t p = 0; p < nq; ++p) {
      if (mult_nodes[2 * p] < 0)
        throw std::invalid_argument("ContactQuadrature: every point needs a first node");
      const double w0 = mult_weights[2 * p];
      const double w1 = mult_nodes[2 * p + 1] < 0 ? 0.0 : mult_weights[2 * p + 1];
      if (!(w0 >= 0) or !(w1 >= 0) or std::abs(w0 + w1 - 1.0) > 1e-12)
        throw std::invalid_argument("ContactQuadrature: a point's node weights must be >= 0 "
                                    "and sum to 1");
    }
  }
}

//-----------------------------------------------------------------------------
std::size_t ContactQuadrature::num_law_points() const {
  if (mult_nodes.empty())
    return size();
  return std::size_t(*std::max_element(mult_nodes.begin(), mult_nodes.end()) + 1);
}

//-----------------------------------------------------------------------------
ContactQuadrature::LawPoints ContactQuadrature::law_points() const {
  const std::size_t nq = size(), na = num_law_points();
  LawPoints lp;
  lp.offsets.assign(na + 1, 0);
  if (mult_nodes.empty()) {
    for (std::size_t p = 0; p < nq; ++p) {
      lp.offsets[p + 1] = p + 1;
      lp.points.push_back(std::int32_t(p));
      lp.psi.push_back(1.0);
    }
    return lp;
  }
  // counting sort of the (node, point) entries with a positive weight
  for (std::size_t k = 0; k < 2 * nq; ++k)
    if (mult_nodes[k] >= 0 and mult_weights[k] > 0)
      ++lp.offsets[std::size_t(mult_nodes[k]) + 1];
  for (std::size_t a = 0; a < na; ++a)
    lp.offsets[a + 1] += lp.offsets[a];
  lp.points.resize(lp.offsets[na]);
  lp.psi.resize(lp.offsets[na]);
  std::vector<std::size_t> next(lp.offsets.begin(), lp.offsets.end() - 1);
  for (std::size_t k = 0; k < 2 * nq; ++k) {
    if (mult_nodes[k] >= 0 and mult_weights[k] > 0) {
      const std::size_t j = next[std::size_t(mult_nodes[k])]++;
      lp.points[j] = std::int32_t(k / 2);
      lp.psi[j] = mult_weights[k];
    }
  }
  return lp;
}

namespace {
/// Block dofs of the points of law point a without repeats, and each entry's positions in that
/// list (nd per entry).
void law_point_dofs(const ContactQuadrature& q, const ContactQuadrature::LawPoints& lp,
                    std::size_t a, std::vector<std::int32_t>& sdofs,
                    std::vector<std::size_t>& where) {
  const std::size_t nd = q.nodes_i + q.nodes_j;
  std::vector<std::int32_t> dofs(nd);
  std::vector<double> N(nd);
  sdofs.clear();
  const std::size_t k0 = lp.offsets[a], k1 = lp.offsets[a + 1];
  where.resize((k1 - k0) * nd);
  for (std::size_t k = k0; k < k1; ++k) {
    point_basis(q, std::size_t(lp.points[k]), dofs, N);
    for (std::size_t i = 0; i < nd; ++i) {
      auto it = std::find(sdofs.begin(), sdofs.end(), dofs[i]);
      where[(k - k0) * nd + i] = std::size_t(it - sdofs.begin());
      if (it == sdofs.end())
        sdofs.push_back(dofs[i]);
    }
  }
}
} // namespace

//-----------------------------------------------------------------------------
CouplingBlocks coupling_dofs(const ContactQuadrature& q) {
  q.validate();
  const ContactQuadrature::LawPoints lp = q.law_points();
  CouplingBlocks blocks;
  blocks.offsets = {0};
  std::vector<std::int32_t> sdofs;
  std::vector<std::size_t> where;
  for (std::size_t a = 0; a + 1 < lp.offsets.size(); ++a) {
    law_point_dofs(q, lp, a, sdofs, where);
    blocks.dofs.insert(blocks.dofs.end(), sdofs.begin(), sdofs.end());
    blocks.offsets.push_back(blocks.dofs.size());
  }
  return blocks;
}

//-----------------------------------------------------------------------------
ContactPointState assemble_contact(const ContactQuadrature& q, const CoulombPenalty& law,
                                   std::span<const double> u, std::span<const double> gtp_old,
                                   std::span<double> b, const BlockInserter& insert,
                                   TangentMode mode, double fd_step, double closed_gap,
                                   std::span<const double> g_n_shift) {
  q.validate();
  if (!(law.eps_n > 0) or !(law.eps_t > 0) or !(law.mu >= 0) or !std::isfinite(law.mu))
    throw std::invalid_argument("assemble_contact: need eps_n > 0, eps_t > 0, finite mu >= 0");
  const bool friction = law.mu > 0.0;
  const std::size_t nq = q.size(), na = q.num_law_points();
  if (friction and gtp_old.size() != na)
    throw std::invalid_argument("assemble_contact: gtp_old must have one value per law point");
  if (!g_n_shift.empty() and g_n_shift.size() != na)
    throw std::invalid_argument("assemble_contact: g_n_shift must be empty or one per law point");
  if (!b.empty() and b.size() != u.size())
    throw std::invalid_argument("assemble_contact: b must have the size of u");
  if (mode == TangentMode::finite_difference and !(fd_step > 0))
    throw std::invalid_argument("assemble_contact: fd_step must be > 0");

  const std::size_t nd = q.nodes_i + q.nodes_j;
  ContactPointState s;
  s.g_n.resize(nq);
  s.g_t.resize(nq);
  s.tau_n.assign(nq, 0.0);
  s.tau_t.assign(nq, 0.0);
  s.state.assign(nq, ContactState::open);
  s.law_g_n.resize(na);
  s.law_g_t.resize(na);
  s.law_tau_n.resize(na);
  s.law_tau_t.resize(na);
  s.law_state.resize(na);
  s.law_coupled.assign(na, 0);
  if (friction)
    s.gtp_trial.resize(na);

  // The points' gaps (eq 26: the jump u_j(P_j) - u_i(P_i); eqs 27-30)
  std::vector<std::int32_t> dofs(nd), sdofs;
  std::vector<std::size_t> where;
  std::vector<double> N(nd), bn, bt, Ke, rp, rm;
  for (std::size_t p = 0; p < nq; ++p) {
    point_basis(q, p, dofs, N);
    std::array<double, 2> du = {0.0, 0.0};
    for (std::size_t i = 0; i < nd; ++i)
      for (std::size_t c = 0; c < 2; ++c)
        du[c] += N[i] * u[2 * std::size_t(dofs[i]) + c];
    if (!q.u_j_prescribed.empty())
      for (std::size_t c = 0; c < 2; ++c)
        du[c] += q.u_j_prescribed[2 * p + c];
    const PointGaps gaps =
        point_gaps(q.g_n0[p], du, std::span<const double, 2>(&q.normals[2 * p], 2),
                   std::span<const double, 2>(&q.tangents[2 * p], 2));
    s.g_n[p] = gaps.g_n;
    s.g_t[p] = gaps.g_t;
  }

  const ContactQuadrature::LawPoints lp = q.law_points();
  std::vector<double> heaviest(nq, -1.0); // the largest psi seen per point (its state's node)
  for (std::size_t a = 0; a < na; ++a) {
    const std::size_t k0 = lp.offsets[a], k1 = lp.offsets[a + 1];
    if (k0 == k1)
      throw std::invalid_argument("assemble_contact: multiplier node " + std::to_string(a) +
                                  " has no points");
    law_point_dofs(q, lp, a, sdofs, where);
    const std::size_t ne = 2 * sdofs.size();
    bn.assign(ne, 0.0);
    bt.assign(ne, 0.0);
    // b_n = sum_p w_p psi_p B_n,p and b_t likewise (B rows: the jump projected on n and t), and
    // the weighted sums of the points' gaps
    double W = 0.0, wgn = 0.0, wgt = 0.0;
    for (std::size_t k = k0; k < k1; ++k) {
      const std::size_t p = std::size_t(lp.points[k]);
      point_basis(q, p, dofs, N);
      const double* n = &q.normals[2 * p];
      const double* t = &q.tangents[2 * p];
      const double w = q.weights[p] * lp.psi[k];
      for (std::size_t i = 0; i < nd; ++i) {
        const std::size_t j = where[(k - k0) * nd + i];
        for (std::size_t c = 0; c < 2; ++c) {
          bn[2 * j + c] += w * N[i] * n[c];
          bt[2 * j + c] += w * N[i] * t[c];
        }
      }
      W += w;
      wgn += w * s.g_n[p];
      wgt += w * s.g_t[p];
    }
    // the law on the mean gaps (a single point of weight 1: its own, exactly)
    const std::size_t p0 = std::size_t(lp.points[k0]);
    const bool single = k1 - k0 == 1 and lp.psi[k0] == 1.0;
    s.law_g_n[a] = single ? s.g_n[p0] : wgn / W;
    s.law_g_t[a] = single ? s.g_t[p0] : wgt / W;
    const double gn = s.law_g_n[a] + (g_n_shift.empty() ? 0.0 : g_n_shift[a]);
    const double gt = s.law_g_t[a];
    const double gtp0 = friction ? gtp_old[a] : 0.0;
    double tau_n, tau_t, gtp = 0.0;
    ContactState state;
    std::array<double, 4> D;
    point_law(law, gn, gt, gtp0, tau_n, tau_t, gtp, state, D);
    s.law_tau_n[a] = tau_n;
    s.law_tau_t[a] = tau_t;
    s.law_state[a] = state;
    if (friction)
      s.gtp_trial[a] = gtp;
    for (std::size_t k = k0; k < k1; ++k) {
      const std::size_t p = std::size_t(lp.points[k]);
      s.tau_n[p] += lp.psi[k] * tau_n;
      s.tau_t[p] += lp.psi[k] * tau_t;
      if (lp.psi[k] > heaviest[p]) {
        heaviest[p] = lp.psi[k];
        s.state[p] = state;
      }
    }
    bool predictor = false;
    if (state == ContactState::open) {
      // A touching node (0 <= g_n < closed_gap) lends the tangent of a closed, sticking one
      // (no traction): the predictor of a step whose bodies are held by contacts not yet closed
      if (!insert or !(gn < closed_gap))
        continue;
      predictor = true;
      D = {1.0 / law.eps_n, 0.0, 0.0, friction ? 1.0 / law.eps_t : 0.0};
    } else if (closed_gap > 0 and state == ContactState::slip and friction) {
      // ... and in that predictor a slipping node sticks: a grain whose contacts all slip
      // has no tangential stiffness in its first iterate (the residual stays exact)
      D = {1.0 / law.eps_n, 0.0, 0.0, 1.0 / law.eps_t};
    }

    if (!b.empty() and !predictor) {
      for (std::size_t j = 0; j < sdofs.size(); ++j)
        for (std::size_t c = 0; c < 2; ++c)
          b[2 * std::size_t(sdofs[j]) + c] += bn[2 * j + c] * tau_n + bt[2 * j + c] * tau_t;
    }
    if (!insert)
      continue;

    Ke.assign(ne * ne, 0.0);
    if (mode == TangentMode::exact or predictor) {
      // K = (1/W) [b_n b_t] D [b_n b_t]^T: d gbar / du = b / W
      for (std::size_t r = 0; r < ne; ++r) {
        const double dn = (bn[r] * D[0] + bt[r] * D[2]) / W;
        const double dt = (bn[r] * D[1] + bt[r] * D[3]) / W;
        for (std::size_t c = 0; c < ne; ++c)
          Ke[r * ne + c] = dn * bn[c] + dt * bt[c];
      }
    } else {
      // Central differences of the law point's residual r(u_e) = [b_n b_t] tau(gbar(u_e))
      rp.resize(ne);
      rm.resize(ne);
      auto residual = [&](double djn, double djt, std::span<double> r) {
        double tn, tt, gp;
        ContactState st;
        std::array<double, 4> Dp;
        point_law(law, gn + djn, gt + djt, gtp0, tn, tt, gp, st, Dp);
        for (std::size_t k = 0; k < ne; ++k)
          r[k] = bn[k] * tn + bt[k] * tt;
      };
      for (std::size_t c = 0; c < ne; ++c) {
        residual(bn[c] / W * fd_step, bt[c] / W * fd_step, rp);
        residual(-bn[c] / W * fd_step, -bt[c] / W * fd_step, rm);
        for (std::size_t r = 0; r < ne; ++r)
          Ke[r * ne + c] = (rp[r] - rm[r]) / (2.0 * fd_step);
      }
    }
    insert(sdofs, Ke);
    s.law_coupled[a] = 1;
  }
  return s;
}

} // namespace contact
