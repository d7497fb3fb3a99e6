// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Micro-benchmarks of the geometry core (not tests): closest points per second and
// contact-surface extraction on large grids. Run by `make bench`.
#include <benchmark/benchmark.h>
#include <cmath>
#include <contact/contact_surface.h>
#include <contact/projection.h>
#include <contact/reinit.h>
#include <contact/shapes.h>
#include <random>

using namespace contact;

namespace {
LevelSet disc(std::size_t n, std::array<double, 2> c, double r) {
  return levelset_from_shape(StructuredGrid::uniform({0, 0}, {1, 1}, {n, n}), Circle(c, r));
}
} // namespace

// Points within 2 cells of the boundary of a disc (the situation on Gamma_c)
static void BM_ClosestPointProjection(benchmark::State& state) {
  const std::size_t n = state.range(0);
  const LevelSet phi = disc(n, {0.5, 0.5}, 0.3);
  std::mt19937 gen(0);
  std::uniform_real_distribution<double> U(0, 2 * M_PI), D(-2.0 / n, 2.0 / n);
  std::vector<double> pts(2 * 100000);
  for (std::size_t p = 0; p < pts.size() / 2; ++p) {
    const double t = U(gen), r = 0.3 + D(gen);
    pts[2 * p] = 0.5 + r * std::cos(t), pts[2 * p + 1] = 0.5 + r * std::sin(t);
  }
  for (auto _ : state)
    benchmark::DoNotOptimize(closest_point_projection(phi, pts));
  state.SetItemsProcessed(state.iterations() * int64_t(pts.size() / 2));
}
BENCHMARK(BM_ClosestPointProjection)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);

static void BM_ContactSurface(benchmark::State& state) {
  const std::size_t n = state.range(0);
  const LevelSet a = disc(n, {0.3, 0.5}, 0.25), b = disc(n, {0.7, 0.5}, 0.148);
  std::size_t nq = 0;
  for (auto _ : state) {
    auto s = contact_surface(a, b, 0.02, 2);
    nq = s.weights.size();
    benchmark::DoNotOptimize(s);
  }
  state.counters["quadrature_points"] = double(nq);
}
BENCHMARK(BM_ContactSurface)->Arg(250)->Arg(500)->Arg(1000)->Unit(benchmark::kMillisecond);

static void BM_Reinitialize(benchmark::State& state) {
  const std::size_t n = state.range(0);
  const StructuredGrid g = StructuredGrid::uniform({0, 0}, {1, 1}, {n, n});
  const LevelSet phi(g, sample_on_grid(g, [](auto x) {
                       return (x[0] - 0.5) * (x[0] - 0.5) + (x[1] - 0.5) * (x[1] - 0.5) - 0.09;
                     }));
  for (auto _ : state)
    benchmark::DoNotOptimize(reinitialize(phi));
}
BENCHMARK(BM_Reinitialize)->Arg(250)->Arg(1000)->Unit(benchmark::kMillisecond);

// The closing level set of two discs (eq 22) swept over the whole grid (cap 0 here) and to
// eps + 4 cells, as contact_surface asks for it (cap 1)
static void BM_ClosingLevelset(benchmark::State& state) {
  const std::size_t n = state.range(0);
  const LevelSet a = disc(n, {0.3, 0.5}, 0.25), b = disc(n, {0.7, 0.5}, 0.148);
  const double eps = 0.02, cap = state.range(1) ? eps + 4.0 / double(n) : INFINITY;
  for (auto _ : state)
    benchmark::DoNotOptimize(closing_levelset(a, b, eps, cap));
}
BENCHMARK(BM_ClosingLevelset)
    ->Args({250, 0})
    ->Args({250, 1})
    ->Args({1000, 0})
    ->Args({1000, 1})
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
