// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// PETSc glue of the condensed bulk solve (issue 12, "pay once for the bulk"): MUMPS factorises
// the Dirichlet-eliminated bulk matrix K0 once with the contact dofs c ordered last and keeps
// the dense Schur complement S0 = K0_cc - K0_ci K0_ii^-1 K0_ic. The contact tangent touches
// only the (c, c) block, so J = K0 + dC has the Schur complement S0 + dC: a Newton iteration
// refactorises that dense m x m matrix alone, and MatSolve on the factor does the condensation
// (forward elimination, the Schur solve, back substitution). petsc4py 3.18 does not bind the
// MatFactor Schur API, hence these three functions. MUMPS Schur complements are serial only.
#include "array.h"
#include "la.h"
#include <caster_petsc.h>
#include <string>

namespace py = pybind11;
using contact::python::Arg;
using contact::python::DenseArray;
using contact::python::OwnedMat;
using contact::python::petsc_check;
using contact::python::SchurComplement;
using contact::python::to_numpy;

void bind_schur(py::module_& m) {
  m.def(
      "schur_factor",
      [](Mat A, IS is, bool symmetric) {
        OwnedMat factor; // destroyed on every exit: petsc4py takes its own reference
        const MatFactorType type = symmetric ? MAT_FACTOR_CHOLESKY : MAT_FACTOR_LU;
        petsc_check(MatGetFactor(A, MATSOLVERMUMPS, type, factor.out()), "MatGetFactor (MUMPS)");
        Mat F = factor.get();
        petsc_check(MatFactorSetSchurIS(F, is), "MatFactorSetSchurIS");
        MatFactorInfo info;
        petsc_check(MatFactorInfoInitialize(&info), "MatFactorInfoInitialize");
        if (symmetric) {
          petsc_check(MatCholeskyFactorSymbolic(F, A, nullptr, &info), "MatCholeskyFactorSymbolic");
          petsc_check(MatCholeskyFactorNumeric(F, A, &info), "MatCholeskyFactorNumeric");
        } else {
          petsc_check(MatLUFactorSymbolic(F, A, nullptr, nullptr, &info), "MatLUFactorSymbolic");
          petsc_check(MatLUFactorNumeric(F, A, &info), "MatLUFactorNumeric");
        }
        SchurComplement schur(F);
        PetscInt m = 0;
        petsc_check(MatGetSize(schur.mat(), &m, nullptr), "MatGetSize");
        std::vector<double> s0(std::size_t(m * m));
        {
          DenseArray v(schur.mat());
          // LDL^T: MUMPS returns the lower triangle (column-major) only; mirror it
          for (PetscInt j = 0; j < m; ++j)
            for (PetscInt i = 0; i < m; ++i)
              if (!symmetric)
                s0[i * m + j] = v(i, j);
              else if (i >= j)
                s0[i * m + j] = s0[j * m + i] = v(i, j);
          v.restore();
        }
        schur.restore(schur.status());
        py::object f = py::cast(F);
        return py::make_tuple(f, to_numpy(std::move(s0), {py::ssize_t(m), py::ssize_t(m)}));
      },
      py::arg("A"), py::arg("schur_is"), py::arg("symmetric") = false,
      "MUMPS LU (symmetric: LDL^T of a symmetric A) of A with the dofs of schur_is eliminated "
      "last; returns (factor, S0) with S0 the dense Schur complement (m, m) on those dofs "
      "(serial).");

  m.def(
      "schur_update",
      [](Mat F, const py::object& S, bool inverted) {
        // the (m, m) shape is known from the factor: check S before taking its complement
        const auto a = contact::python::input<double>(Arg{"schur_update", "S"}, S);
        SchurComplement schur(F);
        PetscInt m = 0;
        petsc_check(MatGetSize(schur.mat(), &m, nullptr), "MatGetSize");
        contact::python::check_shape(Arg{"schur_update", "S"}, a, {m, m});
        {
          DenseArray v(schur.mat());
          const double* s = a.data();
          for (PetscInt j = 0; j < m; ++j)
            for (PetscInt i = 0; i < m; ++i)
              v(i, j) = s[i * m + j];
          v.restore();
        }
        // PETSc factorises the Schur complement as it did the bulk (Cholesky for LDL^T), so a
        // non-symmetric complement of a symmetric bulk comes in inverted: MatSolve then
        // multiplies by it (MAT_FACTOR_SCHUR_INVERTED)
        if (inverted) {
          schur.restore(MAT_FACTOR_SCHUR_INVERTED);
          return;
        }
        schur.restore(MAT_FACTOR_SCHUR_UNFACTORED);
        petsc_check(MatFactorFactorizeSchurComplement(F), "MatFactorFactorizeSchurComplement");
      },
      py::arg("F"), py::arg("S"), py::arg("inverted") = false,
      "Replace the factor's Schur complement by the dense S (m, m) and factorise it: MatSolve "
      "with F then solves the matrix whose Schur complement on the eliminated dofs is S. "
      "inverted: S is the inverse of that Schur complement (any S, whatever the factor's "
      "symmetry).");
}
