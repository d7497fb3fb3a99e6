// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "broad_phase.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
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

/// @brief Axis of largest variance of the box centres of both sets: the sweep along it sees the
/// fewest spurious interval overlaps for a spread-out assembly.
int sweep_axis(std::span<const double> a, std::span<const double> b, int dim) {
  const std::size_t stride = 2 * std::size_t(dim), n = (a.size() + b.size()) / stride;
  int best = 0;
  double best_var = -1.0;
  for (int k = 0; k < dim and n > 1; ++k) {
    const auto centre = [&](std::span<const double> s, std::size_t i) {
      return 0.5 * (s[stride * i + std::size_t(k)] + s[stride * i + std::size_t(dim + k)]);
    };
    // Two passes: the centres may sit far from the origin.
    double mean = 0.0, var = 0.0;
    for (auto s : {a, b})
      for (std::size_t i = 0; i < s.size() / stride; ++i)
        mean += centre(s, i);
    mean /= double(n);
    for (auto s : {a, b})
      for (std::size_t i = 0; i < s.size() / stride; ++i)
        var += (centre(s, i) - mean) * (centre(s, i) - mean);
    if (var > best_var)
      best_var = var, best = k;
  }
  return best;
}

/// @brief The sweep axis and a uniform grid of cells over the other (secondary) axes.
///
/// A plain sweep along one axis visits every pair whose intervals overlap along that axis:
/// for n grains spread over a square that is O(n^1.5) (each interval meets a whole column of
/// grains). Sweeping each cell of a grid over the secondary axes separately, with cells about
/// one box wide, leaves O(1) interval overlaps per box: O(n log n + pairs) overall.
struct Cells {
  int dim = 1, axis = 0;
  std::vector<int> sec;             ///< secondary axes
  std::vector<double> origin, size; ///< per secondary axis
  std::vector<std::int64_t> count;  ///< cells per secondary axis
  std::vector<std::int64_t> stride; ///< linear key = sum index[s] * stride[s]

  /// Cell index of coordinate x along secondary axis s (monotone in x, clamped).
  std::int64_t index(std::size_t s, double x) const {
    const double t = std::floor((x - origin[s]) / size[s]);
    return std::int64_t(std::clamp(t, 0.0, double(count[s] - 1)));
  }

  /// Key of the cell holding the lower corner of the intersection of two overlapping boxes:
  /// it lies in both boxes, so both are registered in that cell, and the pair is reported
  /// there only (exactly once).
  std::int64_t owner(const double* a, const double* b) const {
    std::int64_t key = 0;
    for (std::size_t s = 0; s < sec.size(); ++s)
      key += stride[s] * index(s, std::max(a[sec[s]], b[sec[s]]));
    return key;
  }
};

/// @brief Grid for the (inflated) boxes of both sets: cells of the median box extent, at most
/// about 2 n^(1/(d-1)) per axis (points or huge outliers do not blow the cell count up).
Cells make_cells(std::span<const double> a, std::span<const double> b, int dim) {
  Cells c;
  c.dim = dim;
  c.axis = sweep_axis(a, b, dim);
  const std::size_t stride = 2 * std::size_t(dim), n = (a.size() + b.size()) / stride;
  if (n == 0)
    return c;
  const double cap = std::ceil(2.0 * std::pow(double(n), 1.0 / std::max(1, dim - 1)));
  std::vector<double> extent;
  extent.reserve(n);
  std::int64_t total = 1;
  for (int k = 0; k < dim; ++k) {
    if (k == c.axis)
      continue;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    extent.clear();
    for (auto s : {a, b})
      for (std::size_t i = 0; i < s.size() / stride; ++i) {
        const double l = s[stride * i + std::size_t(k)], h = s[stride * i + std::size_t(dim + k)];
        lo = std::min(lo, l), hi = std::max(hi, h);
        extent.push_back(h - l);
      }
    std::nth_element(extent.begin(), extent.begin() + std::ptrdiff_t(n / 2), extent.end());
    const double range = hi - lo;
    double size = std::max(extent[n / 2], range / cap);
    std::int64_t count = 1;
    if (size > 0.0)
      count = std::int64_t(std::min(cap, std::floor(range / size) + 1.0));
    else
      size = 1.0; // all boxes are flat at one coordinate along k: one cell
    c.sec.push_back(k);
    c.origin.push_back(lo);
    c.size.push_back(size);
    c.count.push_back(count);
    c.stride.push_back(total);
    total *= count;
  }
  return c;
}

/// One registration of a box in a cell, sorted by (cell, lower bound along the sweep axis).
struct Entry {
  std::int64_t key;
  double lo;
  std::int32_t id;
  bool operator<(const Entry& o) const {
    return key < o.key or (key == o.key and (lo < o.lo or (lo == o.lo and id < o.id)));
  }
};

