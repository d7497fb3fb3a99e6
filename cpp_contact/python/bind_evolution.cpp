// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Bindings of the level-set evolution (eqs 19-20): normal extension, WENO5/RK3 advection,
// gradient drift and inside area.
#include "array.h"
#include <contact/evolution.h>
#include <contact/levelset.h>

namespace py = pybind11;
using namespace contact;
using contact::python::any;
using contact::python::Arg;
using contact::python::fail;
using contact::python::flat;
using contact::python::input;
using contact::python::to_numpy;

void bind_evolution(py::module_& m) {
  m.def(
      "extend_normal",
      [](const StructuredGrid& grid, const py::object& phi_in, const py::object& known_in,
         const py::object& values_in, int max_sweeps, bool full_output) -> py::object {
        const char* f = "extend_normal";
        const auto n = py::ssize_t(grid.num_nodes());
        const auto phi = input<double>(Arg{f, "phi"}, phi_in);
        if (phi.size() != n)
          fail(Arg{f, "phi"}, "expected one value per node (" + std::to_string(n) + "), got " +
                                  std::to_string(phi.size()));
        const auto known = contact::python::flags(Arg{f, "known"}, known_in, std::size_t(n));
        const auto values = input<double>(Arg{f, "values"}, values_in);
        if (values.ndim() < 1 or values.ndim() > 2 or values.shape(0) != n or
            (values.ndim() == 2 and values.shape(1) < 1))
          fail(Arg{f, "values"},
               "expected shape (nodes,) or (nodes, m) with nodes = " + std::to_string(n) +
                   ", got " + contact::python::shape_str(values));
        const py::ssize_t mf = values.ndim() == 2 ? values.shape(1) : 1;
        std::vector<double> out(values.data(), values.data() + values.size());
        const ExtensionInfo info =
            extend_normal(grid, flat(phi), known.flat, out, std::size_t(mf), max_sweeps);
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
      [](const LevelSet& phi, const py::object& velocity, double time, double cfl) {
        const auto v = input<double>(Arg{"advect_levelset", "velocity"}, velocity,
                                     {py::ssize_t(phi.grid().num_nodes()), 2});
        AdvectResult r = advect(phi.grid(), phi.values(), flat(v), time, cfl);
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
      [](const py::object& line_in, double h) {
        const auto line = input<double>(Arg{"weno5_derivatives", "line"}, line_in, {any});
        const auto n = std::size_t(line.size());
        std::vector<double> mi(n), pl(n);
        weno5_derivatives(flat(line), h, mi, pl);
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
