// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Tests of the broad phase: sort-and-sweep against the O(n^2) reference on random boxes in
// 1D/2D/3D, touching boxes, the between-sets entry point, empty input and bad input. Set
// CONTACT_TEST_VERBOSE=1 to print a timing table (a measurement, not an assertion).
#include <contact/broad_phase.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

using namespace contact;

namespace {

bool verbose() {
  return std::getenv("CONTACT_TEST_VERBOSE") != nullptr;
}

/// n random boxes in [0, L]^dim with sides in [0, s]; L chosen so that a box meets a few others
/// on average, plus some degenerate (point / flat) boxes.
std::vector<double> random_boxes(std::size_t n, int dim, unsigned seed) {
  std::mt19937 gen(seed);
  const double L = std::pow(double(n), 1.0 / dim);
  std::uniform_real_distribution<double> pos(0.0, L), side(0.0, 1.5);
  std::vector<double> b(2 * std::size_t(dim) * n);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < dim; ++k) {
      const double lo = pos(gen), s = (i % 17 == 0) ? 0.0 : side(gen);
      b[2 * dim * i + k] = lo;
      b[2 * dim * i + dim + k] = lo + s;
    }
  return b;
}

/// Boxes on an integer lattice (unit cells): exact touching along faces, edges and corners.
std::vector<double> lattice_boxes(int m, int dim) {
  std::vector<double> b;
  const int n = int(std::pow(m, dim));
  for (int c = 0; c < n; ++c) {
    std::vector<double> lo(dim);
    for (int k = 0, r = c; k < dim; ++k, r /= m)
      lo[k] = r % m;
    for (int k = 0; k < dim; ++k)
      b.push_back(lo[k]);
    for (int k = 0; k < dim; ++k)
      b.push_back(lo[k] + 1.0);
  }
  return b;
}

void expect_sorted_pairs(const std::vector<std::int32_t>& p, bool ordered) {
  ASSERT_EQ(p.size() % 2, 0u);
  for (std::size_t q = 0; q < p.size() / 2; ++q) {
    if (ordered) {
      EXPECT_LT(p[2 * q], p[2 * q + 1]);
    }
    if (q > 0) {
      const bool lex =
          p[2 * q - 2] < p[2 * q] or (p[2 * q - 2] == p[2 * q] and p[2 * q - 1] < p[2 * q + 1]);
      EXPECT_TRUE(lex) << "pair " << q << " out of lexicographic order or repeated";
    }
  }
}

} // namespace

TEST(BroadPhase, MatchesBruteForceOnRandomBoxes) {
  // Exact equality of pair lists: both sides compare the same inflated doubles with <=.
  std::size_t total = 0;
  for (int dim = 1; dim <= 3; ++dim)
    for (std::size_t n : {1, 2, 3, 10, 57, 200, 500})
      for (unsigned seed : {1u, 2u, 3u})
        for (double inflate : {0.0, 0.1}) {
          const auto b = random_boxes(n, dim, seed + 100 * unsigned(n) + 7 * unsigned(dim));
          const auto fast = candidate_pairs(b, dim, inflate);
          const auto ref = candidate_pairs_brute_force(b, dim, inflate);
          ASSERT_EQ(fast, ref) << "dim " << dim << " n " << n << " seed " << seed;
          expect_sorted_pairs(fast, true);
          total += fast.size() / 2;
        }
  EXPECT_GT(total, 1000u) << "the random sets should produce many pairs";
}

TEST(BroadPhase, BetweenMatchesBruteForce) {
  for (int dim = 1; dim <= 3; ++dim)
    for (std::size_t na : {0, 1, 5, 120, 400})
      for (std::size_t nb : {0, 1, 4, 90})
        for (double inflate : {0.0, 0.2}) {
          const auto a = random_boxes(na, dim, unsigned(na + 3 * nb + dim));
          auto b = random_boxes(nb, dim, unsigned(11 * na + nb + 5 * dim));
          // Share some lower bounds exactly (same side) to exercise the tie rule lo_a == lo_b.
          for (std::size_t j = 0; j < std::min(na, nb); j += 2)
            for (int k = 0; k < dim; ++k) {
              const double side = b[2 * dim * j + dim + k] - b[2 * dim * j + k];
              b[2 * dim * j + k] = a[2 * dim * j + k];
              b[2 * dim * j + dim + k] = a[2 * dim * j + k] + side;
            }
          const auto fast = candidate_pairs_between(a, b, dim, inflate);
          const auto ref = candidate_pairs_between_brute_force(a, b, dim, inflate);
          ASSERT_EQ(fast, ref) << "dim " << dim << " na " << na << " nb " << nb;
          expect_sorted_pairs(fast, false);
        }
}

