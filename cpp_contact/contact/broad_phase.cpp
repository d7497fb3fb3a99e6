// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "broad_phase.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace contact {

namespace {

/// @brief Check the layout and values of a box array; return the number of boxes.
std::size_t check_boxes(std::span<const double> boxes, int dim, const char* name) {
  if (dim < 1)
    throw std::invalid_argument("dim: expected >= 1, got " + std::to_string(dim));
  const std::size_t stride = 2 * std::size_t(dim);
  if (boxes.size() % stride != 0)
    throw std::invalid_argument(std::string(name) + ": size " + std::to_string(boxes.size()) +
                                " is not a multiple of 2 dim = " + std::to_string(stride));
  const std::size_t n = boxes.size() / stride;
  // Pair indices are int32 (numpy side and the solver's body ids).
  if (n > std::size_t(std::numeric_limits<std::int32_t>::max()))
    throw std::invalid_argument(std::string(name) + ": more than INT32_MAX boxes");
  for (std::size_t b = 0; b < n; ++b)
    for (int k = 0; k < dim; ++k) {
      const double lo = boxes[stride * b + std::size_t(k)];
      const double hi = boxes[stride * b + std::size_t(dim + k)];
      if (not std::isfinite(lo) or not std::isfinite(hi))
        throw std::invalid_argument(std::string(name) + ": box " + std::to_string(b) +
                                    " has a non-finite coordinate");
      if (lo > hi)
        throw std::invalid_argument(std::string(name) + ": box " + std::to_string(b) +
                                    " has lo > hi along axis " + std::to_string(k));
    }
  return n;
}

void check_inflate(double inflate) {
  if (not(std::isfinite(inflate) and inflate >= 0.0))
    throw std::invalid_argument("inflate: expected a finite value >= 0, got " +
                                std::to_string(inflate));
}

/// @brief Boxes grown by `inflate` on every side, computed once so that the sweep and the
/// overlap test compare exactly the same numbers (touching stays touching).
std::vector<double> inflated(std::span<const double> boxes, int dim, double inflate) {
  std::vector<double> out(boxes.begin(), boxes.end());
  const std::size_t stride = 2 * std::size_t(dim);
  for (std::size_t b = 0; b < boxes.size() / stride; ++b)
    for (int k = 0; k < dim; ++k) {
      out[stride * b + std::size_t(k)] -= inflate;
      out[stride * b + std::size_t(dim + k)] += inflate;
    }
  return out;
}

/// @brief Closed boxes overlap iff their intervals overlap along every axis.
bool overlap(const double* a, const double* b, int dim) {
  for (int k = 0; k < dim; ++k)
    if (a[k] > b[dim + k] or b[k] > a[dim + k])
      return false;
  return true;
}

/// @brief Axis of largest variance of the box centres (over both sets): the sweep along it
/// sees the fewest spurious interval overlaps for a spread-out assembly.
int sweep_axis(std::span<const double> a, std::span<const double> b, int dim) {
  const std::size_t stride = 2 * std::size_t(dim);
  const std::size_t n = (a.size() + b.size()) / stride;
  if (dim == 1 or n < 2)
    return 0;
  int best = 0;
  double best_var = -1.0;
  for (int k = 0; k < dim; ++k) {
    // Two-pass mean/variance: the centres may sit far from the origin.
    double mean = 0.0;
    for (auto s : {a, b})
      for (std::size_t i = 0; i < s.size() / stride; ++i)
        mean += 0.5 * (s[stride * i + std::size_t(k)] + s[stride * i + std::size_t(dim + k)]);
    mean /= double(n);
    double var = 0.0;
    for (auto s : {a, b})
      for (std::size_t i = 0; i < s.size() / stride; ++i) {
        const double c =
            0.5 * (s[stride * i + std::size_t(k)] + s[stride * i + std::size_t(dim + k)]) - mean;
        var += c * c;
      }
    if (var > best_var)
      best_var = var, best = k;
  }
  return best;
}

/// @brief Box indices sorted by their lower bound along `axis` (ties by index: deterministic).
std::vector<std::int32_t> sorted_by_lo(const std::vector<double>& boxes, int dim, int axis) {
  const std::size_t stride = 2 * std::size_t(dim);
  std::vector<std::int32_t> order(boxes.size() / stride);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::int32_t i, std::int32_t j) {
    const double li = boxes[stride * std::size_t(i) + std::size_t(axis)];
    const double lj = boxes[stride * std::size_t(j) + std::size_t(axis)];
    return li < lj or (li == lj and i < j);
  });
  return order;
}

std::vector<std::int32_t> flatten_sorted(std::vector<std::array<std::int32_t, 2>>& pairs) {
  std::sort(pairs.begin(), pairs.end());
  std::vector<std::int32_t> out(2 * pairs.size());
  for (std::size_t p = 0; p < pairs.size(); ++p)
    out[2 * p] = pairs[p][0], out[2 * p + 1] = pairs[p][1];
  return out;
}

} // namespace

