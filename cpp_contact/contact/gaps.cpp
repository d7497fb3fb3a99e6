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

  auto point = [](std::span<const double> a, std::size_t p) { return a.subspan(2 * p).first<2>(); };
  for (std::size_t p = 0; p < n; ++p) {
    const double du[2] = {u_j[2 * p] - u_i[2 * p], u_j[2 * p + 1] - u_i[2 * p + 1]};
    g_n0[p] = initial_normal_gap(point(p_i, p), point(p_j, p), point(normals, p)); // eq 28
    const PointGaps g = point_gaps(g_n0[p], du, point(normals, p), point(tangents, p));
    j_int[p] = g.j_int;
    g_n[p] = g.g_n;
    g_t[p] = g.g_t;
  }
}
//-----------------------------------------------------------------------------
} // namespace contact
