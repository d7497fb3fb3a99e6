// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "grid.h"
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

using namespace contact;

namespace {
void check_axis(const std::vector<double>& a, const char* name) {
  if (a.size() < 3) {
    throw std::invalid_argument(std::string("grid axis ") + name +
                                ": needs at least 3 nodes, got " + std::to_string(a.size()));
  }
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!std::isfinite(a[i]))
      throw std::invalid_argument(std::string("grid axis ") + name + ": coordinate " +
                                  std::to_string(i) + " is not finite");
    if (i > 0 and !(a[i] > a[i - 1]))
      throw std::invalid_argument(std::string("grid axis ") + name +
                                  ": coordinates must be strictly increasing (index " +
                                  std::to_string(i) + ")");
  }
}

bool is_uniform(const std::vector<double>& a) {
  const double h = (a.back() - a.front()) / double(a.size() - 1);
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::abs(a[i] - (a.front() + double(i) * h)) > 1e-12 * h * double(a.size()))
      return false;
  return true;
}
} // namespace

StructuredGrid::StructuredGrid(std::vector<double> x, std::vector<double> y)
    : _axes{std::move(x), std::move(y)} {
  check_axis(_axes[0], "x");
  check_axis(_axes[1], "y");
  _hmin = std::numeric_limits<double>::max();
  _hmax = 0.0;
  for (int d = 0; d < gdim; ++d) {
    _uniform[d] = is_uniform(_axes[d]);
    for (std::size_t i = 1; i < _axes[d].size(); ++i) {
      _hmin = std::min(_hmin, _axes[d][i] - _axes[d][i - 1]);
      _hmax = std::max(_hmax, _axes[d][i] - _axes[d][i - 1]);
    }
  }
}

StructuredGrid StructuredGrid::uniform(std::array<double, 2> lo, std::array<double, 2> hi,
                                       std::array<std::size_t, 2> n) {
  std::array<std::vector<double>, 2> axes;
  for (int d = 0; d < 2; ++d) {
    if (n[d] < 2)
      throw std::invalid_argument("grid: need at least 2 cells along axis " + std::to_string(d) +
                                  ", got " + std::to_string(n[d]));
    if (!(hi[d] > lo[d]))
      throw std::invalid_argument("grid: upper bound must exceed lower bound along axis " +
                                  std::to_string(d));
    axes[d].resize(n[d] + 1);
    for (std::size_t i = 0; i <= n[d]; ++i)
      axes[d][i] = lo[d] + (hi[d] - lo[d]) * double(i) / double(n[d]);
  }
  return StructuredGrid(std::move(axes[0]), std::move(axes[1]));
}

bool StructuredGrid::contains(std::span<const double, 2> x) const {
  for (int d = 0; d < gdim; ++d)
    if (!(x[d] >= _axes[d].front() and x[d] <= _axes[d].back()))
      return false;
  return true;
}

std::size_t StructuredGrid::locate_axis(int d, double t) const {
  const std::vector<double>& a = _axes[d];
  const std::size_t ncell = a.size() - 1;
  std::size_t i;
  if (_uniform[d]) {
    const double s = (t - a.front()) / (a.back() - a.front()) * double(ncell);
    i = s <= 0.0 ? 0 : std::min(static_cast<std::size_t>(s), ncell - 1);
    // Round-off near a node: settle on the interval that really contains t
    if (i > 0 and t < a[i])
      --i;
    else if (i + 1 < ncell and t >= a[i + 1])
      ++i;
  } else {
    auto it = std::upper_bound(a.begin(), a.end(), t);
    i = it == a.begin() ? 0 : std::size_t(it - a.begin()) - 1;
    i = std::min(i, ncell - 1);
  }
  return i;
}

std::optional<std::array<std::size_t, 2>>
StructuredGrid::locate(std::span<const double, 2> x) const {
  if (!contains(x))
    return std::nullopt;
  return std::array<std::size_t, 2>{locate_axis(0, x[0]), locate_axis(1, x[1])};
}
