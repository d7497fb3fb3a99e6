// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Linear-algebra helpers shared by the binding files that call PETSc or fill a dolfinx
// SparsityPattern: error codes as exceptions, RAII guards so that an array or a Schur
// complement taken from a Mat is given back even when an exception leaves the scope, and the
// index bounds that block dofs are checked against (issue 28, item 5).
#pragma once
#include <algorithm>
#include <cstdint>
#include <dolfinx/common/IndexMap.h>
#include <dolfinx/la/SparsityPattern.h>
#include <petscmat.h>
#include <stdexcept>
#include <string>

namespace contact::python {

/// @brief Throw std::runtime_error naming the PETSc function on a non-zero error code.
inline void petsc_check(PetscErrorCode ierr, const char* where) {
  if (ierr != 0)
    throw std::runtime_error(std::string("PETSc error ") + std::to_string(ierr) + " in " + where);
}

/// @brief Number of local block indices a Mat's row local-to-global map accepts (the bound of
/// MatSetValuesBlockedLocal's indices), or -1 when the Mat has no such map.
inline PetscInt local_block_rows(Mat A) {
  ISLocalToGlobalMapping rmap = nullptr, cmap = nullptr;
  petsc_check(MatGetLocalToGlobalMapping(A, &rmap, &cmap), "MatGetLocalToGlobalMapping");
  if (!rmap)
    return -1;
  PetscInt n = 0, bs = 1;
  petsc_check(ISLocalToGlobalMappingGetSize(rmap, &n), "ISLocalToGlobalMappingGetSize");
  petsc_check(ISLocalToGlobalMappingGetBlockSize(rmap, &bs), "ISLocalToGlobalMappingGetBlockSize");
  return n / bs;
}

/// @brief Number of local block indices (owned and ghost) a square SparsityPattern accepts
/// (the bound of its insert's indices).
inline std::int64_t pattern_blocks(const dolfinx::la::SparsityPattern& pattern) {
  std::int64_t n = -1;
  for (int dim = 0; dim < 2; ++dim) {
    const auto map = pattern.index_map(dim);
    const std::int64_t nd = std::int64_t(map->size_local()) + map->num_ghosts();
    n = n < 0 ? nd : std::min(n, nd);
  }
  return n;
}

/// @brief MatDenseGetArray in the constructor, MatDenseRestoreArray in the destructor.
class DenseArray {
public:
  /// @brief Take the column-major array (leading dimension lda()) of the dense Mat S.
  explicit DenseArray(Mat S) : S_(S) {
    petsc_check(MatDenseGetLDA(S_, &lda_), "MatDenseGetLDA");
    petsc_check(MatDenseGetArray(S_, &v_), "MatDenseGetArray");
  }
  ~DenseArray() {
    if (v_)
      MatDenseRestoreArray(S_, &v_); // no throw from a destructor: the error code is dropped
  }
  DenseArray(const DenseArray&) = delete;
  DenseArray& operator=(const DenseArray&) = delete;
  /// @brief Give the array back now (errors thrown, unlike the destructor).
  void restore() {
    PetscScalar* v = v_;
    v_ = nullptr;
    petsc_check(MatDenseRestoreArray(S_, &v), "MatDenseRestoreArray");
  }
  /// @brief Entry (i, j).
  PetscScalar& operator()(PetscInt i, PetscInt j) { return v_[i + j * lda_]; }

private:
  Mat S_;
  PetscScalar* v_ = nullptr;
  PetscInt lda_ = 0;
};

/// @brief MatFactorGetSchurComplement in the constructor; the destructor restores it with the
/// status it had (unless restore() gave it back with another).
class SchurComplement {
public:
  /// @brief Take the Schur complement of the MUMPS factor F.
  explicit SchurComplement(Mat F) : F_(F) {
    petsc_check(MatFactorGetSchurComplement(F_, &S_, &status_), "MatFactorGetSchurComplement");
  }
  ~SchurComplement() {
    if (S_)
      MatFactorRestoreSchurComplement(F_, &S_, status_); // error code dropped (destructor)
  }
  SchurComplement(const SchurComplement&) = delete;
  SchurComplement& operator=(const SchurComplement&) = delete;
  /// @brief The dense Schur complement.
  Mat mat() const { return S_; }
  /// @brief Its status when taken.
  MatFactorSchurStatus status() const { return status_; }
  /// @brief Give it back now with `status` (errors thrown, unlike the destructor).
  void restore(MatFactorSchurStatus status) {
    Mat S = S_;
    S_ = nullptr;
    petsc_check(MatFactorRestoreSchurComplement(F_, &S, status), "MatFactorRestoreSchurComplement");
  }

private:
  Mat F_;
  Mat S_ = nullptr;
  MatFactorSchurStatus status_ = MAT_FACTOR_SCHUR_UNFACTORED;
};

/// @brief Destroys a Mat this code created unless release()d (exception safety).
class OwnedMat {
public:
  /// @brief Own A (may be null).
  explicit OwnedMat(Mat A = nullptr) : A_(A) {}
  ~OwnedMat() {
    if (A_)
      MatDestroy(&A_);
  }
  OwnedMat(const OwnedMat&) = delete;
  OwnedMat& operator=(const OwnedMat&) = delete;
  /// @brief Address for a PETSc function that creates the Mat.
  Mat* out() { return &A_; }
  /// @brief The Mat.
  Mat get() const { return A_; }

private:
  Mat A_;
};

} // namespace contact::python
