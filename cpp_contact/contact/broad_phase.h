// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

// Broad phase of the multi-body contact search: which pairs of bodies (or body and rigid
// obstacle) can touch, from axis-aligned bounding boxes. The narrow phase (contact surface,
// eqs 21-24) then runs only on the candidate pairs, so its cost grows with the bodies and the
// touching pairs, not with all n (n - 1) / 2 pairs. Sort-and-sweep along one axis: O(n log n)
// for the sort plus the pairs whose intervals overlap on that axis, which for a packing of
// grains of bounded aspect ratio is O(n). Any dimension d >= 1 (chosen at run time).
//
// Box layout (both entry points): flattened (n, 2, d), body b is
// [lo_0, ..., lo_{d-1}, hi_0, ..., hi_{d-1}] at offset 2 d b.

#include <cstdint>
#include <span>
#include <vector>

namespace contact {

/// @brief Candidate pairs i < j of one set of boxes whose inflated boxes overlap.
///
/// Every box grows by `inflate` on every side (so boxes separated by up to 2 inflate along
/// every axis are reported); closed boxes, i.e. touching counts. Sort-and-sweep along the axis
/// of largest spread of the box centres.
/// @param[in] boxes Flattened (n, 2, dim): lo then hi of each box
/// @param[in] dim Spatial dimension (>= 1)
/// @param[in] inflate Margin added on every side of every box (>= 0)
/// @return Flattened (m, 2) pairs (i, j), i < j, sorted lexicographically
/// @throws std::invalid_argument naming the argument for dim < 1, a size not a multiple of
///   2 dim, more than INT32_MAX boxes, non-finite coordinates, lo > hi, or inflate < 0 / NaN
std::vector<std::int32_t> candidate_pairs(std::span<const double> boxes, int dim,
                                          double inflate = 0.0);

/// @brief Candidate pairs (a, b) between two sets (e.g. bodies and rigid obstacles).
///
/// Same inflation and overlap rule as candidate_pairs; both sets are swept together along the
/// axis of largest spread of all centres.
/// @param[in] boxes_a Flattened (n_a, 2, dim) boxes of the first set
/// @param[in] boxes_b Flattened (n_b, 2, dim) boxes of the second set
/// @param[in] dim Spatial dimension (>= 1)
/// @param[in] inflate Margin added on every side of every box of both sets (>= 0)
/// @return Flattened (m, 2) pairs (index in a, index in b), sorted lexicographically
/// @throws std::invalid_argument naming the argument, as candidate_pairs
std::vector<std::int32_t> candidate_pairs_between(std::span<const double> boxes_a,
                                                  std::span<const double> boxes_b, int dim,
                                                  double inflate = 0.0);

/// @brief Reference O(n^2) all-pairs version of candidate_pairs (same output; for tests).
std::vector<std::int32_t> candidate_pairs_brute_force(std::span<const double> boxes, int dim,
                                                      double inflate = 0.0);

/// @brief Reference O(n_a n_b) version of candidate_pairs_between (same output; for tests).
std::vector<std::int32_t> candidate_pairs_between_brute_force(std::span<const double> boxes_a,
                                                              std::span<const double> boxes_b,
                                                              int dim, double inflate = 0.0);

} // namespace contact
