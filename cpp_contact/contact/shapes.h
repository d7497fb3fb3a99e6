// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

#include "levelset.h"
#include <array>
#include <memory>
#include <span>
#include <vector>

namespace contact {

/// @brief An analytic body: phi(x) < 0 inside, > 0 outside (eq 17).
///
/// Circle, Ellipse, Box and Polygon return the exact signed distance; the
/// boolean combinations return min/max of their operands, which is exact
/// outside a union and inside an intersection and a valid level set everywhere
/// (reinitialize() turns it into a distance where needed).
class Shape {
public:
  virtual ~Shape() = default;
  /// @brief Level-set value at x.
  virtual double operator()(std::array<double, 2> x) const = 0;
  /// @brief Values at many points: flattened (n, 2) -> (n,).
  void evaluate(std::span<const double> points, std::span<double> values) const;
};

/// @brief Disc of radius r centred at c (exact signed distance).
class Circle : public Shape {
public:
  Circle(std::array<double, 2> c, double r);
  double operator()(std::array<double, 2> x) const override;

private:
  std::array<double, 2> _c;
  double _r;
};

/// @brief Ellipse with semi-axes (a, b) rotated by `angle` about c (exact signed distance,
/// by the robust root bracketing of Eberly for the closest point).
class Ellipse : public Shape {
public:
  Ellipse(std::array<double, 2> c, double a, double b, double angle = 0.0);
  double operator()(std::array<double, 2> x) const override;
  /// @brief Closest point on the ellipse to x (exact up to round-off).
  std::array<double, 2> closest_point(std::array<double, 2> x) const;

private:
  // Distance and closest point in the local frame, first quadrant, e0 >= e1
  std::array<double, 2> _c;
  double _a, _b, _cos, _sin;
};

/// @brief Axis-aligned box [lo, hi] (exact signed distance, corners included).
class Box : public Shape {
public:
  Box(std::array<double, 2> lo, std::array<double, 2> hi);
  double operator()(std::array<double, 2> x) const override;

private:
  std::array<double, 2> _lo, _hi;
};

/// @brief Simple closed polygon (either orientation; exact signed distance,
/// O(number of edges) per point; use levelset_from_polyline for long curves).
class Polygon : public Shape {
public:
  /// @param[in] vertices Flattened (m, 2), m >= 3, closing edge implied
  explicit Polygon(std::vector<double> vertices);
  double operator()(std::array<double, 2> x) const override;

private:
  std::vector<double> _v;
};

/// @brief Union of shapes: min of the level sets.
class Union : public Shape {
public:
  explicit Union(std::vector<std::shared_ptr<const Shape>> parts);
  double operator()(std::array<double, 2> x) const override;

private:
  std::vector<std::shared_ptr<const Shape>> _parts;
};

/// @brief Intersection of shapes: max of the level sets.
class Intersection : public Shape {
public:
  explicit Intersection(std::vector<std::shared_ptr<const Shape>> parts);
  double operator()(std::array<double, 2> x) const override;

private:
  std::vector<std::shared_ptr<const Shape>> _parts;
};

/// @brief Complement of a shape (e.g. a hole, a matrix around an inclusion): -phi.
class Complement : public Shape {
public:
  explicit Complement(std::shared_ptr<const Shape> s);
  double operator()(std::array<double, 2> x) const override;

private:
  std::shared_ptr<const Shape> _s;
};

/// @brief Level set of a shape sampled at the grid nodes.
LevelSet levelset_from_shape(const StructuredGrid& grid, const Shape& shape);

/// @brief Unsigned distance from x to the segment [a, b]: the one definition (polygons,
/// polyline reinitialisation); exactly 0 for a point on the segment that is exactly
/// collinear with it (a grid node on an axis-aligned edge: no round-off sign).
double segment_distance(std::array<double, 2> x, std::array<double, 2> a, std::array<double, 2> b);

} // namespace contact
