// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Bindings of the contact law: gap functions (eqs 26-31), the penalty Coulomb return mapping
// (Algorithm 1, eqs 8, 11, 12) with its consistent tangent, and the friction history.
// std::invalid_argument from the C++ core reaches Python as ValueError.
#include "array.h"
#include <algorithm>
#include <contact/gaps.h>
#include <contact/return_mapping.h>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace py = pybind11;
using contact::python::any;
using contact::python::Arg;
using contact::python::check_shape;
using contact::python::fail;
using contact::python::flat;
using contact::python::input;
using contact::python::to_numpy;

namespace {
/// Shape of a per-point tangential array: (n,) in 2D (tdim 1), (n, tdim) otherwise.
std::vector<py::ssize_t> tangential_shape(std::size_t n, int tdim) {
  if (tdim == 1)
    return {py::ssize_t(n)};
  return {py::ssize_t(n), py::ssize_t(tdim)};
}

/// Copy of a history buffer as a numpy array of tangential shape.
py::array_t<double> history_array(std::span<const double> v, std::size_t n, int tdim) {
  return to_numpy(std::vector<double>(v.begin(), v.end()), tangential_shape(n, tdim));
}
} // namespace

void bind_contact(py::module_& m) {
  using contact::ContactState;
  using contact::FrictionHistory;

  py::enum_<ContactState>(m, "ContactState",
                          "State of a contact point after the return mapping (Algorithm 1)")
      .value("open", ContactState::open, "g_n >= 0: no traction (active set eq 32 excludes it)")
      .value("stick", ContactState::stick, "trial state admissible, phi_tr <= 0 (eq 11)")
      .value("slip", ContactState::slip, "returned to the Coulomb cone |tau_t| = mu |tau_n|");

  m.def(
      "return_mapping",
      [](const py::object& g_n_in, const py::object& g_t_in, const py::object& gtp_old_in,
         double eps_n, double eps_t, double mu) {
        const char* f = "return_mapping";
        const auto g_n = input<double>(Arg{f, "g_n"}, g_n_in, {any});
        const py::ssize_t n = g_n.shape(0);
        const auto g_t = input<double>(Arg{f, "g_t"}, g_t_in);
        if ((g_t.ndim() != 1 and g_t.ndim() != 2) or g_t.shape(0) != n)
          fail(Arg{f, "g_t"}, "expected shape (n,) or (n, tdim) with n = len(g_n) = " +
                                  std::to_string(n) + ", got " + contact::python::shape_str(g_t));
        const auto gtp_old = input<double>(Arg{f, "gtp_old"}, gtp_old_in);
        if (gtp_old.ndim() != g_t.ndim() or
            !std::equal(g_t.shape(), g_t.shape() + g_t.ndim(), gtp_old.shape()))
          fail(Arg{f, "gtp_old"}, "expected the shape of g_t " + contact::python::shape_str(g_t) +
                                      ", got " + contact::python::shape_str(gtp_old));
        // The C++ core rejects tdim not in {1, 2}
        const int tdim = g_t.ndim() == 1 ? 1 : int(g_t.shape(1));
        const std::size_t nn = n, td = std::max(tdim, 0), nd = 1 + td;

        std::vector<double> tau_n(nn), tau_t(nn * td), gtp(nn * td), D(nn * nd * nd);
        std::vector<ContactState> state(nn);
        contact::return_mapping({eps_n, eps_t, mu}, tdim, flat(g_n), flat(g_t), flat(gtp_old),
                                tau_n, tau_t, gtp, state, D);
        std::vector<std::int8_t> s8(nn);
        std::ranges::transform(state, s8.begin(), [](ContactState s) { return std::int8_t(s); });

        const std::vector<py::ssize_t> tshape(g_t.shape(), g_t.shape() + g_t.ndim());
        py::dict out;
        out["tau_n"] = to_numpy(std::move(tau_n), {n});
        out["tau_t"] = to_numpy(std::move(tau_t), tshape);
        out["gtp_trial"] = to_numpy(std::move(gtp), tshape);
        out["state"] = to_numpy(std::move(s8), {n});
        out["tangent"] = to_numpy(std::move(D), {n, py::ssize_t(nd), py::ssize_t(nd)});
        return out;
      },
      py::arg("g_n"), py::arg("g_t"), py::arg("gtp_old"), py::arg("eps_n"), py::arg("eps_t"),
      py::arg("mu"),
      R"(Penalty Coulomb return mapping (Algorithm 1; eqs 8, 11, 12), vectorised over points.

g_n: (n,) normal gaps (eq 27); g_t: (n,) in 2D (tdim 1) or (n, tdim) tangential gaps (eq 30);
gtp_old: committed plastic slip, shape of g_t. eps_n, eps_t > 0 are compliances (eq 51), mu >= 0.
Compression negative: tau_n = min(g_n, 0)/eps_n (eq 8); g_n >= 0 is open (eq 32).
Returns a dict: tau_n (n,), tau_t and gtp_trial (shape of g_t; tau_t = (g_t - gtp_trial)/eps_t),
state int8 (n,) (0 open, 1 stick, 2 slip, see ContactState), tangent (n, 1+tdim, 1+tdim) =
d[tau_n, tau_t]/d[g_n, g_t], exact and non-symmetric in slip. Open points get gtp_trial = g_t;
with mu == 0 active points are slip with tau_t = 0 and gtp_trial = g_t.
Raises ValueError on shape mismatch, eps <= 0, mu < 0, non-finite input, tdim not in {1, 2}.)");

  py::class_<FrictionHistory>(m, "FrictionHistory",
                              R"(Plastic slip g_t^p (eqs 10-12) with committed and trial values.

Newton iterations write `trial` (e.g. trial = return_mapping(...)["gtp_trial"]);
commit() accepts a converged step, restore() resets trial to the exact committed values.
Arrays are copies of shape (n,) for tdim 1 and (n, tdim) otherwise.)")
      .def(py::init<std::size_t, int>(), py::arg("n"), py::arg("tdim"),
           "n points, tangential dimension tdim in {1, 2}, zero initial slip (ValueError "
           "otherwise)")
      .def_property_readonly("n", &FrictionHistory::size, "Number of points")
      .def_property_readonly("tdim", &FrictionHistory::tdim, "Tangential dimension")
      .def("__len__", &FrictionHistory::size)
      .def_property_readonly(
          "committed",
          [](const FrictionHistory& h) { return history_array(h.committed(), h.size(), h.tdim()); },
          "Copy of the committed plastic slip g_t^p (read at every iteration, Algorithm 1)")
      .def_property(
          "trial",
          [](const FrictionHistory& h) { return history_array(h.trial(), h.size(), h.tdim()); },
          [](FrictionHistory& h, const py::object& v) {
            const Arg arg{"FrictionHistory", "trial"};
            const auto a = input<double>(arg, v);
            const auto n = py::ssize_t(h.size());
            if (h.tdim() == 1)
              check_shape(arg, a, {n});
            else
              check_shape(arg, a, {n, py::ssize_t(h.tdim())});
            std::ranges::copy(flat(a), h.trial().begin());
          },
          "Copy of the trial plastic slip (Algorithm 1, g_t^{p,(k+1)}); assignable from numpy")
      .def("commit", &FrictionHistory::commit, "Accept the trial slip (converged step)")
      .def("restore", &FrictionHistory::restore,
           "Reset the trial slip to the committed values exactly (rejected iteration or step)");

  m.def(
      "compute_gaps",
      [](const py::object& p_i, const py::object& p_j, const py::object& u_i, const py::object& u_j,
         const py::object& normals, const py::object& tangents) {
        const char* f = "compute_gaps";
        const auto pi = input<double>(Arg{f, "p_i"}, p_i, {any, 2});
        const py::ssize_t n = pi.shape(0);
        const auto pj = input<double>(Arg{f, "p_j"}, p_j, {n, 2}),
                   ui = input<double>(Arg{f, "u_i"}, u_i, {n, 2}),
                   uj = input<double>(Arg{f, "u_j"}, u_j, {n, 2}),
                   nrm = input<double>(Arg{f, "normals"}, normals, {n, 2}),
                   tng = input<double>(Arg{f, "tangents"}, tangents, {n, 2});
        std::vector<double> g_n0(n), j_int(n), g_n(n), g_t(n);
        contact::compute_gaps(flat(pi), flat(pj), flat(ui), flat(uj), flat(nrm), flat(tng), g_n0,
                              j_int, g_n, g_t);
        py::dict out;
        out["g_n0"] = to_numpy(std::move(g_n0), {n});
        out["j_int"] = to_numpy(std::move(j_int), {n});
        out["g_n"] = to_numpy(std::move(g_n), {n});
        out["g_t"] = to_numpy(std::move(g_t), {n});
        return out;
      },
      py::arg("p_i"), py::arg("p_j"), py::arg("u_i"), py::arg("u_j"), py::arg("normals"),
      py::arg("tangents"),
      R"(Gap functions at contact points, 2D (eqs 26-31). All inputs have shape (n, 2).

p_i, p_j: closest points on bodies i and j (eq 25); u_i, u_j: displacements there;
normals: contact normal from body i towards body j; tangents: contact tangent.
Returns a dict of (n,) arrays: g_n0 = (p_j - p_i).n (eq 28), j_int = (u_j - u_i).n (eq 29),
g_n = g_n0 + j_int (eq 27), g_t = (u_j - u_i).t (eq 30). ValueError on shape mismatch.)");
}
