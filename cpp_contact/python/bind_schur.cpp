// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// PETSc glue of the condensed bulk solve (issue 12, "pay once for the bulk"): MUMPS factorises
// the Dirichlet-eliminated bulk matrix K0 once with the contact dofs c ordered last and keeps
// the dense Schur complement S0 = K0_cc - K0_ci K0_ii^-1 K0_ic. The contact tangent touches
// only the (c, c) block, so J = K0 + dC has the Schur complement S0 + dC: a Newton iteration
// refactorises that dense m x m matrix alone, and MatSolve on the factor does the condensation
// (forward elimination, the Schur solve, back substitution). petsc4py 3.18 does not bind the
// MatFactor Schur API, hence these three functions. MUMPS Schur complements are serial only.
#include "array.h"
#include <caster_petsc.h>
#include <petscmat.h>
#include <stdexcept>
#include <string>

namespace py = pybind11;
using contact::python::carray;
using contact::python::to_numpy;

namespace {
void check(PetscErrorCode ierr, const char* where) {
  if (ierr != 0)
    throw std::runtime_error(std::string("PETSc error ") + std::to_string(ierr) + " in " + where);
}

/// Visit the entries (i, j) of a dense PETSc matrix (column-major, leading dimension lda).
template <typename F> void for_dense(Mat S, PetscInt m, F&& f) {
  PetscScalar* v = nullptr;
  PetscInt lda = 0;
  check(MatDenseGetLDA(S, &lda), "MatDenseGetLDA");
  check(MatDenseGetArray(S, &v), "MatDenseGetArray");
  for (PetscInt j = 0; j < m; ++j)
    for (PetscInt i = 0; i < m; ++i)
      f(i, j, v[i + j * lda]);
  check(MatDenseRestoreArray(S, &v), "MatDenseRestoreArray");
}
} // namespace

void bind_schur(py::module_& m) {
  m.def(
      "schur_factor",
      [](Mat A, IS is, bool symmetric) {
        Mat F = nullptr;
        const MatFactorType type = symmetric ? MAT_FACTOR_CHOLESKY : MAT_FACTOR_LU;
        check(MatGetFactor(A, MATSOLVERMUMPS, type, &F), "MatGetFactor (MUMPS)");
        check(MatFactorSetSchurIS(F, is), "MatFactorSetSchurIS");
        MatFactorInfo info;
        check(MatFactorInfoInitialize(&info), "MatFactorInfoInitialize");
        if (symmetric) {
          check(MatCholeskyFactorSymbolic(F, A, nullptr, &info), "MatCholeskyFactorSymbolic");
          check(MatCholeskyFactorNumeric(F, A, &info), "MatCholeskyFactorNumeric");
        } else {
          check(MatLUFactorSymbolic(F, A, nullptr, nullptr, &info), "MatLUFactorSymbolic");
          check(MatLUFactorNumeric(F, A, &info), "MatLUFactorNumeric");
        }
        Mat S = nullptr;
        MatFactorSchurStatus status;
        check(MatFactorGetSchurComplement(F, &S, &status), "MatFactorGetSchurComplement");
        PetscInt m = 0;
        check(MatGetSize(S, &m, nullptr), "MatGetSize");
        std::vector<double> s0(std::size_t(m * m));
        // LDL^T: MUMPS returns the lower triangle (column-major) only; mirror it
        for_dense(S, m, [&](PetscInt i, PetscInt j, PetscScalar& v) {
          if (!symmetric)
            s0[i * m + j] = v;
          else if (i >= j)
            s0[i * m + j] = s0[j * m + i] = v;
        });
        check(MatFactorRestoreSchurComplement(F, &S, status), "MatFactorRestoreSchurComplement");
        py::object f = py::cast(F); // petsc4py takes its own reference
        check(MatDestroy(&F), "MatDestroy");
        return py::make_tuple(f, to_numpy(std::move(s0), {py::ssize_t(m), py::ssize_t(m)}));
      },
      py::arg("A"), py::arg("schur_is"), py::arg("symmetric") = false,
      "MUMPS LU (symmetric: LDL^T of a symmetric A) of A with the dofs of schur_is eliminated "
      "last; returns (factor, S0) with S0 the dense Schur complement (m, m) on those dofs "
      "(serial).");

  m.def(
      "schur_update",
      [](Mat F, const carray& S) {
        Mat Sf = nullptr;
        MatFactorSchurStatus status;
        check(MatFactorGetSchurComplement(F, &Sf, &status), "MatFactorGetSchurComplement");
        PetscInt m = 0;
        check(MatGetSize(Sf, &m, nullptr), "MatGetSize");
        if (S.ndim() != 2 || S.shape(0) != m || S.shape(1) != m)
          throw std::invalid_argument("schur_update: S must be (" + std::to_string(m) + ", " +
                                      std::to_string(m) + ")");
        const double* a = S.data();
        for_dense(Sf, m, [&](PetscInt i, PetscInt j, PetscScalar& v) { v = a[i * m + j]; });
        check(MatFactorRestoreSchurComplement(F, &Sf, MAT_FACTOR_SCHUR_UNFACTORED),
              "MatFactorRestoreSchurComplement");
        check(MatFactorFactorizeSchurComplement(F), "MatFactorFactorizeSchurComplement");
      },
      py::arg("F"), py::arg("S"),
      "Replace the factor's Schur complement by the dense S (m, m) and factorise it: MatSolve "
      "with F then solves the matrix whose Schur complement on the eliminated dofs is S.");
}
