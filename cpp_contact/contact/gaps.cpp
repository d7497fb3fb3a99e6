// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "gaps.h"
#include <stdexcept>
#include <string>

namespace contact {
//-----------------------------------------------------------------------------
void compute_gaps(std::span<const double> p_i, std::span<const double> p_j,
                  std::span<const double> u_i, std::span<const double> u_j,
                  std::span<const double> normals, std::span<const double> tangents,
                  std::span<double> g_n0, std::span<double> j_int, std::span<double> g_n,
                  std::span<double> g_t) {
  // The number of points is taken from g_n; everything else must agree with it
  const std::size_t n = g_n.size();
  auto check = [](std::size_t size, std::size_t expected, const char* name, const char* shape) {
    if (size != expected) {
      throw std::invalid_argument(std::string("compute_gaps: ") + name + " has size " +
                                  std::to_string(size) + ", expected " + shape + " = " +
                                  std::to_string(expected));
    }
  };
  check(p_i.size(), 2 * n, "p_i", "2n");
  check(p_j.size(), 2 * n, "p_j", "2n");
  check(u_i.size(), 2 * n, "u_i", "2n");
  check(u_j.size(), 2 * n, "u_j", "2n");
  check(normals.size(), 2 * n, "normals", "2n");
  check(tangents.size(), 2 * n, "tangents", "2n");
  check(g_n0.size(), n, "g_n0", "n");
  check(j_int.size(), n, "j_int", "n");
  check(g_t.size(), n, "g_t", "n");

  for (std::size_t p = 0; p < n; ++p) {
    const std::size_t x = 2 * p, y = 2 * p + 1;
    const double dp0 = p_j[x] - p_i[x], dp1 = p_j[y] - p_i[y];
    const double du0 = u_j[x] - u_i[x], du1 = u_j[y] - u_i[y];
    const double gn0 = dp0 * normals[x] + dp1 * normals[y]; // eq 28
    const double jn = du0 * normals[x] + du1 * normals[y];  // eq 29
    g_n0[p] = gn0;
    j_int[p] = jn;
    g_n[p] = gn0 + jn;                              // eq 27
    g_t[p] = du0 * tangents[x] + du1 * tangents[y]; // eq 30
  }
}
//-----------------------------------------------------------------------------
} // namespace contact
