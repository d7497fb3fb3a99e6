// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "levelset.h"
#include <cmath>
#include <stdexcept>
#include <string>

using namespace contact;

namespace
{
/// Second-order finite-difference weights for f'(a[i]) on a non-uniform axis:
/// central at interior nodes, one-sided (3 points) at the two ends.
/// Returns the stencil start and three weights.
std::pair<std::size_t, std::array<double, 3>> fd_weights(const std::vector<double>& a,
                                                         std::size_t i)
{
  const std::size_t n = a.size();
  if (i == 0)
  {
    const double h1 = a[1] - a[0], h2 = a[2] - a[1];
    return {0, {-(2 * h1 + h2) / (h1 * (h1 + h2)), (h1 + h2) / (h1 * h2), -h1 / (h2 * (h1 + h2))}};
  }
  if (i == n - 1)
  {
    const double h1 = a[n - 2] - a[n - 3], h2 = a[n - 1] - a[n - 2];
    return {n - 3, {h2 / (h1 * (h1 + h2)), -(h1 + h2) / (h1 * h2), (2 * h2 + h1) / (h2 * (h1 + h2))}};
  }
  const double h1 = a[i] - a[i - 1], h2 = a[i + 1] - a[i];
  return {i - 1, {-h2 / (h1 * (h1 + h2)), (h2 - h1) / (h1 * h2), h1 / (h2 * (h1 + h2))}};
}

// Cubic Hermite basis on [0, 1] and derivatives
inline void hermite(double s, double* H, double* dH)
{
  const double s2 = s * s, s3 = s2 * s;
  H[0] = 2 * s3 - 3 * s2 + 1; // value at 0
  H[1] = s3 - 2 * s2 + s;     // slope at 0
  H[2] = -2 * s3 + 3 * s2;    // value at 1
  H[3] = s3 - s2;             // slope at 1
  dH[0] = 6 * s2 - 6 * s;
  dH[1] = 3 * s2 - 4 * s + 1;
  dH[2] = -6 * s2 + 6 * s;
  dH[3] = 3 * s2 - 2 * s;
}
} // namespace

LevelSet::LevelSet(StructuredGrid grid, std::vector<double> values)
    : _grid(std::move(grid)), _values(std::move(values))
{
  if (_values.size() != _grid.num_nodes())
    throw std::invalid_argument("level set: expected " + std::to_string(_grid.num_nodes())
                                + " node values, got " + std::to_string(_values.size()));
  for (std::size_t k = 0; k < _values.size(); ++k)
    if (!std::isfinite(_values[k]))
      throw std::invalid_argument("level set: node value " + std::to_string(k)
                                  + " is not finite");

  const auto& x = _grid.axis(0);
  const auto& y = _grid.axis(1);
  const std::size_t nx = x.size(), ny = y.size();
  _deriv.assign(nx * ny, {0, 0, 0});
  for (std::size_t j = 0; j < ny; ++j)
    for (std::size_t i = 0; i < nx; ++i)
    {
      auto [ix, wx] = fd_weights(x, i);
      auto [jy, wy] = fd_weights(y, j);
      double fx = 0, fy = 0;
      for (int k = 0; k < 3; ++k)
      {
        fx += wx[k] * _values[_grid.node(ix + k, j)];
        fy += wy[k] * _values[_grid.node(i, jy + k)];
      }
      _deriv[_grid.node(i, j)][0] = fx;
      _deriv[_grid.node(i, j)][1] = fy;
    }
  // Cross derivative: x-difference of phi_y
  for (std::size_t j = 0; j < ny; ++j)
    for (std::size_t i = 0; i < nx; ++i)
    {
      auto [ix, wx] = fd_weights(x, i);
      double fxy = 0;
      for (int k = 0; k < 3; ++k)
        fxy += wx[k] * _deriv[_grid.node(ix + k, j)][1];
      _deriv[_grid.node(i, j)][2] = fxy;
    }
}

