// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace contact {

/// @brief Structured tensor-product grid in 2D (uniform or graded spacing).
///
/// Nodes are numbered x-fastest: node(i, j) = i + nx * j; cells likewise with
/// (nx - 1) cells per row. The axes are stored explicitly so a graded grid
/// costs nothing extra; a uniform axis is detected and located in O(1).
/// The dimension is a compile-time constant so a 3D grid is an extension.
class StructuredGrid {
public:
  static constexpr int gdim = 2;

  /// @brief Create a grid from its node coordinates along each axis.
  /// @param[in] x Strictly increasing, finite node coordinates along x (>= 3 nodes)
  /// @param[in] y Strictly increasing, finite node coordinates along y (>= 3 nodes)
  /// @throws std::invalid_argument naming the axis if the input is not valid
  StructuredGrid(std::vector<double> x, std::vector<double> y);

  /// @brief Create a uniform grid of [lo, hi] with n[d] cells along axis d.
  static StructuredGrid uniform(std::array<double, 2> lo, std::array<double, 2> hi,
                                std::array<std::size_t, 2> n);

  /// @brief Node coordinates along axis d.
  const std::vector<double>& axis(int d) const { return _axes[d]; }

  /// @brief Number of nodes along axis d.
  std::size_t num_nodes(int d) const { return _axes[d].size(); }

  /// @brief Total number of nodes.
  std::size_t num_nodes() const { return _axes[0].size() * _axes[1].size(); }

  /// @brief Total number of cells.
  std::size_t num_cells() const { return (_axes[0].size() - 1) * (_axes[1].size() - 1); }

  /// @brief Linear index of node (i, j).
  std::size_t node(std::size_t i, std::size_t j) const { return i + _axes[0].size() * j; }

  /// @brief Linear index of cell (i, j) (the cell [x_i, x_{i+1}] x [y_j, y_{j+1}]).
  std::size_t cell(std::size_t i, std::size_t j) const { return i + (_axes[0].size() - 1) * j; }

  /// @brief Coordinates of node (i, j).
  std::array<double, 2> node_coordinates(std::size_t i, std::size_t j) const {
    return {_axes[0][i], _axes[1][j]};
  }

  /// @brief Smallest node spacing over both axes (the h of tolerances).
  double min_spacing() const { return _hmin; }

  /// @brief Largest node spacing over both axes.
  double max_spacing() const { return _hmax; }

  /// @brief True if x lies in the closed bounding box of the grid.
  bool contains(std::span<const double, 2> x) const;

  /// @brief Index of the cell interval along axis d that contains t.
  ///
  /// Points on the upper boundary belong to the last interval. O(1) for
  /// uniform axes, O(log n) otherwise. The caller must check contains() first.
  std::size_t locate_axis(int d, double t) const;

  /// @brief Cell (i, j) containing x, or nullopt if x is outside the grid.
  std::optional<std::array<std::size_t, 2>> locate(std::span<const double, 2> x) const;

private:
  std::array<std::vector<double>, 2> _axes;
  std::array<bool, 2> _uniform;
  double _hmin, _hmax;
};

} // namespace contact
