// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Bindings of the point location on unstructured P1 meshes (triangles, quadrilaterals).
#include "array.h"
#include <contact/point_location.h>
#include <numeric>
#include <optional>
#include <pybind11/stl.h>

namespace py = pybind11;
using namespace contact;
using contact::python::as_span;
using contact::python::carray;
using contact::python::to_numpy;

namespace {
using iarray = py::array_t<std::int32_t, py::array::c_style | py::array::forcecast>;

CellLocator make_locator(const carray& x, const iarray& cells,
                         const std::optional<iarray>& subset) {
  if (x.ndim() != 2 or (x.shape(1) != 2 and x.shape(1) != 3))
    throw std::invalid_argument("x: expected an array of shape (nv, 2) or (nv, 3)");
  if (cells.ndim() != 2 or (cells.shape(1) != 3 and cells.shape(1) != 4))
    throw std::invalid_argument("cells: expected an array of shape (nc, 3) (triangles) or "
                                "(nc, 4) (quadrilaterals)");
  if (subset and subset->ndim() != 1)
    throw std::invalid_argument("subset: expected a 1D array of cell indices");
  std::span<const std::int32_t> c(cells.data(), std::size_t(cells.size()));
  std::vector<std::int32_t> all;
  std::span<const std::int32_t> s;
  if (subset)
    s = std::span<const std::int32_t>(subset->data(), std::size_t(subset->size()));
  else {
    all.resize(std::size_t(cells.shape(0)));
    std::iota(all.begin(), all.end(), 0);
    s = all;
  }
  return CellLocator(as_span(x, "x"), int(x.shape(1)), c, int(cells.shape(1)), s);
}
} // namespace

void bind_location(py::module_& m) {
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
          [](const CellLocator& loc, const carray& pts, double max_distance) {
            auto x = as_span(pts, "points", 2);
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
          },
          py::arg("points"), py::arg("max_distance") = 0.0,
          "Locate (n, 2) points. Returns a dict: cells (int32, -1 if further than max_distance "
          "from every indexed cell), X (n, 2) reference coordinates (extrapolated for points "
          "outside the cells, NaN if cells == -1) and outside (0 inside, else the distance to "
          "the cell; inf if cells == -1). Points outside all cells but within max_distance get "
          "the nearest cell.");
}