double LevelSet::eval_cell(std::size_t i, std::size_t j, double s, double t, double* grad) const
{
  const auto& x = _grid.axis(0);
  const auto& y = _grid.axis(1);
  const double hx = x[i + 1] - x[i], hy = y[j + 1] - y[j];
  double Hs[4], dHs[4], Ht[4], dHt[4];
  hermite(s, Hs, dHs);
  hermite(t, Ht, dHt);

  // Tensor-product Hermite: sum over corners (a, b) of
  //   f Hs_v Ht_v + hx fx Hs_d Ht_v + hy fy Hs_v Ht_d + hx hy fxy Hs_d Ht_d
  double f = 0, fs = 0, ft = 0;
  for (int b = 0; b < 2; ++b)
    for (int a = 0; a < 2; ++a)
    {
      const std::size_t n = _grid.node(i + a, j + b);
      const double v = _values[n];
      const auto& d = _deriv[n];
      const double cs[2] = {v, hx * d[0]};         // coefficients of (value, slope) in s
      const double ct[2] = {hy * d[1], hx * hy * d[2]}; // same, multiplied by t-slope basis
      const double Sv = Hs[2 * a], Sd = Hs[2 * a + 1];
      const double dSv = dHs[2 * a], dSd = dHs[2 * a + 1];
      const double Tv = Ht[2 * b], Td = Ht[2 * b + 1];
      const double dTv = dHt[2 * b], dTd = dHt[2 * b + 1];
      f += (cs[0] * Sv + cs[1] * Sd) * Tv + (ct[0] * Sv + ct[1] * Sd) * Td;
      fs += (cs[0] * dSv + cs[1] * dSd) * Tv + (ct[0] * dSv + ct[1] * dSd) * Td;
      ft += (cs[0] * Sv + cs[1] * Sd) * dTv + (ct[0] * Sv + ct[1] * Sd) * dTd;
    }
  if (grad)
  {
    grad[0] = fs / hx;
    grad[1] = ft / hy;
  }
  return f;
}

double LevelSet::eval(std::span<const double, 2> x, std::span<double, 2> grad) const
{
  const std::size_t i = _grid.locate_axis(0, x[0]);
  const std::size_t j = _grid.locate_axis(1, x[1]);
  const auto& ax = _grid.axis(0);
  const auto& ay = _grid.axis(1);
  const double s = (x[0] - ax[i]) / (ax[i + 1] - ax[i]);
  const double t = (x[1] - ay[j]) / (ay[j + 1] - ay[j]);
  return eval_cell(i, j, s, t, grad.data());
}

double LevelSet::eval(std::span<const double, 2> x) const
{
  const std::size_t i = _grid.locate_axis(0, x[0]);
  const std::size_t j = _grid.locate_axis(1, x[1]);
  const auto& ax = _grid.axis(0);
  const auto& ay = _grid.axis(1);
  const double s = (x[0] - ax[i]) / (ax[i + 1] - ax[i]);
  const double t = (x[1] - ay[j]) / (ay[j + 1] - ay[j]);
  return eval_cell(i, j, s, t, nullptr);
}

void LevelSet::evaluate(std::span<const double> points, std::span<double> values,
                        std::span<double> grads) const
{
  const std::size_t n = points.size() / 2;
  if (points.size() % 2 != 0 or values.size() != n or (!grads.empty() and grads.size() != 2 * n))
    throw std::invalid_argument("level set evaluate: points must be (n, 2), values (n,), "
                                "grads (n, 2) or empty");
  for (std::size_t p = 0; p < n; ++p)
  {
    std::span<const double, 2> x(points.data() + 2 * p, 2);
    if (!_grid.contains(x))
      throw std::out_of_range("level set evaluate: point " + std::to_string(p) + " ("
                              + std::to_string(x[0]) + ", " + std::to_string(x[1])
                              + ") is outside the grid");
    if (grads.empty())
      values[p] = eval(x);
    else
      values[p] = eval(x, std::span<double, 2>(grads.data() + 2 * p, 2));
  }
}
