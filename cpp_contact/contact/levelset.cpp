// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "levelset.h"
#include <cmath>
#include <stdexcept>
#include <string>

using namespace contact;

namespace {
/// Second-order finite-difference weights for f'(a[i]) on a non-uniform axis:
/// central at interior nodes, one-sided (3 points) at the two ends.
/// Returns the stencil start and three weights.
std::pair<std::size_t, std::array<double, 3>> fd_weights(const std::vector<double>& a,
                                                         std::size_t i) {
  const std::size_t n = a.size();
  if (i == 0) {
    const double h1 = a[1] - a[0], h2 = a[2] - a[1];
    return {0, {-(2 * h1 + h2) / (h1 * (h1 + h2)), (h1 + h2) / (h1 * h2), -h1 / (h2 * (h1 + h2))}};
  }
  if (i == n - 1) {
    const double h1 = a[n - 2] - a[n - 3], h2 = a[n - 1] - a[n - 2];
    return {n - 3,
            {h2 / (h1 * (h1 + h2)), -(h1 + h2) / (h1 * h2), (2 * h2 + h1) / (h2 * (h1 + h2))}};
  }
  const double h1 = a[i] - a[i - 1], h2 = a[i + 1] - a[i];
  return {i - 1, {-h2 / (h1 * (h1 + h2)), (h2 - h1) / (h1 * h2), h1 / (h2 * (h1 + h2))}};
}

// Cubic Hermite basis on [0, 1] and derivatives
inline void hermite(double s, double* H, double* dH, double* ddH = nullptr) {
  if (ddH) {
    ddH[0] = 12 * s - 6;
    ddH[1] = 6 * s - 4;
    ddH[2] = -12 * s + 6;
    ddH[3] = 6 * s - 2;
  }
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
    : _grid(std::move(grid)), _values(std::move(values)) {
  if (_values.size() != _grid.num_nodes())
    throw std::invalid_argument("level set: expected " + std::to_string(_grid.num_nodes()) +
                                " node values, got " + std::to_string(_values.size()));
  for (std::size_t k = 0; k < _values.size(); ++k)
    if (!std::isfinite(_values[k]))
      throw std::invalid_argument("level set: node value " + std::to_string(k) + " is not finite");

  const auto& x = _grid.axis(0);
  const auto& y = _grid.axis(1);
  const std::size_t nx = x.size(), ny = y.size();
  // the stencils depend on the axis position only: once per axis node, not per grid node
  // (a pair grid's level sets are made afresh at every step of an assembly)
  std::vector<std::pair<std::size_t, std::array<double, 3>>> sx(nx), sy(ny);
  for (std::size_t i = 0; i < nx; ++i)
    sx[i] = fd_weights(x, i);
  for (std::size_t j = 0; j < ny; ++j)
    sy[j] = fd_weights(y, j);
  _deriv.assign(nx * ny, {0, 0, 0});
  for (std::size_t j = 0; j < ny; ++j)
    for (std::size_t i = 0; i < nx; ++i) {
      const auto& [ix, wx] = sx[i];
      const auto& [jy, wy] = sy[j];
      double fx = 0, fy = 0;
      for (int k = 0; k < 3; ++k) {
        fx += wx[k] * _values[_grid.node(ix + k, j)];
        fy += wy[k] * _values[_grid.node(i, jy + k)];
      }
      _deriv[_grid.node(i, j)][0] = fx;
      _deriv[_grid.node(i, j)][1] = fy;
    }
  // Cross derivative: x-difference of phi_y
  for (std::size_t j = 0; j < ny; ++j)
    for (std::size_t i = 0; i < nx; ++i) {
      const auto& [ix, wx] = sx[i];
      double fxy = 0;
      for (int k = 0; k < 3; ++k)
        fxy += wx[k] * _deriv[_grid.node(ix + k, j)][1];
      _deriv[_grid.node(i, j)][2] = fxy;
    }
}

double LevelSet::eval_cell(std::size_t i, std::size_t j, double s, double t, double* grad,
                           double* hess) const {
  const auto& x = _grid.axis(0);
  const auto& y = _grid.axis(1);
  const double hx = x[i + 1] - x[i], hy = y[j + 1] - y[j];
  double Hs[4], dHs[4], ddHs[4], Ht[4], dHt[4], ddHt[4];
  hermite(s, Hs, dHs, hess ? ddHs : nullptr);
  hermite(t, Ht, dHt, hess ? ddHt : nullptr);

  // Tensor-product Hermite: sum over corners (a, b) of
  //   f Sv Tv + hx fx Sd Tv + hy fy Sv Td + hx hy fxy Sd Td
  // with S*, T* the value (v) and slope (d) bases in s and t.
  double f = 0, fs = 0, ft = 0, fss = 0, fst = 0, ftt = 0;
  for (int b = 0; b < 2; ++b)
    for (int a = 0; a < 2; ++a) {
      const std::size_t n = _grid.node(i + a, j + b);
      const auto& d = _deriv[n];
      const double c00 = _values[n], c10 = hx * d[0], c01 = hy * d[1], c11 = hx * hy * d[2];
      // Coefficients of Tv and Td as functions of s, and their s-derivatives
      const double Av = c00 * Hs[2 * a] + c10 * Hs[2 * a + 1];
      const double Ad = c01 * Hs[2 * a] + c11 * Hs[2 * a + 1];
      const double dAv = c00 * dHs[2 * a] + c10 * dHs[2 * a + 1];
      const double dAd = c01 * dHs[2 * a] + c11 * dHs[2 * a + 1];
      f += Av * Ht[2 * b] + Ad * Ht[2 * b + 1];
      fs += dAv * Ht[2 * b] + dAd * Ht[2 * b + 1];
      ft += Av * dHt[2 * b] + Ad * dHt[2 * b + 1];
      if (hess) {
        const double ddAv = c00 * ddHs[2 * a] + c10 * ddHs[2 * a + 1];
        const double ddAd = c01 * ddHs[2 * a] + c11 * ddHs[2 * a + 1];
        fss += ddAv * Ht[2 * b] + ddAd * Ht[2 * b + 1];
        fst += dAv * dHt[2 * b] + dAd * dHt[2 * b + 1];
        ftt += Av * ddHt[2 * b] + Ad * ddHt[2 * b + 1];
      }
    }
  if (grad) {
    grad[0] = fs / hx;
    grad[1] = ft / hy;
  }
  if (hess) {
    hess[0] = fss / (hx * hx);
    hess[1] = fst / (hx * hy);
    hess[2] = ftt / (hy * hy);
  }
  return f;
}

double LevelSet::eval_at(std::span<const double, 2> x, double* grad, double* hess) const {
  const std::size_t i = _grid.locate_axis(0, x[0]);
  const std::size_t j = _grid.locate_axis(1, x[1]);
  const auto& ax = _grid.axis(0);
  const auto& ay = _grid.axis(1);
  const double s = (x[0] - ax[i]) / (ax[i + 1] - ax[i]);
  const double t = (x[1] - ay[j]) / (ay[j + 1] - ay[j]);
  return eval_cell(i, j, s, t, grad, hess);
}

double LevelSet::eval(std::span<const double, 2> x, std::span<double, 2> grad,
                      std::span<double, 3> hess) const {
  return eval_at(x, grad.data(), hess.data());
}

double LevelSet::eval(std::span<const double, 2> x, std::span<double, 2> grad) const {
  return eval_at(x, grad.data(), nullptr);
}

double LevelSet::eval(std::span<const double, 2> x) const {
  return eval_at(x, nullptr, nullptr);
}

void LevelSet::evaluate(std::span<const double> points, std::span<double> values,
                        std::span<double> grads) const {
  const std::size_t n = points.size() / 2;
  if (points.size() % 2 != 0 or values.size() != n or (!grads.empty() and grads.size() != 2 * n))
    throw std::invalid_argument("level set evaluate: points must be (n, 2), values (n,), "
                                "grads (n, 2) or empty");
  for (std::size_t p = 0; p < n; ++p) {
    std::span<const double, 2> x(points.data() + 2 * p, 2);
    if (!_grid.contains(x))
      throw std::out_of_range("level set evaluate: point " + std::to_string(p) + " (" +
                              std::to_string(x[0]) + ", " + std::to_string(x[1]) +
                              ") is outside the grid");
    if (grads.empty())
      values[p] = eval(x);
    else
      values[p] = eval(x, std::span<double, 2>(grads.data() + 2 * p, 2));
  }
}
