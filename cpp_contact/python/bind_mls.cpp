// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// MLS projection of material-point values onto integration points (eqs 38-45).
#include "array.h"
#include <contact/mls.h>
#include <string>

namespace py = pybind11;
using contact::MLSOptions;
using contact::MLSProjector;
using contact::MLSResult;
using contact::python::any;
using contact::python::Arg;
using contact::python::fail;
using contact::python::flat;
using contact::python::input;
using contact::python::to_numpy;

namespace {
MLSProjector make_projector(const py::object& sources_in, double h, double rcond_min,
                            double widen_factor, int max_widenings) {
  const auto sources = input<double>(Arg{"MLSProjector", "sources"}, sources_in);
  if (sources.ndim() != 2 or (sources.shape(1) != 2 and sources.shape(1) != 3))
    fail(Arg{"MLSProjector", "sources"},
         "expected an array of shape (n, 2) or (n, 3), got " + contact::python::shape_str(sources));
  const int dim = int(sources.shape(1));
  return MLSProjector(flat(sources), dim, h, MLSOptions{rcond_min, widen_factor, max_widenings});
}

py::dict project(const MLSProjector& mls, const py::object& values_in, const py::object& targets_in,
                 int threads) {
  const char* f = "MLSProjector.project";
  const auto n = py::ssize_t(mls.num_points());
  const auto values = input<double>(Arg{f, "values"}, values_in);
  if ((values.ndim() != 1 and values.ndim() != 2) or values.shape(0) != n)
    fail(Arg{f, "values"}, "expected an array of shape (" + std::to_string(n) + ",) or (" +
                               std::to_string(n) + ", m), got " +
                               contact::python::shape_str(values));
  const std::size_t m = values.ndim() == 2 ? std::size_t(values.shape(1)) : 1;
  const auto targets = input<double>(Arg{f, "targets"}, targets_in, {any, mls.dim()});
  const auto x = flat(targets);
  const auto v = flat(values);
  if (threads < 1)
    fail(Arg{f, "threads"}, "must be >= 1, got " + std::to_string(threads));
  MLSResult r;
  {
    py::gil_scoped_release release;
    r = mls.project(v, m, x, threads);
  }
  const auto k = py::ssize_t(r.widening.size());
  py::dict d;
  if (values.ndim() == 2)
    d["values"] = to_numpy(std::move(r.values), {k, py::ssize_t(m)});
  else
    d["values"] = to_numpy(std::move(r.values), {k});
  d["widening"] = to_numpy(std::move(r.widening), {k});
  d["rcond"] = to_numpy(std::move(r.rcond), {k});
  d["neighbours"] = to_numpy(std::move(r.neighbours), {k});
  return d;
}
} // namespace

void bind_mls(py::module_& m) {
  m.def(
      "quadratic_spline_weight",
      [](const py::object& r_in) {
        const auto r = input<double>(Arg{"quadratic_spline_weight", "r"}, r_in);
        py::array_t<double> w(std::vector<py::ssize_t>(r.shape(), r.shape() + r.ndim()));
        const double* in = r.data();
        double* out = w.mutable_data();
        for (py::ssize_t i = 0; i < r.size(); ++i)
          out[i] = contact::quadratic_spline_weight(in[i]);
        return w;
      },
      py::arg("r"),
      "Quadratic spline weight of eq 45 at r = |x - x_p| / h (radial), elementwise, same shape");

  py::class_<MLSProjector>(m, "MLSProjector",
                           "Moving-least-squares projection (linear basis, eq 45 weight, eqs "
                           "38-44) from scattered sources to targets; k-d tree built once")
      .def(py::init(&make_projector), py::arg("sources"), py::arg("h"),
           py::arg("rcond_min") = MLSOptions{}.rcond_min,
           py::arg("widen_factor") = MLSOptions{}.widen_factor,
           py::arg("max_widenings") = MLSOptions{}.max_widenings,
           "sources: (n, 2|3) coordinates; h: support length (grid spacing), support radius "
           "1.5 h; a target whose fit has rcond < rcond_min (or fewer than d + 1 neighbours) is "
           "retried with h * widen_factor, up to max_widenings times, then raises RuntimeError")
      .def_property_readonly("num_points", &MLSProjector::num_points, "Number of sources n")
      .def_property_readonly("dim", &MLSProjector::dim, "Spatial dimension (2 or 3)")
      .def_property_readonly("h", &MLSProjector::h, "Support length h")
      .def("project", &project, py::arg("values"), py::arg("targets"), py::arg("threads") = 1,
           "Project values (n,) or (n, m) onto targets (k, d), on `threads` threads (the "
           "results do not depend on it). Returns a dict: values (k,) or "
           "(k, m), widening (k,) support factor used (1 = none), rcond (k,) reciprocal 1-norm "
           "condition number of the scaled moment matrix, neighbours (k,) int32 sources with "
           "positive weight");
}
