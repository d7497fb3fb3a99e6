// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Bindings of the level-set geometry: grids, level sets, shapes, projection (eq 25),
// reinitialisation and the intermediate contact surface (eqs 21-24).
#include "array.h"
#include <contact/contact_surface.h>
#include <contact/grid.h>
#include <contact/levelset.h>
#include <contact/projection.h>
#include <contact/reinit.h>
#include <contact/shapes.h>
#include <pybind11/stl.h>

namespace py = pybind11;
using namespace contact;
using contact::python::any;
using contact::python::Arg;
using contact::python::flat;
using contact::python::Indices;
using contact::python::input;
using contact::python::to_numpy;

namespace {
/// The dict both closest_point_projection overloads return.
py::dict projection_dict(contact::ProjectionResult&& r) {
  using contact::ProjectionStatus;
  const auto n = py::ssize_t(r.iterations.size());
  std::vector<std::int8_t> st(r.status.size());
  py::array_t<bool> conv(n);
  for (py::ssize_t p = 0; p < n; ++p) {
    st[p] = std::int8_t(r.status[p]);
    conv.mutable_at(p) = r.status[p] == ProjectionStatus::converged;
  }
  py::dict d;
  d["points"] = to_numpy(std::move(r.points), {n, 2});
  d["status"] = to_numpy(std::move(st), {n});
  d["iterations"] = to_numpy(std::move(r.iterations), {n});
  d["converged"] = conv;
  return d;
}
} // namespace

namespace {
/// A ContactSurface as a dict of numpy arrays (segments, cells, points, weights, normals,
/// tangents, segment)
py::dict surface_dict(ContactSurface&& s) {
  const auto ns = py::ssize_t(s.cells.size()), nq = py::ssize_t(s.weights.size());
  py::dict d;
  d["segments"] = to_numpy(std::move(s.segments), {ns, 2, 2});
  d["cells"] = to_numpy(std::move(s.cells), {ns});
  d["points"] = to_numpy(std::move(s.points), {nq, 2});
  d["weights"] = to_numpy(std::move(s.weights), {nq});
  d["normals"] = to_numpy(std::move(s.normals), {nq, 2});
  d["tangents"] = to_numpy(std::move(s.tangents), {nq, 2});
  d["segment"] = to_numpy(std::move(s.segment), {nq});
  return d;
}
} // namespace

