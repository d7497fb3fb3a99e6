// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Bindings of the point location on unstructured P1 meshes (triangles, quadrilaterals), and
// of the Q1 field evaluation at located points of grid cells.
#include "array.h"
#include <contact/grid_field.h>
#include <contact/grid_location.h>
#include <contact/point_location.h>
#include <numeric>
#include <optional>
#include <pybind11/stl.h>

namespace py = pybind11;
using namespace contact;
using contact::python::any;
using contact::python::Arg;
using contact::python::fail;
using contact::python::flat;
using contact::python::Indices;
using contact::python::input;
using contact::python::to_numpy;

namespace {
/// Both locators' locate(points, max_distance) as a dict of numpy arrays.
template <class Locator>
py::dict locate(const Locator& loc, const py::object& points, double max_distance,
                const char* name) {
  const auto pts = input<double>(Arg{name, "points"}, points, {any, 2});
  const auto x = flat(pts);
  LocatedPoints r;
  {
    py::gil_scoped_release release;
    r = loc.locate(x, max_distance);
  }
  const auto n = py::ssize_t(r.cells.size());
  py::dict d;
  d["cells"] = to_numpy(std::move(r.cells), {n});
  d["X"] = to_numpy(std::move(r.X), {n, 2});
  d["outside"] = to_numpy(std::move(r.outside), {n});
  return d;
}
CellLocator make_locator(const py::object& x_in, const py::object& cells_in,
                         const py::object& subset_in) {
  const char* f = "CellLocator";
  const auto x = input<double>(Arg{f, "x"}, x_in);
  if (x.ndim() != 2 or (x.shape(1) != 2 and x.shape(1) != 3))
    fail(Arg{f, "x"},
         "expected an array of shape (nv, 2) or (nv, 3), got " + contact::python::shape_str(x));
  const Indices cells(Arg{f, "cells"}, cells_in);
  if (cells.ndim() != 2 or (cells.shape(1) != 3 and cells.shape(1) != 4))
    fail(Arg{f, "cells"},
         "expected an array of shape (nc, 3) (triangles) or (nc, 4) (quadrilaterals), got " +
             contact::python::shape_str(cells.array()));
  // vertex indices index the rows of x
  cells.check_range(0, x.shape(0));
  std::vector<std::int32_t> all;
  std::optional<Indices> subset;
  std::span<const std::int32_t> s;
  if (!subset_in.is_none()) {
    subset.emplace(Arg{f, "subset"}, subset_in, std::initializer_list<py::ssize_t>{any});
    // cell indices index the rows of cells
    subset->check_range(0, cells.shape(0));
    s = subset->flat();
  } else {
    all.resize(std::size_t(cells.shape(0)));
    std::iota(all.begin(), all.end(), 0);
    s = all;
  }
  return CellLocator(flat(x), int(x.shape(1)), cells.flat(), int(cells.shape(1)), s);
}
} // namespace

