// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// DOLFINx/PETSc glue of the contact kernel (eq 48): the pure numerics live in
// contact/contact_kernel.h; here element blocks go into a PETSc Mat by local block indices
// and the coupling blocks into a dolfinx SparsityPattern.
#include "array.h"
#include <caster_petsc.h>
#include <contact/contact_kernel.h>
#include <dolfinx/la/SparsityPattern.h>
#include <petscmat.h>
#include <pybind11/stl.h>
#include <stdexcept>
#include <string>

namespace py = pybind11;
using contact::python::as_span;
using contact::python::carray;
using contact::python::to_numpy;
using iarray = py::array_t<std::int32_t, py::array::c_style | py::array::forcecast>;

namespace {
template <typename T>
std::vector<T> copy_of(const py::array_t<T, py::array::c_style | py::array::forcecast>& a) {
  return std::vector<T>(a.data(), a.data() + a.size());
}

/// Throw with the PETSc function named on a non-zero error code.
void petsc_check(PetscErrorCode ierr, const char* where) {
  if (ierr != 0)
    throw std::runtime_error(std::string("PETSc error ") + std::to_string(ierr) + " in " + where);
}
} // namespace

void bind_assembly(py::module_& m) {
  using contact::ContactQuadrature;

  py::class_<ContactQuadrature>(m, "ContactQuadrature",
                                "Contact points of a body pair with the cells and basis values at "
                                "their closest points on each body (reference configuration)")
      .def(py::init([](const carray& weights, const carray& normals, const carray& tangents,
                       const carray& g_n0, const iarray& dofs_i, const iarray& dofs_j,
                       const carray& basis_i, const carray& basis_j) {
             if (dofs_i.ndim() != 2 or dofs_j.ndim() != 2)
               throw std::invalid_argument("dofs_i, dofs_j: expected arrays of shape (nq, nodes)");
             ContactQuadrature q;
             q.nodes_i = int(dofs_i.shape(1));
             q.nodes_j = int(dofs_j.shape(1));
             q.weights = copy_of(weights);
             q.normals = copy_of(normals);
             q.tangents = copy_of(tangents);
             q.g_n0 = copy_of(g_n0);
             q.dofs_i = copy_of(dofs_i);
             q.dofs_j = copy_of(dofs_j);
             q.basis_i = copy_of(basis_i);
             q.basis_j = copy_of(basis_j);
             q.validate();
             return q;
           }),
           py::arg("weights"), py::arg("normals"), py::arg("tangents"), py::arg("g_n0"),
           py::arg("dofs_i"), py::arg("dofs_j"), py::arg("basis_i"), py::arg("basis_j"))
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
          [](ContactQuadrature& q, const carray& v) {
            if (v.size() != 0 and
                (v.ndim() != 2 or v.shape(0) != py::ssize_t(q.size()) or v.shape(1) != 2))
              throw std::invalid_argument("u_j_prescribed: expected shape (nq, 2) or empty");
            q.u_j_prescribed = copy_of(v);
          },
          "(nq, 2) displacement of side j at P_j not carried by dofs (rigid obstacle motion), "
          "added to u_j(P_j) in the gaps; empty: none")
      .def(
          "set_multiplier_nodes",
          [](ContactQuadrature& q, const iarray& nodes, const carray& weights) {
            if (nodes.ndim() != 2 or nodes.shape(1) != 2 or weights.ndim() != 2 or
                weights.shape(1) != 2)
              throw std::invalid_argument("nodes, weights: expected arrays of shape (nq, 2)");
            std::vector<std::int32_t> old_n = q.mult_nodes;
            std::vector<double> old_w = q.mult_weights;
            q.mult_nodes = copy_of(nodes);
            q.mult_weights = copy_of(weights);
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
      [](dolfinx::la::SparsityPattern& pattern, const ContactQuadrature& q) {
        const contact::CouplingBlocks c = contact::coupling_dofs(q);
        for (std::size_t s = 0; s + 1 < c.offsets.size(); ++s) {
          std::span<const std::int32_t> d(c.dofs.data() + c.offsets[s],
                                          c.offsets[s + 1] - c.offsets[s]);
          pattern.insert(d, d);
        }
      },
      py::arg("pattern"), py::arg("quadrature"),
      "Add the contact coupling blocks of every law point to a (not yet assembled) "
      "SparsityPattern");

  m.def(
      "add_coupling_zeros",
      [](Mat A, const ContactQuadrature& q) {
        // PETSc squeezes preallocated but unused entries out at the first final assembly:
        // explicit zeros keep the contact blocks in the matrix for every later iteration.
        const contact::CouplingBlocks c = contact::coupling_dofs(q);
        for (std::size_t s = 0; s + 1 < c.offsets.size(); ++s) {
          const auto nd = PetscInt(c.offsets[s + 1] - c.offsets[s]);
          const std::vector<double> zeros(std::size_t(4 * nd * nd), 0.0);
          petsc_check(MatSetValuesBlockedLocal(A, nd, c.dofs.data() + c.offsets[s], nd,
                                               c.dofs.data() + c.offsets[s], zeros.data(),
                                               ADD_VALUES),
                      "MatSetValuesBlockedLocal (coupling block outside the sparsity pattern)");
        }
      },
      py::arg("A"), py::arg("quadrature"),
      "Add explicit zeros on the contact coupling blocks (before the matrix's first assembly)");

  m.def(
      "assemble_contact",
      [](const ContactQuadrature& q, double eps_n, double eps_t, double mu, const carray& u,
         const carray& gtp_old, std::optional<py::array_t<double, py::array::c_style>> b,
         std::optional<Mat> A, bool finite_difference, double fd_step, double closed_gap,
         std::optional<carray> g_n_shift) {
        std::span<double> bs;
        if (b) {
          if (b->size() != u.size())
            throw std::invalid_argument("b: expected the size of u");
          bs = std::span<double>(b->mutable_data(), std::size_t(b->size()));
        }
        contact::BlockInserter insert;
        if (A) {
          Mat mat = *A;
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
            q, contact::CoulombPenalty{eps_n, eps_t, mu}, as_span(u, "u"),
            as_span(gtp_old, "gtp_old"), bs, insert, mode, fd_step, closed_gap,
            g_n_shift ? as_span(*g_n_shift, "g_n_shift") : std::span<const double>());
        const auto nq = py::ssize_t(q.size()), na = py::ssize_t(q.num_law_points());
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
      "the points) law_g_n, law_g_t, law_tau_n, law_tau_t, law_state, and their gtp_trial "
      "(None when mu == 0). gtp_old and g_n_shift (eps_n lambda_n of the augmented "
      "Lagrangian, added to the gap the law sees, or None) are per law point.");
}
