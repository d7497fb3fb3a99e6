// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// DOLFINx/PETSc glue of the contact kernel (eq 48): the pure numerics live in
// contact/contact_kernel.h; here element blocks go into a PETSc Mat by local block indices
// and the coupling blocks into a dolfinx SparsityPattern.
#include "array.h"
#include "la.h"
#include <caster_petsc.h>
#include <contact/contact_kernel.h>
#include <pybind11/stl.h>
#include <string>

namespace py = pybind11;
using contact::python::any;
using contact::python::Arg;
using contact::python::check_range;
using contact::python::flat;
using contact::python::Indices;
using contact::python::input;
using contact::python::pattern_blocks;
using contact::python::petsc_check;
using contact::python::to_numpy;

namespace {
/// @brief A copy of a checked float64 input as a std::vector.
std::vector<double> f64_vector(const Arg& arg, const py::handle& h,
                               std::initializer_list<py::ssize_t> pattern) {
  const auto a = input<double>(arg, h, pattern);
  return std::vector<double>(a.data(), a.data() + a.size());
}

/// @brief Check the block dofs of a quadrature against the number of blocks they index.
void check_dofs(const char* function, const contact::ContactQuadrature& q, std::int64_t blocks,
                const char* what) {
  const std::string i = std::string("quadrature.dofs_i (blocks of ") + what + ")",
                    j = std::string("quadrature.dofs_j (blocks of ") + what + ")";
  check_range(Arg{function, i.c_str()}, q.dofs_i, 0, blocks);
  check_range(Arg{function, j.c_str()}, q.dofs_j, 0, blocks);
}

/// @brief The law points whose coupling blocks to insert: `points` (indices into the law
/// points, checked), or every one of c's blocks for None.
std::vector<std::size_t> selected(const Arg& arg, const py::object& points,
                                  const contact::CouplingBlocks& c) {
  const std::size_t n = c.offsets.size() - 1;
  std::vector<std::size_t> out;
  if (points.is_none()) {
    out.resize(n);
    for (std::size_t s = 0; s < n; ++s)
      out[s] = s;
    return out;
  }
  const Indices idx(arg, points, {any});
  idx.check_range(0, std::int64_t(n));
  for (std::int32_t s : idx.flat())
    out.push_back(std::size_t(s));
  return out;
}

} // namespace