std::vector<std::int32_t> candidate_pairs(std::span<const double> boxes, int dim, double inflate) {
  check_boxes(boxes, dim, "boxes");
  check_inflate(inflate);
  const auto ib = inflated(boxes, dim, inflate);
  const int axis = sweep_axis(boxes, {}, dim);
  const auto order = sorted_by_lo(ib, dim, axis);
  const std::size_t stride = 2 * std::size_t(dim), n = order.size();
  const auto box = [&](std::int32_t i) { return ib.data() + stride * std::size_t(i); };

  // For an overlapping pair, the box that comes first in `order` has the smaller lower bound,
  // and the other's lower bound lies within its interval: scanning forward while the lower
  // bounds stay <= hi finds it, and visits only pairs that overlap along the sweep axis.
  std::vector<std::array<std::int32_t, 2>> pairs;
  for (std::size_t p = 0; p < n; ++p) {
    const std::int32_t i = order[p];
    const double hi = box(i)[dim + axis];
    for (std::size_t q = p + 1; q < n and box(order[q])[axis] <= hi; ++q) {
      const std::int32_t j = order[q];
      if (overlap(box(i), box(j), dim))
        pairs.push_back({std::min(i, j), std::max(i, j)});
    }
  }
  return flatten_sorted(pairs);
}

std::vector<std::int32_t> candidate_pairs_between(std::span<const double> boxes_a,
                                                  std::span<const double> boxes_b, int dim,
                                                  double inflate) {
  check_boxes(boxes_a, dim, "boxes_a");
  check_boxes(boxes_b, dim, "boxes_b");
  check_inflate(inflate);
  const auto ia = inflated(boxes_a, dim, inflate), ib = inflated(boxes_b, dim, inflate);
  const int axis = sweep_axis(boxes_a, boxes_b, dim);
  const auto oa = sorted_by_lo(ia, dim, axis), ob = sorted_by_lo(ib, dim, axis);
  const std::size_t stride = 2 * std::size_t(dim);
  const auto box = [&](const std::vector<double>& v, std::int32_t i) {
    return v.data() + stride * std::size_t(i);
  };

  // An overlapping pair has lo_a <= lo_b <= hi_a or lo_b < lo_a <= hi_b: two sweeps, each
  // from a monotone start pointer, cover the two cases exactly once.
  std::vector<std::array<std::int32_t, 2>> pairs;
  std::size_t start = 0;
  for (const std::int32_t i : oa) {
    const double lo = box(ia, i)[axis], hi = box(ia, i)[dim + axis];
    while (start < ob.size() and box(ib, ob[start])[axis] < lo)
      ++start;
    for (std::size_t q = start; q < ob.size() and box(ib, ob[q])[axis] <= hi; ++q)
      if (overlap(box(ia, i), box(ib, ob[q]), dim))
        pairs.push_back({i, ob[q]});
  }
  start = 0;
  for (const std::int32_t j : ob) {
    const double lo = box(ib, j)[axis], hi = box(ib, j)[dim + axis];
    while (start < oa.size() and box(ia, oa[start])[axis] <= lo)
      ++start;
    for (std::size_t p = start; p < oa.size() and box(ia, oa[p])[axis] <= hi; ++p)
      if (overlap(box(ia, oa[p]), box(ib, j), dim))
        pairs.push_back({oa[p], j});
  }
  return flatten_sorted(pairs);
}

std::vector<std::int32_t> candidate_pairs_brute_force(std::span<const double> boxes, int dim,
                                                      double inflate) {
  const std::size_t n = check_boxes(boxes, dim, "boxes");
  check_inflate(inflate);
  const auto ib = inflated(boxes, dim, inflate);
  const std::size_t stride = 2 * std::size_t(dim);
  std::vector<std::array<std::int32_t, 2>> pairs;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      if (overlap(ib.data() + stride * i, ib.data() + stride * j, dim))
        pairs.push_back({std::int32_t(i), std::int32_t(j)});
  return flatten_sorted(pairs);
}

std::vector<std::int32_t> candidate_pairs_between_brute_force(std::span<const double> boxes_a,
                                                              std::span<const double> boxes_b,
                                                              int dim, double inflate) {
  const std::size_t na = check_boxes(boxes_a, dim, "boxes_a");
  const std::size_t nb = check_boxes(boxes_b, dim, "boxes_b");
  check_inflate(inflate);
  const auto ia = inflated(boxes_a, dim, inflate), ib = inflated(boxes_b, dim, inflate);
  const std::size_t stride = 2 * std::size_t(dim);
  std::vector<std::array<std::int32_t, 2>> pairs;
  for (std::size_t i = 0; i < na; ++i)
    for (std::size_t j = 0; j < nb; ++j)
      if (overlap(ia.data() + stride * i, ib.data() + stride * j, dim))
        pairs.push_back({std::int32_t(i), std::int32_t(j)});
  return flatten_sorted(pairs);
}

} // namespace contact