void bind_location(py::module_& m) {
  py::class_<GridCellLocator>(m, "GridCellLocator",
                              "Point location among one body's cells of a structured grid: "
                              "bisection on the lines, a table over the body's cells")
      .def(py::init([](const py::object& xl, const py::object& yl, const py::object& corners_in,
                       const py::object& cells_in) {
             const char* f = "GridCellLocator";
             const auto x = input<double>(Arg{f, "xlines"}, xl, {any});
             const auto y = input<double>(Arg{f, "ylines"}, yl, {any});
             const auto corners = input<double>(Arg{f, "corners"}, corners_in, {any, 4, 2});
             const Indices cells(Arg{f, "cells"}, cells_in, {corners.shape(0)});
             return GridCellLocator(flat(x), flat(y), flat(corners), cells.flat());
           }),
           py::arg("xlines"), py::arg("ylines"), py::arg("corners"), py::arg("cells"),
           "xlines, ylines: the grid lines; corners (n, 4, 2): each cell's vertices in DOLFINx "
           "order; cells (n,): the index reported for each")
      .def_property_readonly("num_cells", &GridCellLocator::num_cells)
      .def(
          "locate",
          [](const GridCellLocator& l, const py::object& p, double d) {
            return locate(l, p, d, "GridCellLocator.locate");
          },
          py::arg("points"), py::arg("max_distance") = 0.0,
          "Locate (n, 2) points: a dict of cells (int32, -1 if no cell of the 3 x 3 "
          "neighbourhood is within max_distance), X (n, 2) reference coordinates (NaN there) "
          "and outside (0 inside, else the distance to the cell; inf there)");

  m.def(
      "q1_evaluate",
      [](const py::object& u_in, const py::object& dofs_in, const py::object& X_in,
         const py::object& extent_in) {
        const char* f = "q1_evaluate";
        const auto u = input<double>(Arg{f, "u"}, u_in, {any, any});
        const auto X = input<double>(Arg{f, "X"}, X_in, {any, any});
        const py::ssize_t n = X.shape(0), d = X.shape(1), bs = u.shape(1);
        if (d != 2 and d != 3)
          fail(Arg{f, "X"}, "expected (n, 2) or (n, 3), got " + contact::python::shape_str(X));
        const auto extent = input<double>(Arg{f, "extent"}, extent_in, {n, d});
        const Indices dofs(Arg{f, "dofs"}, dofs_in, {n, py::ssize_t(1) << d});
        dofs.check_range(0, u.shape(0));
        std::vector<double> out(std::size_t(n * bs * (1 + d)));
        {
          py::gil_scoped_release release;
          q1_evaluate(flat(u), int(bs), dofs.flat(), flat(X), flat(extent), int(d), out);
        }
        py::dict r;
        auto all = to_numpy(std::move(out), {n, bs * (1 + d)});
        r["values"] = all[py::make_tuple(py::slice(0, n, 1), py::slice(0, bs, 1))];
        r["grad"] = all[py::make_tuple(py::slice(0, n, 1), py::slice(bs, bs * (1 + d), 1))].attr(
            "reshape")(n, bs, d);
        return r;
      },
      py::arg("u"), py::arg("dofs"), py::arg("X"), py::arg("extent"),
      "Value and gradient of a Q1 vector field u (num_dofs, bs) at n points of axis-aligned grid "
      "cells: dofs (n, 2^d) of each point's cell in basix vertex order, X (n, d) reference "
      "coordinates (extrapolated outside [0, 1]^d), extent (n, d) the cells' edge lengths. "
      "Returns a dict: values (n, bs), grad (n, bs, d) with grad[:, c, a] = du_c / dx_a");

  py::class_<CellLocator>(
      m, "CellLocator",
      "Cells of one body of a P1 mesh (triangles or DOLFINx-ordered quadrilaterals), binned on a "
      "uniform grid for O(1) average point location")
      .def(py::init(&make_locator), py::arg("x"), py::arg("cells"), py::arg("subset") = py::none(),
           "x: vertex coordinates (nv, 2|3) (e.g. mesh.geometry.x); cells: vertex indices "
           "(nc, 3|4) in DOLFINx order (e.g. mesh.geometry.dofmap.array.reshape(-1, nverts)); "
           "subset: cell indices to index (default: all cells)")
      .def_property_readonly("num_cells", &CellLocator::num_cells, "Number of indexed cells")
      .def_property_readonly("num_vertices", &CellLocator::num_vertices, "3 or 4")
      .def_property_readonly("num_bins", &CellLocator::num_bins, "Bins along x and y")
      .def_property_readonly("bin_size", &CellLocator::bin_size, "Bin size along x and y")
      .def(
          "locate",
          [](const CellLocator& l, const py::object& p, double d) {
            return locate(l, p, d, "CellLocator.locate");
          },
          py::arg("points"), py::arg("max_distance") = 0.0,
          "Locate (n, 2) points. Returns a dict: cells (int32, -1 if further than max_distance "
          "from every indexed cell), X (n, 2) reference coordinates (extrapolated for points "
          "outside the cells, NaN if cells == -1) and outside (0 inside, else the distance to "
          "the cell; inf if cells == -1). Points outside all cells but within max_distance get "
          "the nearest cell.");
}
