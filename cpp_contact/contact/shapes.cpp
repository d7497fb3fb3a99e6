// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "shapes.h"
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

using namespace contact;

namespace {
void check_finite(std::initializer_list<double> v, const char* what) {
  for (double x : v)
    if (!std::isfinite(x))
      throw std::invalid_argument(std::string(what) + ": parameters must be finite");
}

// Root of F(s) = (r0 z0/(s + r0))^2 + (z1/(s + 1))^2 - 1 by bisection (Eberly,
// "Distance from a point to an ellipse"): robust for points near the axes and
// the centre, where Newton on the angle parametrisation fails.
double ellipse_root(double r0, double z0, double z1, double g) {
  const double n0 = r0 * z0;
  double s0 = z1 - 1.0;
  double s1 = g < 0 ? 0.0 : std::hypot(n0, z1) - 1.0;
  double s = 0.0;
  for (int i = 0; i < 200; ++i) {
    s = 0.5 * (s0 + s1);
    if (s == s0 or s == s1)
      break;
    const double ratio0 = n0 / (s + r0), ratio1 = z1 / (s + 1.0);
    const double gs = ratio0 * ratio0 + ratio1 * ratio1 - 1.0;
    if (gs > 0)
      s0 = s;
    else if (gs < 0)
      s1 = s;
    else
      break;
  }
  return s;
}

// Closest point on the ellipse (x/e0)^2 + (y/e1)^2 = 1, e0 >= e1, to y in the first quadrant
std::array<double, 2> ellipse_closest_quadrant(double e0, double e1, double y0, double y1) {
  if (y1 > 0) {
    if (y0 > 0) {
      const double z0 = y0 / e0, z1 = y1 / e1;
      const double g = z0 * z0 + z1 * z1 - 1.0;
      if (g == 0)
        return {y0, y1};
      const double r0 = (e0 / e1) * (e0 / e1);
      const double s = ellipse_root(r0, z0, z1, g);
      return {r0 * y0 / (s + r0), y1 / (s + 1.0)};
    }
    return {0.0, e1};
  }
  const double numer0 = e0 * y0, denom0 = e0 * e0 - e1 * e1;
  if (numer0 < denom0) {
    const double xde0 = numer0 / denom0;
    return {e0 * xde0, e1 * std::sqrt(std::max(0.0, 1.0 - xde0 * xde0))};
  }
  return {e0, 0.0};
}
} // namespace

void Shape::evaluate(std::span<const double> points, std::span<double> values) const {
  if (points.size() != 2 * values.size())
    throw std::invalid_argument("shape evaluate: points must be (n, 2) and values (n,)");
  for (std::size_t p = 0; p < values.size(); ++p)
    values[p] = (*this)({points[2 * p], points[2 * p + 1]});
}

Circle::Circle(std::array<double, 2> c, double r) : _c(c), _r(r) {
  check_finite({c[0], c[1], r}, "Circle");
  if (!(r > 0))
    throw std::invalid_argument("Circle: radius must be > 0, got " + std::to_string(r));
}

double Circle::operator()(std::array<double, 2> x) const {
  return std::hypot(x[0] - _c[0], x[1] - _c[1]) - _r;
}

Ellipse::Ellipse(std::array<double, 2> c, double a, double b, double angle)
    : _c(c), _a(a), _b(b), _cos(std::cos(angle)), _sin(std::sin(angle)) {
  check_finite({c[0], c[1], a, b, angle}, "Ellipse");
  if (!(a > 0) or !(b > 0))
    throw std::invalid_argument("Ellipse: semi-axes must be > 0");
}

std::array<double, 2> Ellipse::closest_point(std::array<double, 2> x) const {
  // Local frame, reflected into the first quadrant, major axis first
  const double dx = x[0] - _c[0], dy = x[1] - _c[1];
  double l0 = _cos * dx + _sin * dy, l1 = -_sin * dx + _cos * dy;
  const bool swap = _b > _a;
  if (swap)
    std::swap(l0, l1);
  const double e0 = std::max(_a, _b), e1 = std::min(_a, _b);
  // Coordinates within round-off of an axis are put on it: the root bracket of
  // Eberly's method degenerates (s + 1 == 0) for |y1| ~ 1e-17 e1
  const double y0 = std::abs(l0) <= 1e-14 * e0 ? 0.0 : std::abs(l0);
  const double y1 = std::abs(l1) <= 1e-14 * e1 ? 0.0 : std::abs(l1);
  auto q = ellipse_closest_quadrant(e0, e1, y0, y1);
  q[0] = std::copysign(q[0], l0);
  q[1] = std::copysign(q[1], l1);
  if (swap)
    std::swap(q[0], q[1]);
  return {_c[0] + _cos * q[0] - _sin * q[1], _c[1] + _sin * q[0] + _cos * q[1]};
}

