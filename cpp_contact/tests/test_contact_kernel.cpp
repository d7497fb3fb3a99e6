// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Contact kernel of eq 48: exact tangent against the kernel's central differences, and
// action = reaction between the two bodies.
#include <cmath>
#include <contact/contact_kernel.h>
#include <gtest/gtest.h>
#include <map>
#include <random>

using namespace contact;

namespace {
/// Two-point, two-node-per-side quadrature on 4 nodes: nodes 0,1 body i; 2,3 body j.
ContactQuadrature make(std::mt19937& gen, std::size_t nq) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  ContactQuadrature q;
  q.nodes_i = q.nodes_j = 2;
  for (std::size_t p = 0; p < nq; ++p) {
    const double th = 6.283185307179586 * U(gen), s = U(gen);
    q.weights.push_back(0.5 + U(gen));
    q.normals.insert(q.normals.end(), {std::cos(th), std::sin(th)});
    q.tangents.insert(q.tangents.end(), {-std::sin(th), std::cos(th)});
    q.g_n0.push_back(0.02 * (U(gen) - 0.5));
    q.dofs_i.insert(q.dofs_i.end(), {0, 1});
    q.dofs_j.insert(q.dofs_j.end(), {2, 3});
    q.basis_i.insert(q.basis_i.end(), {s, 1 - s});
    q.basis_j.insert(q.basis_j.end(), {1 - s, s});
  }
  return q;
}

using Dense = std::map<std::pair<int, int>, double>;

Dense tangent(const ContactQuadrature& q, const CoulombPenalty& law, const std::vector<double>& u,
              const std::vector<double>& gtp, TangentMode mode, ContactPointState* s = nullptr) {
  Dense K;
  BlockInserter ins = [&K](std::span<const std::int32_t> d, std::span<const double> Ke) {
    const std::size_t ne = 2 * d.size();
    for (std::size_t r = 0; r < ne; ++r)
      for (std::size_t c = 0; c < ne; ++c)
        K[{2 * d[r / 2] + int(r % 2), 2 * d[c / 2] + int(c % 2)}] += Ke[r * ne + c];
  };
  ContactPointState st = assemble_contact(q, law, u, gtp, {}, ins, mode, 1e-9);
  if (s)
    *s = st;
  return K;
}
} // namespace

TEST(ContactKernel, ExactTangentMatchesFiniteDifferences) {
  std::mt19937 gen(11);
  std::uniform_real_distribution<double> U(-0.01, 0.01);
  const ContactQuadrature q = make(gen, 60);
  std::vector<double> u(8), gtp(q.size());
  for (double& v : u)
    v = U(gen);
  for (double& v : gtp)
    v = U(gen);
  const CoulombPenalty law{1e-2, 2e-2, 0.3};
  ContactPointState s;
  const Dense K = tangent(q, law, u, gtp, TangentMode::exact, &s);
  const Dense Kfd = tangent(q, law, u, gtp, TangentMode::finite_difference);
  int count[3] = {0, 0, 0};
  for (ContactState c : s.state)
    ++count[int(c)];
  EXPECT_GT(count[0], 0);
  EXPECT_GT(count[1], 0);
  EXPECT_GT(count[2], 0);
  double scale = 0, err = 0;
  for (const auto& [key, v] : K) {
    scale = std::max(scale, std::abs(v));
    err = std::max(err, std::abs(v - Kfd.at(key)));
  }
  EXPECT_GT(scale, 0.0);
  EXPECT_LE(err, 1e-6 * scale);
}

TEST(ContactKernel, ActionEqualsReaction) {
  std::mt19937 gen(5);
  const ContactQuadrature q = make(gen, 20);
  std::vector<double> u{0.0, 0.0, 0.0, 0.0, 0.0, -0.01, 0.0, -0.01}, b(8, 0.0);
  std::vector<double> gtp(q.size(), 0.0);
  assemble_contact(q, CoulombPenalty{1e-2, 1e-2, 0.5}, u, gtp, b, {});
  for (int c = 0; c < 2; ++c)
    EXPECT_NEAR(b[c] + b[2 + c], -(b[4 + c] + b[6 + c]), 1e-12);
}

TEST(ContactKernel, RejectsInconsistentQuadrature) {
  std::mt19937 gen(1);
  ContactQuadrature q = make(gen, 3);
  q.basis_j.pop_back();
  std::vector<double> u(8, 0.0);
  EXPECT_THROW(assemble_contact(q, CoulombPenalty{1e-2, 1e-2, 0.0}, u, {}, {}, {}),
               std::invalid_argument);
}

// law_coupled says which law points inserted a tangent block (the sparsity that holds the
// contact tangent is grown from it): the closed ones, the predictor's touching open ones too,
// none without an inserter.
TEST(ContactKernel, CoupledFlagsTheInsertedBlocks) {
  std::mt19937 gen(3);
  const ContactQuadrature q = make(gen, 40);
  std::vector<double> u(8, 0.0), gtp(q.size(), 0.0);
  const CoulombPenalty law{1e-2, 1e-2, 0.3};
  for (double closed_gap : {0.0, 0.005}) {
    int calls = 0;
    BlockInserter ins = [&calls](std::span<const std::int32_t>, std::span<const double>) {
      ++calls;
    };
    const ContactPointState s =
        assemble_contact(q, law, u, gtp, {}, ins, TangentMode::exact, 1e-9, closed_gap);
    int coupled = 0, open = 0;
    for (std::size_t a = 0; a < q.size(); ++a) {
      const bool closed = s.law_state[a] != ContactState::open;
      open += !closed;
      EXPECT_EQ(s.law_coupled[a], closed or s.law_g_n[a] < closed_gap ? 1 : 0) << a;
      coupled += s.law_coupled[a];
    }
    EXPECT_EQ(calls, coupled);
    EXPECT_GT(open, 0);
    EXPECT_GT(coupled, 0);
  }
  const ContactPointState none = assemble_contact(q, law, u, gtp, {}, BlockInserter{});
  for (std::int8_t c : none.law_coupled)
    EXPECT_EQ(c, 0);
}
