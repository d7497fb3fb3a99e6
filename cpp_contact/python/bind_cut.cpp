// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Cut cells: the kernels' addresses for custom integrals in dolfinx Forms, their coefficient
// layout, vectorised cut quadrature (tests, diagnostics), and the ghost-penalty couplings.
#include "array.h"
#include <contact/cut_cell.h>
#include <cstdint>
#include <dolfinx/la/SparsityPattern.h>
#include <pybind11/stl.h>

namespace py = pybind11;
using contact::python::as_span;
using contact::python::carray;
using contact::python::to_numpy;
namespace cut = contact::cut;

void bind_cut(py::module_& m) {
  m.def(
      "cut_kernels",
      []() {
        py::dict d;
        d["elasticity_q1"] = reinterpret_cast<std::uintptr_t>(&cut::elasticity_q1);
        d["traction_q1"] = reinterpret_cast<std::uintptr_t>(&cut::traction_q1);
        return d;
      },
      "Addresses of the cut-cell kernels (ufcx tabulate_tensor ABI) for dolfinx Forms");
  m.def(
      "cut_layout",
      []() {
        py::dict d;
        d["phi"] = cut::Layout::phi;
        d["lame"] = cut::Layout::lame;
        d["traction"] = cut::Layout::traction;
        d["bilinear_size"] = cut::Layout::bilinear_size;
        d["traction_size"] = cut::Layout::traction_size;
        return d;
      },
      "Offsets of the packed coefficients the cut kernels read (see contact/cut_cell.h)");
  m.def(
      "cut_quadrature",
      [](const carray& phi, int degree) {
        const auto p = as_span(phi, "phi", 4);
        const std::size_t n = p.size() / 4;
        std::vector<double> pts, wts;
        std::vector<std::int64_t> offsets(n + 1, 0);
        for (std::size_t c = 0; c < n; ++c) {
          cut::cut_square_rule(std::span<const double, 4>(p.data() + 4 * c, 4), degree, pts, wts);
          offsets[c + 1] = std::int64_t(wts.size());
        }
        const py::ssize_t m_ = py::ssize_t(wts.size());
        py::dict d;
        d["offsets"] = to_numpy(std::move(offsets), {py::ssize_t(n + 1)});
        d["points"] = to_numpy(std::move(pts), {m_, 2});
        d["weights"] = to_numpy(std::move(wts), {m_});
        return d;
      },
      py::arg("phi"), py::arg("degree") = 2,
      "Cut rule per cell: phi (n, 4) vertex values -> offsets (n+1), reference points (m, 2), "
      "weights (m,) (the full reference square has weight 1)");
  m.def(
      "inside_fraction",
      [](const carray& phi) {
        const auto p = as_span(phi, "phi", 4);
        std::vector<double> f(p.size() / 4);
        for (std::size_t c = 0; c < f.size(); ++c)
          f[c] = cut::inside_fraction(std::span<const double, 4>(p.data() + 4 * c, 4));
        return to_numpy(std::move(f), {py::ssize_t(f.size())});
      },
      py::arg("phi"), "Inside area fraction of each cell, phi (n, 4) in tensor order");
  m.def(
      "cut_moment_weights",
      [](const carray& phi, const carray& points) {
        const auto p = as_span(phi, "phi", 4);
        if (points.ndim() != 2 or points.shape(1) != 2 or points.shape(0) == 0)
          throw std::invalid_argument("points: expected an array of shape (nq, 2), nq > 0");
        const std::span<const double> x(points.data(), std::size_t(points.size()));
        const std::size_t n = p.size() / 4, nq = x.size() / 2;
        std::vector<double> w(n * nq);
        for (std::size_t c = 0; c < n; ++c)
          cut::moment_fitted_weights(std::span<const double, 4>(p.data() + 4 * c, 4), x,
                                     std::span<double>(w.data() + nq * c, nq));
        return to_numpy(std::move(w), {py::ssize_t(n), py::ssize_t(nq)});
      },
      py::arg("phi"), py::arg("points"),
      "Moment-fitted weights of a tensor rule on cut cells: phi (n, 4) vertex values (tensor "
      "order), points (nq, 2) reference points of a full tensor grid (any order) -> (n, nq) "
      "weights integrating Q_{m-1} exactly over the inside part (full square: total 1)");
  m.def(
      "insert_blocks",
      [](dolfinx::la::SparsityPattern& pattern,
         const py::array_t<std::int32_t, py::array::c_style | py::array::forcecast>& dofs) {
        if (dofs.ndim() != 2)
          throw std::invalid_argument("dofs: expected an array of shape (n, k)");
        const std::size_t k = dofs.shape(1);
        for (py::ssize_t r = 0; r < dofs.shape(0); ++r) {
          std::span<const std::int32_t> d(dofs.data() + r * k, k);
          pattern.insert(d, d);
        }
      },
      py::arg("pattern"), py::arg("dofs"),
      "Couple all block dofs of each row of dofs (n, k) in a SparsityPattern (e.g. the two "
      "cells of a ghost-penalty facet)");
}