void bind_geometry(py::module_& m) {
  py::class_<StructuredGrid>(m, "StructuredGrid",
                             "Tensor-product 2D grid, uniform or graded; nodes x-fastest")
      .def(py::init([](const py::object& x, const py::object& y) {
             const auto ax = input<double>(Arg{"StructuredGrid", "x"}, x, {any}),
                        ay = input<double>(Arg{"StructuredGrid", "y"}, y, {any});
             const auto sx = flat(ax), sy = flat(ay);
             return StructuredGrid({sx.begin(), sx.end()}, {sy.begin(), sy.end()});
           }),
           py::arg("x"), py::arg("y"), "Grid from strictly increasing node coordinates per axis")
      .def_static("uniform", &StructuredGrid::uniform, py::arg("lo"), py::arg("hi"), py::arg("n"),
                  "Uniform grid of [lo, hi] with n[d] cells along axis d")
      .def_property_readonly("x",
                             [](const StructuredGrid& g) {
                               return py::array_t<double>(py::ssize_t(g.axis(0).size()),
                                                          g.axis(0).data());
                             })
      .def_property_readonly("y",
                             [](const StructuredGrid& g) {
                               return py::array_t<double>(py::ssize_t(g.axis(1).size()),
                                                          g.axis(1).data());
                             })
      .def_property_readonly(
          "shape",
          [](const StructuredGrid& g) { return py::make_tuple(g.num_nodes(1), g.num_nodes(0)); },
          "(ny, nx): shape of node arrays")
      .def_property_readonly("num_nodes",
                             py::overload_cast<>(&StructuredGrid::num_nodes, py::const_))
      .def_property_readonly("num_cells", &StructuredGrid::num_cells)
      .def_property_readonly("min_spacing", &StructuredGrid::min_spacing)
      .def_property_readonly("max_spacing", &StructuredGrid::max_spacing)
      .def(
          "nodes",
          [](const StructuredGrid& g) {
            std::vector<double> p(2 * g.num_nodes());
            for (std::size_t j = 0; j < g.num_nodes(1); ++j)
              for (std::size_t i = 0; i < g.num_nodes(0); ++i) {
                p[2 * g.node(i, j)] = g.axis(0)[i];
                p[2 * g.node(i, j) + 1] = g.axis(1)[j];
              }
            return to_numpy(std::move(p), {py::ssize_t(g.num_nodes()), 2});
          },
          "Node coordinates, shape (num_nodes, 2), x-fastest")
      .def(
          "locate",
          [](const StructuredGrid& g, const py::object& points) {
            const auto pts =
                input<double>(Arg{"StructuredGrid.locate", "points"}, points, {any, 2});
            const auto x = flat(pts);
            std::vector<std::int64_t> c(x.size() / 2, -1);
            for (std::size_t p = 0; p < c.size(); ++p)
              if (auto ij = g.locate(std::span<const double, 2>(x.data() + 2 * p, 2)))
                c[p] = std::int64_t(g.cell((*ij)[0], (*ij)[1]));
            return to_numpy(std::move(c), {py::ssize_t(c.size())});
          },
          py::arg("points"), "Cell index of each point ((n, 2) -> (n,)), -1 outside the grid");

  py::class_<LevelSet>(m, "LevelSet", "Level set on a grid (eq 17), C1 bicubic Hermite interpolant")
      .def(py::init([](const StructuredGrid& g, const py::object& v) {
             const Arg arg{"LevelSet", "values"};
             const auto a = input<double>(arg, v);
             const auto ny = py::ssize_t(g.num_nodes(1)), nx = py::ssize_t(g.num_nodes(0));
             if (a.ndim() == 1)
               contact::python::check_shape(arg, a, {nx * ny});
             else
               contact::python::check_shape(arg, a, {ny, nx});
             const auto s = flat(a);
             return LevelSet(g, {s.begin(), s.end()});
           }),
           py::arg("grid"), py::arg("values"), "From node values, flat x-fastest or shape (ny, nx)")
      .def_property_readonly("grid", &LevelSet::grid)
      .def_property_readonly(
          "values",
          [](const LevelSet& l) {
            return py::array_t<double>(
                {py::ssize_t(l.grid().num_nodes(1)), py::ssize_t(l.grid().num_nodes(0))},
                l.values().data());
          },
          "Node values as a (ny, nx) copy")
      .def(
          "evaluate",
          [](const LevelSet& l, const py::object& points) {
            const auto pts = input<double>(Arg{"LevelSet.evaluate", "points"}, points, {any, 2});
            const auto x = flat(pts);
            std::vector<double> v(x.size() / 2), g(x.size());
            {
              py::gil_scoped_release release; // pure C++: the pair geometries run in threads
              l.evaluate(x, v, g);
            }
            const auto n = py::ssize_t(v.size());
            return py::make_tuple(to_numpy(std::move(v), {n}), to_numpy(std::move(g), {n, 2}));
          },
          py::arg("points"), "(values (n,), gradients (n, 2)) of the interpolant at (n, 2) points");

  py::class_<Shape, std::shared_ptr<Shape>>(m, "Shape", "Analytic body: phi < 0 inside")
      .def(
          "__call__",
          [](const Shape& s, const py::object& points) {
            const auto pts = input<double>(Arg{"Shape.__call__", "points"}, points, {any, 2});
            const auto x = flat(pts);
            std::vector<double> v(x.size() / 2);
            s.evaluate(x, v);
            return to_numpy(std::move(v), {py::ssize_t(v.size())});
          },
          py::arg("points"), "Level-set values at (n, 2) points");
  py::class_<Circle, Shape, std::shared_ptr<Circle>>(m, "Circle")
      .def(py::init<std::array<double, 2>, double>(), py::arg("center"), py::arg("radius"));
  py::class_<Ellipse, Shape, std::shared_ptr<Ellipse>>(m, "Ellipse")
      .def(py::init<std::array<double, 2>, double, double, double>(), py::arg("center"),
           py::arg("a"), py::arg("b"), py::arg("angle") = 0.0)
      .def(
          "closest_point",
          [](const Ellipse& e, const py::object& points) {
            const auto pts =
                input<double>(Arg{"Ellipse.closest_point", "points"}, points, {any, 2});
            const auto x = flat(pts);
            std::vector<double> q(x.size());
            for (std::size_t p = 0; p < x.size() / 2; ++p) {
              auto c = e.closest_point({x[2 * p], x[2 * p + 1]});
              q[2 * p] = c[0], q[2 * p + 1] = c[1];
            }
            return to_numpy(std::move(q), {py::ssize_t(x.size() / 2), 2});
          },
          py::arg("points"), "Exact closest points on the ellipse");
  py::class_<Box, Shape, std::shared_ptr<Box>>(m, "Box").def(
      py::init<std::array<double, 2>, std::array<double, 2>>(), py::arg("lo"), py::arg("hi"));
  py::class_<Polygon, Shape, std::shared_ptr<Polygon>>(m, "Polygon")
      .def(py::init([](const py::object& v) {
             const auto a = input<double>(Arg{"Polygon", "vertices"}, v, {any, 2});
             const auto s = flat(a);
             return std::make_shared<Polygon>(std::vector<double>(s.begin(), s.end()));
           }),
           py::arg("vertices"));
  py::class_<Union, Shape, std::shared_ptr<Union>>(m, "Union")
      .def(py::init([](const std::vector<std::shared_ptr<Shape>>& parts) {
             return std::make_shared<Union>(
                 std::vector<std::shared_ptr<const Shape>>(parts.begin(), parts.end()));
           }),
           py::arg("shapes"));
  py::class_<Intersection, Shape, std::shared_ptr<Intersection>>(m, "Intersection")
      .def(py::init([](const std::vector<std::shared_ptr<Shape>>& parts) {
             return std::make_shared<Intersection>(
                 std::vector<std::shared_ptr<const Shape>>(parts.begin(), parts.end()));
           }),
           py::arg("shapes"));
  py::class_<Complement, Shape, std::shared_ptr<Complement>>(m, "Complement")
      .def(
          py::init([](const std::shared_ptr<Shape>& s) { return std::make_shared<Complement>(s); }),
          py::arg("shape"));

  m.def("levelset_from_shape", &levelset_from_shape, py::arg("grid"), py::arg("shape"),
        py::call_guard<py::gil_scoped_release>(), "Sample an analytic shape at the grid nodes");
  m.def(
      "levelset_from_polyline",
      [](const StructuredGrid& g, const py::object& v, int band) {
        const auto a = input<double>(Arg{"levelset_from_polyline", "vertices"}, v, {any, 2});
        return levelset_from_polyline(g, flat(a), band);
      },
      py::arg("grid"), py::arg("vertices"), py::arg("band") = 3,
      "Signed distance to a closed polyline: exact in a band, fast sweeping beyond");
  m.def("reinitialize", &reinitialize, py::arg("phi"), py::arg("max_sweeps") = 8,
        py::arg("cap") = std::numeric_limits<double>::infinity(),
        py::call_guard<py::gil_scoped_release>(),
        "Signed distance with the same zero contour (projection near it, fast sweeping beyond; "
        "+-cap beyond cap)");

  py::enum_<ProjectionStatus>(m, "ProjectionStatus")
      .value("converged", ProjectionStatus::converged)
      .value("max_iterations", ProjectionStatus::max_iterations)
      .value("vanishing_gradient", ProjectionStatus::vanishing_gradient)
      .value("left_grid", ProjectionStatus::left_grid);
  m.def(
      "closest_point_projection",
      [](const LevelSet& phi, const py::object& points, double rtol, int max_iterations,
         double grad_tol) {
        const auto pts = input<double>(Arg{"closest_point_projection", "points"}, points, {any, 2});
        ProjectionResult r;
        {
          py::gil_scoped_release release;
          r = closest_point_projection(phi, flat(pts),
                                       ProjectionOptions{rtol, max_iterations, grad_tol});
        }
        return projection_dict(std::move(r));
      },
      py::arg("phi"), py::arg("points"), py::arg("rtol") = 1e-10, py::arg("max_iterations") = 50,
      py::arg("grad_tol") = 1e-8,
      "Closest points on phi = 0 (eq 25) of (n, 2) points inside the grid. Returns a dict: "
      "points (n, 2), status (int8, ProjectionStatus), iterations, converged (bool)");
  m.def(
      "closest_point_projection",
      [](const Shape& shape, const py::object& points, double length_scale, double rtol,
         int max_iterations, double grad_tol) {
        const auto pts = input<double>(Arg{"closest_point_projection", "points"}, points, {any, 2});
        ProjectionResult r;
        {
          py::gil_scoped_release release;
          r = closest_point_projection(shape, flat(pts), length_scale,
                                       ProjectionOptions{rtol, max_iterations, grad_tol});
        }
        return projection_dict(std::move(r));
      },
      py::arg("shape"), py::arg("points"), py::arg("length_scale"), py::arg("rtol") = 1e-10,
      py::arg("max_iterations") = 20, py::arg("grad_tol") = 1e-8,
      "Closest points on the boundary of an exact signed-distance shape (x - d grad d, "
      "repeated); same dict as the level-set overload");

  m.def("min_levelset", &min_levelset, py::arg("phi_i"), py::arg("phi_j"), "phi_min (eq 21)");
  m.def("intermediate_levelset", &intermediate_levelset, py::arg("phi_i"), py::arg("phi_j"),
        "phi_int = (phi_i - phi_j)/2 (eq 23)");
  m.def("closing_levelset", &closing_levelset, py::arg("phi_i"), py::arg("phi_j"), py::arg("eps"),
        py::arg("cap") = std::numeric_limits<double>::infinity(),
        "reinitialize(phi_min - eps, cap=cap) + eps (eq 22)");
  m.def(
      "contact_region",
      [](const LevelSet& a, const LevelSet& b, double eps) {
        auto f = contact_region(a, b, eps);
        return to_numpy(std::move(f),
                        {py::ssize_t(a.grid().num_nodes(1)), py::ssize_t(a.grid().num_nodes(0))});
      },
      py::arg("phi_i"), py::arg("phi_j"), py::arg("eps"),
      "Node flags (ny, nx) of the contact region (eq 22) including overlaps");
  m.def(
      "contact_surface",
      [](const LevelSet& a, const LevelSet& b, double eps, int num_gauss) {
        ContactSurface s;
        {
          py::gil_scoped_release release;
          s = contact_surface(a, b, eps, num_gauss);
        }
        return surface_dict(std::move(s));
      },
      py::arg("phi_i"), py::arg("phi_j"), py::arg("eps"), py::arg("num_gauss") = 2,
      "Gamma_c (eq 24): segments of phi_int = 0 in the contact region with Gauss points, weights, "
      "normals (body i -> j) and tangents");
  m.def(
      "segment_quadrature",
      [](const LevelSet& phi_int, const py::object& segments_in, const py::object& cells_in,
         int num_gauss) {
        const char* f = "segment_quadrature";
        const Indices cells(Arg{f, "cells"}, cells_in, {any});
        // a segment's cell indexes the grid's cells
        cells.check_range(0, std::int64_t(phi_int.grid().num_cells()));
        const auto segments =
            input<double>(Arg{f, "segments"}, segments_in, {py::ssize_t(cells.size()), 2, 2});
        ContactSurface s = segment_quadrature(phi_int, flat(segments), cells.flat(), num_gauss);
        return surface_dict(std::move(s));
      },
      py::arg("phi_int"), py::arg("segments"), py::arg("cells"), py::arg("num_gauss") = 2,
      "Gauss points, weights, normals and tangents on given segments of Gamma_c (eq 24)");
}
