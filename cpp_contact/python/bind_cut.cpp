// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Cut cells: the kernels' addresses for custom integrals in dolfinx Forms, their coefficient
// layout, vectorised cut quadrature (tests, diagnostics), and the ghost-penalty couplings.
#include "array.h"
#include "la.h"
#include <contact/contour.h>
#include <contact/cut_cell.h>
#include <cstdint>
#include <limits>
#include <pybind11/stl.h>

namespace py = pybind11;
using contact::python::any;
using contact::python::Arg;
using contact::python::flat;
using contact::python::input;
using contact::python::to_numpy;
namespace cut = contact::cut;

void bind_cut(py::module_& m) {
  m.def(
      "cut_kernels",
      []() {
        py::dict d;
        d["traction_q1"] = reinterpret_cast<std::uintptr_t>(&cut::traction_q1);
        return d;
      },
      "Addresses of the cut-cell kernels (ufcx tabulate_tensor ABI) for dolfinx Forms");
  m.def(
      "cut_layout",
      []() {
        py::dict d;
        d["phi"] = cut::Layout::phi;
        d["traction"] = cut::Layout::traction;
        d["traction_size"] = cut::Layout::traction_size;
        return d;
      },
      "Offsets of the packed coefficients the cut kernels read (see contact/cut_cell.h)");
  m.def(
      "cut_quadrature",
      [](const py::object& phi, int degree) {
        const auto phi_a = input<double>(Arg{"cut_quadrature", "phi"}, phi, {any, 4});
        const auto p = flat(phi_a);
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
      [](const py::object& phi) {
        const auto phi_a = input<double>(Arg{"inside_fraction", "phi"}, phi, {any, 4});
        const auto p = flat(phi_a);
        std::vector<double> f(p.size() / 4);
        for (std::size_t c = 0; c < f.size(); ++c)
          f[c] = cut::inside_fraction(std::span<const double, 4>(p.data() + 4 * c, 4));
        return to_numpy(std::move(f), {py::ssize_t(f.size())});
      },
      py::arg("phi"), "Inside area fraction of each cell, phi (n, 4) in tensor order");
  m.def(
      "cell_contours",
      [](const py::object& phi) {
        const auto phi_a = input<double>(Arg{"cell_contours", "phi"}, phi, {any, 4});
        const auto p = flat(phi_a);
        const std::size_t n = p.size() / 4;
        std::vector<double> t(4 * n);
        std::vector<std::int8_t> seg(4 * n, -1), ns(n);
        for (std::size_t c = 0; c < n; ++c) {
          const contact::CellContour k =
              contact::cell_contour(std::span<const double, 4>(p.data() + 4 * c, 4));
          for (int e = 0; e < 4; ++e)
            t[4 * c + e] = k.crossed[e] ? k.t[e] : std::numeric_limits<double>::quiet_NaN();
          for (int s = 0; s < k.num_segments; ++s)
            for (int a = 0; a < 2; ++a)
              seg[4 * c + 2 * s + a] = std::int8_t(k.segments[s][a]);
          ns[c] = std::int8_t(k.num_segments);
        }
        const auto nn = py::ssize_t(n);
        py::dict d;
        d["t"] = to_numpy(std::move(t), {nn, 4});
        d["segments"] = to_numpy(std::move(seg), {nn, 2, 2});
        d["num_segments"] = to_numpy(std::move(ns), {nn});
        d["edges"] = contact::cell_edges;
        return d;
      },
      py::arg("phi"),
      "Zero contour of the bilinear interpolant in each cell (marching squares, "
      "contact/contour.h): phi (n, 4) vertex values (tensor order) -> t (n, 4) crossing of "
      "edge e at X[a] + t (X[b] - X[a]), (a, b) = edges[e], NaN where not crossed; segments "
      "(n, 2, 2) the two edges each segment joins (-1 unused); num_segments (n,) 0, 1 or 2; "
      "edges (4, 2)");
  m.def(
      "cut_moment_weights",
      [](const py::object& phi, const py::object& points) {
        const char* f = "cut_moment_weights";
        const auto phi_a = input<double>(Arg{f, "phi"}, phi, {any, 4});
        const auto p = flat(phi_a);
        const auto pts = input<double>(Arg{f, "points"}, points, {any, 2}, "(nq, 2), nq > 0");
        if (pts.shape(0) == 0)
          contact::python::fail(Arg{f, "points"}, "expected an array of shape (nq, 2), nq > 0, "
                                                  "got (0, 2)");
        const std::span<const double> x = flat(pts);
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
      [](dolfinx::la::SparsityPattern& pattern, const py::object& dofs_in) {
        const contact::python::Indices dofs(Arg{"insert_blocks", "dofs"}, dofs_in, {any, any});
        dofs.check_range(0, contact::python::pattern_blocks(pattern));
        const std::size_t k = dofs.shape(1);
        for (py::ssize_t r = 0; r < dofs.shape(0); ++r) {
          std::span<const std::int32_t> d(dofs.flat().data() + r * k, k);
          pattern.insert(d, d);
        }
      },
      py::arg("pattern"), py::arg("dofs"),
      "Couple all block dofs of each row of dofs (n, k) in a SparsityPattern (e.g. the two "
      "cells of a ghost-penalty facet)");
}