double Ellipse::operator()(std::array<double, 2> x) const {
  const auto q = closest_point(x);
  const double d = std::hypot(x[0] - q[0], x[1] - q[1]);
  const double dx = x[0] - _c[0], dy = x[1] - _c[1];
  const double l0 = (_cos * dx + _sin * dy) / _a, l1 = (-_sin * dx + _cos * dy) / _b;
  return l0 * l0 + l1 * l1 < 1.0 ? -d : d;
}

Box::Box(std::array<double, 2> lo, std::array<double, 2> hi) : _lo(lo), _hi(hi) {
  check_finite({lo[0], lo[1], hi[0], hi[1]}, "Box");
  if (!(hi[0] > lo[0]) or !(hi[1] > lo[1]))
    throw std::invalid_argument("Box: need hi > lo in both directions");
}

double Box::operator()(std::array<double, 2> x) const {
  double q[2], outside = 0.0;
  for (int d = 0; d < 2; ++d) {
    const double c = 0.5 * (_lo[d] + _hi[d]), half = 0.5 * (_hi[d] - _lo[d]);
    q[d] = std::abs(x[d] - c) - half;
    outside += std::max(q[d], 0.0) * std::max(q[d], 0.0);
  }
  return std::sqrt(outside) + std::min(std::max(q[0], q[1]), 0.0);
}

double contact::segment_distance(std::array<double, 2> x, std::array<double, 2> a,
                                 std::array<double, 2> b) {
  const double ex = b[0] - a[0], ey = b[1] - a[1];
  const double wx = x[0] - a[0], wy = x[1] - a[1];
  const double l2 = ex * ex + ey * ey;
  const double t = l2 > 0 ? std::clamp((wx * ex + wy * ey) / l2, 0.0, 1.0) : 0.0;
  if (wx * ey - wy * ex == 0 and t > 0 and t < 1)
    return 0.0;
  return std::hypot(wx - t * ex, wy - t * ey);
}

Polygon::Polygon(std::vector<double> vertices) : _v(std::move(vertices)) {
  if (_v.size() % 2 != 0 or _v.size() < 6)
    throw std::invalid_argument("Polygon: vertices must be (m, 2) with m >= 3");
  for (double v : _v)
    if (!std::isfinite(v))
      throw std::invalid_argument("Polygon: vertices must be finite");
}

double Polygon::operator()(std::array<double, 2> x) const {
  const std::size_t m = _v.size() / 2;
  double d = std::numeric_limits<double>::max();
  bool inside = false;
  for (std::size_t k = 0, l = m - 1; k < m; l = k++) {
    const std::array<double, 2> a{_v[2 * l], _v[2 * l + 1]}, b{_v[2 * k], _v[2 * k + 1]};
    d = std::min(d, segment_distance(x, a, b));
    // Crossing number with the half-open rule (each vertex counted once)
    if ((a[1] > x[1]) != (b[1] > x[1])) {
      const double xc = a[0] + (x[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
      if (x[0] < xc)
        inside = !inside;
    }
  }
  return inside ? -d : d;
}

Union::Union(std::vector<std::shared_ptr<const Shape>> parts) : _parts(std::move(parts)) {
  if (_parts.empty())
    throw std::invalid_argument("Union: needs at least one shape");
}

double Union::operator()(std::array<double, 2> x) const {
  double v = std::numeric_limits<double>::max();
  for (const auto& s : _parts)
    v = std::min(v, (*s)(x));
  return v;
}

Intersection::Intersection(std::vector<std::shared_ptr<const Shape>> parts)
    : _parts(std::move(parts)) {
  if (_parts.empty())
    throw std::invalid_argument("Intersection: needs at least one shape");
}

double Intersection::operator()(std::array<double, 2> x) const {
  double v = std::numeric_limits<double>::lowest();
  for (const auto& s : _parts)
    v = std::max(v, (*s)(x));
  return v;
}

Complement::Complement(std::shared_ptr<const Shape> s) : _s(std::move(s)) {
  if (!_s)
    throw std::invalid_argument("Complement: shape is null");
}

double Complement::operator()(std::array<double, 2> x) const {
  return -(*_s)(x);
}

LevelSet contact::levelset_from_shape(const StructuredGrid& grid, const Shape& shape) {
  return LevelSet(grid,
                  sample_on_grid(grid, [&shape](std::array<double, 2> x) { return shape(x); }));
}