TEST(BroadPhase, TouchingBoxesCount) {
  // A 4x4 (x4) lattice of unit boxes touching exactly: every box pairs with all neighbours of
  // its 3^d - 1 neighbourhood; count = number of lattice pairs with |di| <= 1 per axis.
  for (int dim = 1; dim <= 3; ++dim) {
    const int m = 4;
    const auto b = lattice_boxes(m, dim);
    const auto p = candidate_pairs(b, dim, 0.0);
    // Per axis, (offset 0: m ordered pairs of identical coordinate; offset 1: m - 1) ->
    // unordered pairs = ((m + 2 (m - 1))^dim - m^dim) / 2.
    const double expected = (std::pow(m + 2.0 * (m - 1), dim) - std::pow(m, dim)) / 2;
    EXPECT_EQ(double(p.size() / 2), expected) << "dim " << dim;
    EXPECT_EQ(p, candidate_pairs_brute_force(b, dim, 0.0));
  }
  // Two boxes a gap g apart: separate with inflate < g/2, a pair from inflate = g/2 on
  // (g and g/2 exact in binary, so the inflated bounds meet exactly).
  const std::vector<double> two = {0.0, 0.0, 1.0, 1.0, 1.5, 0.0, 2.5, 1.0};
  EXPECT_TRUE(candidate_pairs(two, 2, 0.24).empty());
  EXPECT_EQ(candidate_pairs(two, 2, 0.25), (std::vector<std::int32_t>{0, 1}));
  EXPECT_EQ(candidate_pairs_between({two.data(), 4}, {two.data() + 4, 4}, 2, 0.25),
            (std::vector<std::int32_t>{0, 0}));
  EXPECT_TRUE(candidate_pairs_between({two.data(), 4}, {two.data() + 4, 4}, 2, 0.24).empty());
  // Overlap on x only is not a pair.
  const std::vector<double> stacked = {0.0, 0.0, 1.0, 1.0, 0.5, 2.0, 1.5, 3.0};
  EXPECT_TRUE(candidate_pairs(stacked, 2, 0.0).empty());
}

TEST(BroadPhase, EmptyAndSingle) {
  EXPECT_TRUE(candidate_pairs({}, 2, 0.0).empty());
  EXPECT_TRUE(candidate_pairs(std::vector<double>{0, 0, 1, 1}, 2, 1.0).empty());
  EXPECT_TRUE(candidate_pairs_between({}, std::vector<double>{0, 0, 1, 1}, 2, 0.0).empty());
  EXPECT_TRUE(candidate_pairs_between(std::vector<double>{0, 0, 1, 1}, {}, 2, 0.0).empty());
}

TEST(BroadPhase, BadInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const auto throws_naming = [](auto&& f, const char* name) {
    try {
      f();
      ADD_FAILURE() << "no exception, expected one naming " << name;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  };
  const std::vector<double> ok = {0, 0, 1, 1};
  throws_naming([&] { candidate_pairs(std::vector<double>{0, nan, 1, 1}, 2, 0.0); }, "boxes");
  throws_naming([&] { candidate_pairs(std::vector<double>{0, 0, inf, 1}, 2, 0.0); }, "boxes");
  throws_naming([&] { candidate_pairs(std::vector<double>{0, 2, 1, 1}, 2, 0.0); }, "lo > hi");
  throws_naming([&] { candidate_pairs(std::vector<double>{0, 0, 1}, 2, 0.0); }, "boxes");
  throws_naming([&] { candidate_pairs(ok, 0, 0.0); }, "dim");
  throws_naming([&] { candidate_pairs(ok, 2, -0.1); }, "inflate");
  throws_naming([&] { candidate_pairs(ok, 2, nan); }, "inflate");
  throws_naming(
      [&] {
        candidate_pairs_between(ok, std::vector<double>{1, 1, 0, 2}, 2, 0.0);
      },
      "boxes_b");
  throws_naming(
      [&] {
        candidate_pairs_between(std::vector<double>{nan, 0, 1, 1}, ok, 2, 0.0);
      },
      "boxes_a");
  throws_naming([&] { candidate_pairs_between(ok, ok, 2, -1.0); }, "inflate");
}

TEST(BroadPhase, GrainPackingPairsLinear) {
  // Grains of radius ~0.45 on a jittered unit lattice: each touches at most its 8 lattice
  // neighbours, so pairs <= 4 n; measured times printed with CONTACT_TEST_VERBOSE=1.
  std::mt19937 gen(42);
  std::uniform_real_distribution<double> u(-0.05, 0.05), r(0.35, 0.5);
  for (int m : {5, 10, 20, 40, 80}) {
    std::vector<double> b;
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) {
        const double x = i + u(gen), y = j + u(gen), R = r(gen);
        b.insert(b.end(), {x - R, y - R, x + R, y + R});
      }
    const std::size_t n = std::size_t(m) * m;
    const auto t0 = std::chrono::steady_clock::now();
    const int reps = 20;
    std::size_t npairs = 0;
    for (int rep = 0; rep < reps; ++rep)
      npairs = candidate_pairs(b, 2, 0.02).size() / 2;
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_LE(npairs, 4 * n);
    if (verbose())
      std::printf("broad phase N = %5zu  pairs = %6zu  time = %9.2f us  per grain = %.3f us\n", n,
                  npairs, 1e6 * dt / reps, 1e6 * dt / reps / double(n));
  }
}