/// @brief Register every box in each cell its secondary extent covers, sorted by (cell, lower
/// bound along the sweep axis, index).
///
/// Counting sort by cell (linear; a comparison sort of the whole list was slow on the
/// patterned, nearly sorted input of a lattice), then a sort by lower bound within each cell.
std::vector<Entry> entries(const std::vector<double>& boxes, const Cells& c) {
  const std::size_t stride = 2 * std::size_t(c.dim), m = c.sec.size(), n = boxes.size() / stride;
  std::size_t ncells = 1;
  for (const auto k : c.count)
    ncells *= std::size_t(k);
  std::vector<std::int64_t> first(m), last(m), idx(m);
  // Visit every (cell key, box) registration; f(key, box).
  const auto for_each_cell = [&](auto&& f) {
    for (std::size_t i = 0; i < n; ++i) {
      const double* bx = boxes.data() + stride * i;
      for (std::size_t s = 0; s < m; ++s) {
        first[s] = idx[s] = c.index(s, bx[c.sec[s]]);
        last[s] = c.index(s, bx[c.dim + c.sec[s]]);
      }
      while (true) { // odometer over the covered block of cells
        std::int64_t key = 0;
        for (std::size_t s = 0; s < m; ++s)
          key += c.stride[s] * idx[s];
        f(std::size_t(key), i);
        std::size_t s = 0;
        for (; s < m; ++s) {
          if (++idx[s] <= last[s])
            break;
          idx[s] = first[s];
        }
        if (s == m)
          break;
      }
    }
  };
  std::vector<std::size_t> offset(ncells + 1, 0);
  for_each_cell([&](std::size_t key, std::size_t) { ++offset[key + 1]; });
  for (std::size_t k = 0; k < ncells; ++k)
    offset[k + 1] += offset[k];
  std::vector<Entry> out(offset[ncells]);
  std::vector<std::size_t> pos(offset.begin(), offset.end() - 1);
  for_each_cell([&](std::size_t key, std::size_t i) {
    out[pos[key]++] = {std::int64_t(key), boxes[stride * i + std::size_t(c.axis)], std::int32_t(i)};
  });
  for (std::size_t k = 0; k < ncells; ++k)
    std::sort(out.begin() + std::ptrdiff_t(offset[k]), out.begin() + std::ptrdiff_t(offset[k + 1]));
  return out;
}

/// @brief End of the run of entries with the same cell key as e[p].
std::size_t run_end(const std::vector<Entry>& e, std::size_t p) {
  std::size_t q = p;
  while (q < e.size() and e[q].key == e[p].key)
    ++q;
  return q;
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
  const Cells cells = make_cells(ib, {}, dim);
  const auto e = entries(ib, cells);
  const std::size_t stride = 2 * std::size_t(dim);
  const auto box = [&](std::size_t p) { return ib.data() + stride * std::size_t(e[p].id); };

  // In a cell, of an overlapping pair the box that comes first has the smaller lower bound and
  // the other's lower bound lies within its interval: scanning forward while the lower bounds
  // stay <= hi finds it, visiting only the pairs that overlap along the sweep axis.
  std::vector<std::array<std::int32_t, 2>> pairs;
  for (std::size_t r = 0; r < e.size();) {
    const std::size_t end = run_end(e, r);
    for (std::size_t p = r; p < end; ++p) {
      const double hi = box(p)[dim + cells.axis];
      for (std::size_t q = p + 1; q < end and e[q].lo <= hi; ++q)
        if (overlap(box(p), box(q), dim) and cells.owner(box(p), box(q)) == e[p].key)
          pairs.push_back({std::min(e[p].id, e[q].id), std::max(e[p].id, e[q].id)});
    }
    r = end;
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
  const Cells cells = make_cells(ia, ib, dim);
  const auto ea = entries(ia, cells), eb = entries(ib, cells);
  const std::size_t stride = 2 * std::size_t(dim);
  const int ax = cells.axis;
  const auto box = [&](const std::vector<double>& v, std::int32_t i) {
    return v.data() + stride * std::size_t(i);
  };

  std::vector<std::array<std::int32_t, 2>> pairs;
  const auto report = [&](std::int32_t i, std::int32_t j, std::int64_t key) {
    if (overlap(box(ia, i), box(ib, j), dim) and cells.owner(box(ia, i), box(ib, j)) == key)
      pairs.push_back({i, j});
  };
  std::size_t pa = 0, pb = 0;
  while (pa < ea.size() and pb < eb.size()) {
    if (ea[pa].key < eb[pb].key) {
      pa = run_end(ea, pa);
      continue;
    }
    if (eb[pb].key < ea[pa].key) {
      pb = run_end(eb, pb);
      continue;
    }
    const std::int64_t key = ea[pa].key;
    const std::size_t enda = run_end(ea, pa), endb = run_end(eb, pb);
    // An overlapping pair has lo_a <= lo_b <= hi_a or lo_b < lo_a <= hi_b: two sweeps, each
    // from a monotone start pointer, cover the two cases exactly once.
    std::size_t start = pb;
    for (std::size_t p = pa; p < enda; ++p) {
      const double hi = box(ia, ea[p].id)[dim + ax];
      while (start < endb and eb[start].lo < ea[p].lo)
        ++start;
      for (std::size_t q = start; q < endb and eb[q].lo <= hi; ++q)
        report(ea[p].id, eb[q].id, key);
    }
    start = pa;
    for (std::size_t q = pb; q < endb; ++q) {
      const double hi = box(ib, eb[q].id)[dim + ax];
      while (start < enda and ea[start].lo <= eb[q].lo)
        ++start;
      for (std::size_t p = start; p < enda and ea[p].lo <= hi; ++p)
        report(ea[p].id, eb[q].id, key);
    }
    pa = enda, pb = endb;
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
