// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

// Broad phase of the multi-body contact search: which pairs of bodies (or body and rigid
// obstacle) can touch, from axis-aligned bounding boxes. The narrow phase (contact surface,
// eqs 21-24) then runs only on the candidate pairs, so its cost grows with the bodies and the
// touching pairs, not with all n (n - 1) / 2 pairs. Sort-and-sweep along the axis of largest
// spread of the box centres, run separately in each cell of a uniform grid over the other axes
// (cells about one median box wide): a single global sweep would visit every pair overlapping
// along the sweep axis, O(n^1.5) for grains filling a square, whereas per cell each box meets
// O(1) intervals. Cost O(n log n + pairs) for boxes of comparable size; a box much larger than
// the median (a rigid plate) is registered in every cell it covers. Any dimension d >= 1
// (chosen at run time; d = 1 is a plain sweep).
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
/// every axis are reported); closed boxes, i.e. touching counts. A pair met in several cells
/// is reported once, by the cell holding the lower corner of the boxes' intersection.
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
/// Same inflation and overlap rule as candidate_pairs; one grid and sweep axis for both sets
/// (from all centres), and in each cell a merged sweep of the two sorted lists, so that pairs
/// within one set are never visited.
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
