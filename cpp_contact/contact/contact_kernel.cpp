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
  if (!segments.empty()) {
    check(segments.size(), nq, "segments");
    if (!std::is_sorted(segments.begin(), segments.end()))
      throw std::invalid_argument("ContactQuadrature: segments must be non-decreasing");
  }
}

//-----------------------------------------------------------------------------
std::vector<std::size_t> ContactQuadrature::segment_offsets() const {
  std::vector<std::size_t> offsets = {0};
  for (std::size_t p = 1; p <= size(); ++p)
    if (segments.empty() or p == size() or segments[p] != segments[p - 1])
      offsets.push_back(p);
  if (size() == 0)
    offsets.resize(1);
  return offsets;
}

namespace {
/// Block dofs of the points [p0, p1) without repeats, and each point's positions in that list
/// (nd per point).
void segment_dofs(const ContactQuadrature& q, std::size_t p0, std::size_t p1,
                  std::vector<std::int32_t>& sdofs, std::vector<std::size_t>& where) {
  const std::size_t nd = q.nodes_i + q.nodes_j;
  std::vector<std::int32_t> dofs(nd);
  std::vector<double> N(nd);
  sdofs.clear();
  where.resize((p1 - p0) * nd);
  for (std::size_t p = p0; p < p1; ++p) {
    point_basis(q, p, dofs, N);
    for (std::size_t a = 0; a < nd; ++a) {
      auto it = std::find(sdofs.begin(), sdofs.end(), dofs[a]);
      where[(p - p0) * nd + a] = std::size_t(it - sdofs.begin());
      if (it == sdofs.end())
        sdofs.push_back(dofs[a]);
    }
  }
}
} // namespace

//-----------------------------------------------------------------------------
CouplingBlocks coupling_dofs(const ContactQuadrature& q) {
  q.validate();
  const std::vector<std::size_t> offsets = q.segment_offsets();
  CouplingBlocks blocks;
  blocks.offsets = {0};
  std::vector<std::int32_t> sdofs;
  std::vector<std::size_t> where;
  for (std::size_t s = 0; s + 1 < offsets.size(); ++s) {
    segment_dofs(q, offsets[s], offsets[s + 1], sdofs, where);
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
  const std::size_t nq = q.size();
  if (friction and gtp_old.size() != nq)
    throw std::invalid_argument("assemble_contact: gtp_old must have one value per point");
  if (!g_n_shift.empty() and g_n_shift.size() != nq)
    throw std::invalid_argument("assemble_contact: g_n_shift must be empty or one per point");
  if (!b.empty() and b.size() != u.size())
    throw std::invalid_argument("assemble_contact: b must have the size of u");
  if (mode == TangentMode::finite_difference and !(fd_step > 0))
    throw std::invalid_argument("assemble_contact: fd_step must be > 0");

  const std::size_t nd = q.nodes_i + q.nodes_j;
  ContactPointState s;
  s.g_n.resize(nq);
  s.g_t.resize(nq);
  s.tau_n.resize(nq);
  s.tau_t.resize(nq);
  s.state.resize(nq);
  if (friction)
    s.gtp_trial.resize(nq);

  const std::vector<std::size_t> offsets = q.segment_offsets();
  std::vector<std::int32_t> dofs(nd), sdofs;
  std::vector<std::size_t> where;
  std::vector<double> N(nd), bn, bt, Ke, rp, rm;
  for (std::size_t seg = 0; seg + 1 < offsets.size(); ++seg) {
    const std::size_t p0 = offsets[seg], p1 = offsets[seg + 1];
    segment_dofs(q, p0, p1, sdofs, where);
    const std::size_t ne = 2 * sdofs.size();
    bn.assign(ne, 0.0);
    bt.assign(ne, 0.0);
    // b_n = sum_p w_p B_n,p and b_t likewise (B rows: jump of u projected on n and t), and the
    // weighted sums of the points' gaps
    double W = 0.0, wgn = 0.0, wgt = 0.0, wgtp = 0.0, wshift = 0.0;
    for (std::size_t p = p0; p < p1; ++p) {
      point_basis(q, p, dofs, N);
      const double* n = &q.normals[2 * p];
      const double* t = &q.tangents[2 * p];
      const double w = q.weights[p];
      // Displacement jump u_j(P_j) - u_i(P_i) (eq 26) and the gaps (eqs 27-30)
      std::array<double, 2> du = {0.0, 0.0};
      for (std::size_t a = 0; a < nd; ++a) {
        const std::size_t k = where[(p - p0) * nd + a];
        for (std::size_t c = 0; c < 2; ++c) {
          du[c] += N[a] * u[2 * std::size_t(dofs[a]) + c];
          bn[2 * k + c] += w * N[a] * n[c];
          bt[2 * k + c] += w * N[a] * t[c];
        }
      }
      if (!q.u_j_prescribed.empty())
        for (std::size_t c = 0; c < 2; ++c)
          du[c] += q.u_j_prescribed[2 * p + c];
      const PointGaps gaps = point_gaps(q.g_n0[p], du, std::span<const double, 2>(n, 2),
                                        std::span<const double, 2>(t, 2));
      s.g_n[p] = gaps.g_n;
      s.g_t[p] = gaps.g_t;
      W += w;
      wgn += w * gaps.g_n;
      wgt += w * gaps.g_t;
      wgtp += friction ? w * gtp_old[p] : 0.0;
      wshift += g_n_shift.empty() ? 0.0 : w * g_n_shift[p];
    }
    // the law on the segment's mean gaps (a single point: its own, exactly)
    const bool single = p1 - p0 == 1;
    const double gn = (single ? s.g_n[p0] : wgn / W) +
                      (g_n_shift.empty() ? 0.0 : (single ? g_n_shift[p0] : wshift / W));
    const double gt = single ? s.g_t[p0] : wgt / W;
    const double gtp0 = friction ? (single ? gtp_old[p0] : wgtp / W) : 0.0;
    double tau_n, tau_t, gtp = 0.0;
    ContactState state;
    std::array<double, 4> D;
    point_law(law, gn, gt, gtp0, tau_n, tau_t, gtp, state, D);
    for (std::size_t p = p0; p < p1; ++p) {
      s.tau_n[p] = tau_n;
      s.tau_t[p] = tau_t;
      s.state[p] = state;
      if (friction)
        s.gtp_trial[p] = gtp;
    }
    bool predictor = false;
    if (state == ContactState::open) {
      // A touching segment (0 <= g_n < closed_gap) lends the tangent of a closed, sticking one
      // (no traction): the predictor of a step whose bodies are held by contacts not yet closed
      if (!insert or !(gn < closed_gap))
        continue;
      predictor = true;
      D = {1.0 / law.eps_n, 0.0, 0.0, friction ? 1.0 / law.eps_t : 0.0};
    } else if (closed_gap > 0 and state == ContactState::slip and friction) {
      // ... and in that predictor a slipping segment sticks: a grain whose contacts all slip
      // has no tangential stiffness in its first iterate (the residual stays exact)
      D = {1.0 / law.eps_n, 0.0, 0.0, 1.0 / law.eps_t};
    }

    if (!b.empty() and !predictor) {
      for (std::size_t k = 0; k < sdofs.size(); ++k)
        for (std::size_t c = 0; c < 2; ++c)
          b[2 * std::size_t(sdofs[k]) + c] += bn[2 * k + c] * tau_n + bt[2 * k + c] * tau_t;
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
      // Central differences of the segment residual r(u_e) = [b_n b_t] tau(gbar(u_e))
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
  }
  return s;
}

} // namespace contact
