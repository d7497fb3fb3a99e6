// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

#include "return_mapping.h"
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace contact {

/// @brief Contact quadrature of one body pair in the reference configuration (2D).
///
/// Built once per scene: points on Gamma_c (eq 24) with their weights, normal n (body i -> j),
/// tangent t, initial normal gap g_n0 = (P_j - P_i).n (eq 28), and, for each side, the cell
/// that contains the closest point P_i (P_j) with the basis values there. Small strain: the
/// geometry does not change during Newton, only u does (eqs 27-30).
/// Dof indices are *block* (node) indices into a local vector with block size 2.
/// Side j may have no dofs (nodes_j = 0): a rigid obstacle, whose prescribed displacement at
/// P_j enters the jump through `u_j_prescribed` (seed 002: rigid level-set objects).
struct ContactQuadrature {
  int nodes_i = 0;                  ///< basis functions per cell of body i (> 0)
  int nodes_j = 0;                  ///< basis functions per cell of body j (0: rigid side)
  std::vector<double> weights;      ///< (nq,) length measure
  std::vector<double> normals;      ///< (nq, 2)
  std::vector<double> tangents;     ///< (nq, 2)
  std::vector<double> g_n0;         ///< (nq,)
  std::vector<std::int32_t> dofs_i; ///< (nq, nodes_i) block dofs of the cell containing P_i
  std::vector<std::int32_t> dofs_j; ///< (nq, nodes_j)
  std::vector<double> basis_i;      ///< (nq, nodes_i) basis values at P_i
  std::vector<double> basis_j;      ///< (nq, nodes_j)
  /// (nq, 2) displacement of side j at P_j not carried by dofs (a rigid obstacle's prescribed
  /// motion), added to u_j(P_j) in the jump of eq 26; empty: none
  std::vector<double> u_j_prescribed;
  /// Multiplier nodes (optional; empty: every point carries its own traction). Point p
  /// belongs to node mult_nodes[2p] with weight mult_weights[2p] and to mult_nodes[2p + 1]
  /// (-1: none) with mult_weights[2p + 1]; a point's weights sum to 1 (a partition of unity
  /// along Gamma_c: one node of weight 1 for piecewise-constant segments, two hat values for a
  /// piecewise-linear pressure). A node carries one traction from the psi-weighted mean of its
  /// points' gaps, so the constraints are as many as the nodes, not as the points (no
  /// over-constraint of the P1/Q1 trace: a stable pressure).
  std::vector<std::int32_t> mult_nodes;
  std::vector<double> mult_weights;

  /// @brief Number of quadrature points.
  std::size_t size() const { return weights.size(); }
  /// @brief Check that all arrays have consistent sizes.
  /// @throws std::invalid_argument naming the first inconsistent array
  void validate() const;
  /// @brief Where the law acts: the multiplier nodes, or the points without them.
  std::size_t num_law_points() const;
  /// @brief For each law point, its points and their weights psi (CSR: law point a has
  /// points[offsets[a], offsets[a + 1]) with psi likewise).
  struct LawPoints {
    std::vector<std::size_t> offsets;
    std::vector<std::int32_t> points;
    std::vector<double> psi;
  };
  LawPoints law_points() const;
};

/// @brief Traction state after an evaluation, at the points and at the law points (the
/// multiplier nodes, or the points themselves without them).
struct ContactPointState {
  std::vector<double> g_n, g_t;             ///< the points' gaps (eqs 27, 30)
  std::vector<double> tau_n, tau_t;         ///< the points' tractions, sum_a psi_a tau_a
  std::vector<ContactState> state;          ///< the points' state: that of their heaviest node
  std::vector<double> law_g_n, law_g_t;     ///< law points' mean gaps
  std::vector<double> law_tau_n, law_tau_t; ///< law points' tractions (compression negative)
  std::vector<ContactState> law_state;      ///< law points' state: open / stick / slip
  std::vector<double> gtp_trial;            ///< law points' plastic slip after this evaluation
  std::vector<std::int8_t> law_coupled;     ///< 1 where a law point's tangent block was inserted
};

/// @brief Callback receiving one point's element matrix: block dofs (nodes_i + nodes_j) and the
/// row-major (2 nd x 2 nd) matrix, nd = nodes_i + nodes_j, interleaved (node*2 + component).
using BlockInserter =
    std::function<void(std::span<const std::int32_t> dofs, std::span<const double> Ke)>;

/// @brief Tangent of the contact terms: exact (consistent, default) or central finite
/// differences of the point residual (verification only).
enum class TangentMode { exact, finite_difference };

/// @brief Contact residual and tangent of eq 48 for a body pair.
///
/// Per law point a (a multiplier node, or a single point without them), with its points'
/// weights w_p psi_p, W = sum w_p psi_p: the law (Algorithm 1) acts on the mean gaps
/// gbar = sum w_p psi_p g_p / W (+ the shift), r += sum_p w_p psi_p B_p^T tau_a
/// = [b_n b_t] tau_a with b = sum_p w_p psi_p B_p, and K += (1/W) [b_n b_t] D [b_n b_t]^T:
/// the exact derivative. For a single point of weight 1 this is the point-wise form below.
/// At each point: g_n = g_n0 + (u_j(P_j) - u_i(P_i)).n, g_t = (u_j - u_i).t (`point_gaps`,
/// u_j(P_j) including q.u_j_prescribed;
/// gaps.h, with u interpolated at P_i and P_j by the basis values), the return
/// mapping (Algorithm 1) gives tau_n, tau_t and D = d[tau_n, tau_t]/d[g_n, g_t], and with
/// B = [n t]^T [-N_i, N_j] (2 x 2nd):  r += w B^T [tau_n, tau_t],  K += w B^T D B.
/// Open points add nothing. With mu == 0 the tangential row is skipped altogether (no
/// return mapping of friction, gtp is neither read nor written).
/// @param[in] q Quadrature of the pair
/// @param[in] law Penalty compliances and friction coefficient
/// @param[in] u Local displacement array (block size 2, owned + ghost)
/// @param[in] gtp_old Committed plastic slip (one per law point), ignored (may be empty) when
/// mu == 0
/// @param[out] b Local residual array to add to (size of u), or empty to skip
/// @param[in] insert Receives element matrices, or empty to skip the tangent
/// @param[in] mode Exact or finite-difference tangent
/// @param[in] fd_step Perturbation of the FD tangent (displacement units)
/// @param[in] closed_gap > 0 selects the predictor tangent: open points with g_n < closed_gap
/// add the tangent of a closed, sticking point (and no residual), slipping points the sticking
/// tangent: for bodies held only by contacts that touch but are not yet closed, or that all
/// slip in a first iterate far from equilibrium (0: off, the exact tangent)
/// @param[in] g_n_shift (one per law point) added to the normal gap the law sees, or empty: the
/// augmented
/// Lagrangian's multiplier, eps_n lambda_n, so that tau_n = min(0, lambda_n + g_n / eps_n)
/// (Uzawa, seed 003); the reported g_n stays the true gap
/// @return Gaps, tractions and states at the points and the law points, trial slip
ContactPointState assemble_contact(const ContactQuadrature& q, const CoulombPenalty& law,
                                   std::span<const double> u, std::span<const double> gtp_old,
                                   std::span<double> b, const BlockInserter& insert,
                                   TangentMode mode = TangentMode::exact, double fd_step = 1e-8,
                                   double closed_gap = 0.0, std::span<const double> g_n_shift = {});

/// @brief Coupling blocks of a pair, one per law point: the block dofs of all its points.
struct CouplingBlocks {
  std::vector<std::int32_t> dofs;   ///< block dofs, law point after law point (no repeats within)
  std::vector<std::size_t> offsets; ///< law point a: dofs[offsets[a], offsets[a + 1])
};

/// @brief The coupling blocks that the sparsity pattern must contain.
CouplingBlocks coupling_dofs(const ContactQuadrature& q);

} // namespace contact