void bind_assembly(py::module_& m) {
  using contact::ContactQuadrature;

  py::class_<ContactQuadrature>(m, "ContactQuadrature",
                                "Contact points of a body pair with the cells and basis values at "
                                "their closest points on each body (reference configuration)")
      .def(py::init([](const py::object& weights, const py::object& normals,
                       const py::object& tangents, const py::object& g_n0, const py::object& dofs_i,
                       const py::object& dofs_j, const py::object& basis_i,
                       const py::object& basis_j) {
             const char* f = "ContactQuadrature";
             ContactQuadrature q;
             q.weights = f64_vector(Arg{f, "weights"}, weights, {any});
             const auto nq = py::ssize_t(q.weights.size());
             q.normals = f64_vector(Arg{f, "normals"}, normals, {nq, 2});
             q.tangents = f64_vector(Arg{f, "tangents"}, tangents, {nq, 2});
             q.g_n0 = f64_vector(Arg{f, "g_n0"}, g_n0, {nq});
             const Indices di(Arg{f, "dofs_i"}, dofs_i, {nq, any});
             const Indices dj(Arg{f, "dofs_j"}, dofs_j, {nq, any});
             // block dofs index a local vector that assemble_contact checks them against
             di.check_range(0, std::numeric_limits<std::int32_t>::max());
             dj.check_range(0, std::numeric_limits<std::int32_t>::max());
             q.nodes_i = int(di.shape(1));
             q.nodes_j = int(dj.shape(1));
             q.dofs_i = di.vector();
             q.dofs_j = dj.vector();
             q.basis_i = f64_vector(Arg{f, "basis_i"}, basis_i, {nq, q.nodes_i});
             q.basis_j = f64_vector(Arg{f, "basis_j"}, basis_j, {nq, q.nodes_j});
             q.validate();
             return q;
           }),
           py::arg("weights"), py::arg("normals"), py::arg("tangents"), py::arg("g_n0"),
           py::arg("dofs_i"), py::arg("dofs_j"), py::arg("basis_i"), py::arg("basis_j"),
           "weights (nq,), normals and tangents (nq, 2), g_n0 (nq,) float64; dofs_i (nq, "
           "nodes_i) and dofs_j (nq, nodes_j) block dofs, int32 or int64 (>= 0); basis_i, "
           "basis_j float64 of the shapes of dofs_i, dofs_j. ValueError names a bad argument.")
      .def("__len__", &ContactQuadrature::size)
      .def_property_readonly("weights",
                             [](const ContactQuadrature& q) {
                               return to_numpy(std::vector<double>(q.weights),
                                               {py::ssize_t(q.size())});
                             })
      .def_property_readonly("g_n0",
                             [](const ContactQuadrature& q) {
                               return to_numpy(std::vector<double>(q.g_n0),
                                               {py::ssize_t(q.size())});
                             })
      .def_property(
          "u_j_prescribed",
          [](const ContactQuadrature& q) {
            return to_numpy(std::vector<double>(q.u_j_prescribed),
                            {py::ssize_t(q.u_j_prescribed.size() / 2), 2});
          },
          [](ContactQuadrature& q, const py::object& v) {
            const Arg arg{"ContactQuadrature", "u_j_prescribed"};
            const auto a = input<double>(arg, v);
            if (a.size() != 0)
              contact::python::check_shape(arg, a, {py::ssize_t(q.size()), 2});
            q.u_j_prescribed.assign(a.data(), a.data() + a.size());
          },
          "(nq, 2) displacement of side j at P_j not carried by dofs (rigid obstacle motion), "
          "added to u_j(P_j) in the gaps; empty: none")
      .def(
          "set_multiplier_nodes",
          [](ContactQuadrature& q, const py::object& nodes, const py::object& weights) {
            const char* f = "set_multiplier_nodes";
            const auto nq = py::ssize_t(q.size());
            const Indices n(Arg{f, "nodes"}, nodes, {nq, 2});
            // -1: no second node; the law points are 0 .. max(nodes)
            n.check_range(-1, std::numeric_limits<std::int32_t>::max());
            std::vector<double> w = f64_vector(Arg{f, "weights"}, weights, {nq, 2});
            std::vector<std::int32_t> old_n = q.mult_nodes;
            std::vector<double> old_w = q.mult_weights;
            q.mult_nodes = n.vector();
            q.mult_weights = std::move(w);
            try {
              q.validate();
            } catch (...) {
              q.mult_nodes = old_n;
              q.mult_weights = old_w;
              throw;
            }
          },
          py::arg("nodes"), py::arg("weights"),
          "Multiplier nodes: point p belongs to nodes[p, 0] with weights[p, 0] and to nodes[p, 1] "
          "(-1: none) with weights[p, 1], the weights of a point summing to 1; each node carries "
          "one traction from the weighted mean of its points' gaps")
      .def_property_readonly("num_law_points", &ContactQuadrature::num_law_points,
                             "Multiplier nodes, or points without them: where the law acts")
      .def(
          "coupling_dofs",
          [](const ContactQuadrature& q) {
            const contact::CouplingBlocks c = contact::coupling_dofs(q);
            py::list out;
            for (std::size_t s = 0; s + 1 < c.offsets.size(); ++s)
              out.append(to_numpy(std::vector<std::int32_t>(c.dofs.begin() + c.offsets[s],
                                                            c.dofs.begin() + c.offsets[s + 1]),
                                  {py::ssize_t(c.offsets[s + 1] - c.offsets[s])}));
            return out;
          },
          "Block dofs coupled by each law point (a list, one array per law point)");

  m.def(
      "insert_coupling",
      [](dolfinx::la::SparsityPattern& pattern, const ContactQuadrature& q,
         const py::object& points) {
        check_dofs("insert_coupling", q, pattern_blocks(pattern), "the pattern's index map");
        const contact::CouplingBlocks c = contact::coupling_dofs(q);
        for (std::size_t s : selected(Arg{"insert_coupling", "points"}, points, c)) {
          std::span<const std::int32_t> d(c.dofs.data() + c.offsets[s],
                                          c.offsets[s + 1] - c.offsets[s]);
          pattern.insert(d, d);
        }
      },
      py::arg("pattern"), py::arg("quadrature"), py::arg("points") = py::none(),
      "Add the contact coupling blocks of the law points `points` (indices; None: every law "
      "point) to a (not yet assembled) SparsityPattern");

  m.def(
      "add_coupling_zeros",
      [](Mat A, const ContactQuadrature& q, const py::object& points) {
        // PETSc squeezes preallocated but unused entries out at the first final assembly:
        // explicit zeros keep the contact blocks in the matrix for every later iteration.
        const PetscInt blocks = contact::python::local_block_rows(A);
        if (blocks >= 0)
          check_dofs("add_coupling_zeros", q, blocks, "A's local-to-global map");
        const contact::CouplingBlocks c = contact::coupling_dofs(q);
        for (std::size_t s : selected(Arg{"add_coupling_zeros", "points"}, points, c)) {
          const auto nd = PetscInt(c.offsets[s + 1] - c.offsets[s]);
          const std::vector<double> zeros(std::size_t(4 * nd * nd), 0.0);
          petsc_check(MatSetValuesBlockedLocal(A, nd, c.dofs.data() + c.offsets[s], nd,
                                               c.dofs.data() + c.offsets[s], zeros.data(),
                                               ADD_VALUES),
                      "MatSetValuesBlockedLocal (coupling block outside the sparsity pattern)");
        }
      },
      py::arg("A"), py::arg("quadrature"), py::arg("points") = py::none(),
      "Add explicit zeros on the contact coupling blocks of the law points `points` (indices; "
      "None: every law point), before the matrix's first assembly");

  m.def(
      "assemble_contact",
      [](const ContactQuadrature& q, double eps_n, double eps_t, double mu, const py::object& u,
         const py::object& gtp_old, const py::object& b, std::optional<Mat> A,
         bool finite_difference, double fd_step, double closed_gap, const py::object& g_n_shift) {
        const char* f = "assemble_contact";
        q.validate();
        const auto ua = input<double>(Arg{f, "u"}, u, {any});
        if (ua.size() % 2 != 0)
          contact::python::fail(Arg{f, "u"}, "expected an even length (block size 2), got " +
                                                 std::to_string(ua.size()));
        const auto na = py::ssize_t(q.num_law_points());
        // gtp_old is not read without friction (may be empty)
        const auto gtp = input<double>(Arg{f, "gtp_old"}, gtp_old, {mu > 0 ? na : any});
        // every dof indexes u (and b): checked once here, not in the kernel's loops
        check_dofs(f, q, ua.size() / 2, "u");
        std::span<double> bs;
        if (!b.is_none())
          bs = contact::python::output<double>(Arg{f, "b"}, b, std::size_t(ua.size()));
        std::optional<contact::python::Array<double>> shift;
        if (!g_n_shift.is_none())
          shift = input<double>(Arg{f, "g_n_shift"}, g_n_shift, {na});
        contact::BlockInserter insert;
        if (A) {
          Mat mat = *A;
          const PetscInt blocks = contact::python::local_block_rows(mat);
          if (blocks >= 0)
            check_dofs(f, q, blocks, "A's local-to-global map");
          insert = [mat](std::span<const std::int32_t> dofs, std::span<const double> Ke) {
            const auto nd = PetscInt(dofs.size());
            petsc_check(MatSetValuesBlockedLocal(mat, nd, dofs.data(), nd, dofs.data(), Ke.data(),
                                                 ADD_VALUES),
                        "MatSetValuesBlockedLocal (contact block outside the sparsity pattern?)");
          };
        }
        const auto mode = finite_difference ? contact::TangentMode::finite_difference
                                            : contact::TangentMode::exact;
        contact::ContactPointState s = contact::assemble_contact(
            q, contact::CoulombPenalty{eps_n, eps_t, mu}, flat(ua), flat(gtp), bs, insert, mode,
            fd_step, closed_gap, shift ? flat(*shift) : std::span<const double>());
        const auto nq = py::ssize_t(q.size());
        auto int8 = [](const std::vector<contact::ContactState>& v) {
          std::vector<std::int8_t> out(v.size());
          for (std::size_t p = 0; p < v.size(); ++p)
            out[p] = std::int8_t(v[p]);
          return out;
        };
        std::vector<std::int8_t> st = int8(s.state);
        py::dict d;
        d["law_g_n"] = to_numpy(std::move(s.law_g_n), {na});
        d["law_g_t"] = to_numpy(std::move(s.law_g_t), {na});
        d["law_tau_n"] = to_numpy(std::move(s.law_tau_n), {na});
        d["law_tau_t"] = to_numpy(std::move(s.law_tau_t), {na});
        d["law_state"] = to_numpy(int8(s.law_state), {na});
        d["g_n"] = to_numpy(std::move(s.g_n), {nq});
        d["g_t"] = to_numpy(std::move(s.g_t), {nq});
        d["tau_n"] = to_numpy(std::move(s.tau_n), {nq});
        d["tau_t"] = to_numpy(std::move(s.tau_t), {nq});
        d["state"] = to_numpy(std::move(st), {nq});
        d["law_coupled"] = to_numpy(std::move(s.law_coupled), {na});
        if (mu > 0)
          d["gtp_trial"] = to_numpy(std::move(s.gtp_trial), {na});
        else
          d["gtp_trial"] = py::none();
        return d;
      },
      py::arg("quadrature"), py::arg("eps_n"), py::arg("eps_t"), py::arg("mu"), py::arg("u"),
      py::arg("gtp_old"), py::arg("b") = py::none(), py::arg("A") = py::none(),
      py::arg("finite_difference") = false, py::arg("fd_step") = 1e-8, py::arg("closed_gap") = 0.0,
      py::arg("g_n_shift") = py::none(),
      "Contact residual (added into the local array b) and tangent (added into the PETSc Mat A "
      "by local block indices; call A.assemble() after) of eq 48. Returns a dict of per-point "
      "g_n, g_t, tau_n, tau_t, state (int8 ContactState), of law points (multiplier nodes, or "
      "the points) law_g_n, law_g_t, law_tau_n, law_tau_t, law_state, law_coupled (int8: 1 "
      "where the law point's tangent block went into A), and their gtp_trial "
      "(None when mu == 0). gtp_old and g_n_shift (eps_n lambda_n of the augmented "
      "Lagrangian, added to the gap the law sees, or None) are per law point. Arrays are "
      "float64, C-contiguous (b also writeable, never copied); every block dof must index u "
      "(and A): ValueError names a bad argument.");
}
