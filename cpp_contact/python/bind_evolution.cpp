// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Bindings of the level-set evolution (eqs 19-20): normal extension, WENO5/RK3 advection,
// gradient drift and inside area.
#include "array.h"
#include <contact/evolution.h>
#include <contact/levelset.h>

namespace py = pybind11;
using namespace contact;
using contact::python::as_span;
using contact::python::carray;
using contact::python::to_numpy;

namespace {
using i8array = py::array_t<std::int8_t, py::array::c_style | py::array::forcecast>;
} // namespace

void bind_evolution(py::module_& m) {
  m.def(
      "extend_normal",
      [](const StructuredGrid& grid, const carray& phi, const py::array& known_in,
         const carray& values, int max_sweeps, bool full_output) -> py::object {
        const auto n = py::ssize_t(grid.num_nodes());
        if (phi.size() != n)
          throw std::invalid_argument("extend_normal: phi must have one value per node (" +
                                      std::to_string(n) + "), got " + std::to_string(phi.size()));
        const i8array known = i8array::ensure(known_in);
        if (!known or known.size() != n)
          throw std::invalid_argument("extend_normal: known must be a bool/int8 array with one "
                                      "flag per node (" +
                                      std::to_string(n) + ")");
        if (values.ndim() < 1 or values.ndim() > 2 or values.shape(0) != n or
            (values.ndim() == 2 and values.shape(1) < 1))
          throw std::invalid_argument("extend_normal: values must have shape (nodes,) or "
                                      "(nodes, m) with nodes = " +
                                      std::to_string(n));
        const py::ssize_t mf = values.ndim() == 2 ? values.shape(1) : 1;
        std::vector<double> out(values.data(), values.data() + values.size());
        const ExtensionInfo info = extend_normal(
            grid, as_span(phi, "phi"), std::span<const std::int8_t>(known.data(), std::size_t(n)),
            out, std::size_t(mf), max_sweeps);
        std::vector<py::ssize_t> shape = {n};
        if (values.ndim() == 2)
          shape.push_back(mf);
        py::array a = to_numpy(std::move(out), shape);
        if (!full_output)
          return a;
        py::dict d;
        d["sweeps"] = info.sweeps;
        d["fallback"] = info.fallback;
        return py::make_tuple(a, d);
      },
      py::arg("grid"), py::arg("phi"), py::arg("known"), py::arg("values"),
      py::arg("max_sweeps") = 20, py::arg("full_output") = false,
      "Constant extension along the normal (eq 20) of node values from the known nodes, upwind "
      "from smaller phi. values (nodes,) or (nodes, m) -> same shape. With full_output=True "
      "returns (array, dict(sweeps, fallback)); fallback counts nodes without an upwind path to "
      "a known node, filled by averaging their neighbours.");

  m.def(
      "advect_levelset",
      [](const LevelSet& phi, const carray& velocity, double time, double cfl) {
        AdvectResult r =
            advect(phi.grid(), phi.values(), as_span(velocity, "velocity", 2), time, cfl);
        py::dict d;
        d["substeps"] = r.substeps;
        d["levelset"] = LevelSet(phi.grid(), std::move(r.values));
        return d;
      },
      py::arg("phi"), py::arg("velocity"), py::arg("time") = 1.0, py::arg("cfl") = 0.5,
      "phi_t + v . grad phi = 0 (eq 19) with HJ-WENO5 and TVD-RK3 on a uniform grid; velocity "
      "(nodes, 2) at the nodes, steady over the pseudo-time. Returns dict(levelset, substeps).");

  m.def(
      "weno5_derivatives",
      [](const carray& line, double h) {
        if (line.ndim() != 1)
          throw std::invalid_argument("weno5_derivatives: line must be a 1D array");
        const auto n = std::size_t(line.size());
        std::vector<double> mi(n), pl(n);
        weno5_derivatives(as_span(line, "line"), h, mi, pl);
        const auto sn = py::ssize_t(n);
        return py::make_tuple(to_numpy(std::move(mi), {sn}), to_numpy(std::move(pl), {sn}));
      },
      py::arg("line"), py::arg("h"),
      "One-sided HJ-WENO5 derivatives (D-, D+) of uniformly spaced values (linear-extrapolation "
      "ghosts)");

  m.def(
      "levelset_gradient_drift",
      [](const LevelSet& phi, double band) {
        return gradient_drift(phi.grid(), phi.values(), band);
      },
      py::arg("phi"), py::arg("band"),
      "max | |grad phi| - 1 | over nodes within `band` (length) of the zero contour");

  m.def(
      "levelset_area", [](const LevelSet& phi) { return inside_area(phi.grid(), phi.values()); },
      py::arg("phi"), "Area of {phi < 0}: sum of the clipped cut-cell polygons");
}
