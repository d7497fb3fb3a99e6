"""Newton's linear solves J du = b, and what they reuse.

J = K0 + dC: the bulk tangent with the Dirichlet rows eliminated (rows zeroed, 1 on the
diagonal, columns kept) plus the contact tangent, which couples only the contact dofs c (the
dofs of the cells that hold closest points: a few hundred of 1e4-1e6).

* `Factorised`: a PETSc KSP (MUMPS LU by default, or the user's `--petsc` options) on J. The
  factorisation is reused while J is the same matrix (a linear bulk, the same active set, mu and
  a constant contact tangent); otherwise each Newton iteration refactorises.
* `Condensed` (issue 12, "pay once for the bulk"): a linear bulk on one process with the
  default direct solver. K0 is factorised once per scene by MUMPS with the contact dofs ordered
  last, which leaves the dense Schur complement S0 = K0_cc - K0_ci K0_ii^-1 K0_ic. Since dC lives
  in the (c, c) block, J's Schur complement is S0 + dC_cc: a Newton iteration, a load step or
  a force-control border refactorises only that m x m matrix, and the solve condenses and
  expands through the one sparse factorisation (`_cpp.schur_factor`, `_cpp.schur_update`).
  Should one dense update take longer than twice that factorisation (m too large for n), it
  hands over to `Factorised` for the rest of the run.

`choose` picks Condensed where it applies and pays (m well below the dofs), else Factorised.
"""

import time

import numpy as np
from petsc4py import PETSc

from . import _cpp

DEFAULT_OPTIONS = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
MAX_CONDENSED = 6000  # the dense m x m blocks (3 of them) stay below ~1 GB


class LinearSolverError(RuntimeError):
    """A failed linear solve (the message names the solver and PETSc's reason)."""


class Factorised:
    """KSP on the full J, the factorisation reused while J is unchanged."""

    name = "factorised"

    def __init__(self, problem, petsc_options=None):
        self.ksp = PETSc.KSP().create(problem.comm)
        self.ksp.setOptionsPrefix("ils_")
        opts = PETSc.Options()
        for k, v in {**DEFAULT_OPTIONS, **(petsc_options or {})}.items():
            opts["ils_" + k] = v
        self.ksp.setFromOptions()
        self.key = None  # what the last factorisation was of
        self.factorisations = 0

    def setup(self, J, key):
        """key: None (J changed), or a hashable description of J (the same key: same J)."""
        reuse = key is not None and key == self.key
        self.ksp.getPC().setReusePreconditioner(reuse)
        self.key = key
        self.factorisations += not reuse
        self.ksp.setOperators(J)

    def solve(self, b, x):
        self.ksp.solve(b, x)
        reason = self.ksp.getConvergedReason()
        if reason < 0:
            raise LinearSolverError(f"linear solver diverged (reason {reason})")


class Condensed:
    """The bulk factorised once, Newton on the dense Schur complement of the contact dofs.

    The dense update costs ~m^3 and a sparse factorisation ~n^1.5 (2D): should an update take
    longer than twice the sparse factorisation (and 50 ms), the solver hands over to `Factorised` for the
    rest of the run (`name` then says so)."""

    name = "condensed"
    min_handover = 0.05  # s: below this a dense update is never "too slow"

    def __init__(self, problem, dofs, petsc_options=None):
        self.problem, self.petsc_options = problem, petsc_options
        t0 = time.perf_counter()
        K0 = problem.K.copy()
        K0.zeroRows(problem.bc_global, diag=1.0)
        self.IS = PETSc.IS().createGeneral(np.asarray(dofs, dtype=np.int32), comm=problem.comm)
        self.F, self.S0 = _cpp.schur_factor(K0, self.IS)
        self.K0cc = _dense(K0.createSubMatrix(self.IS, self.IS))
        self.t_factor = time.perf_counter() - t0
        self.num_dofs = len(dofs)
        self.factorisations = 1  # sparse, once
        self.schur_factorisations = 0  # dense, m x m
        self.key, self.full = None, None

    def setup(self, J, key):
        if self.full is not None:
            return self.full.setup(J, key)
        if key is not None and key == self.key:
            return
        self.key = key
        t0 = time.perf_counter()
        dC = _dense(J.createSubMatrix(self.IS, self.IS)) - self.K0cc
        _cpp.schur_update(self.F, self.S0 + dC)
        self.schur_factorisations += 1
        # m too large for its n (timer noise aside: twice, and 50 ms): refactorise instead
        if time.perf_counter() - t0 > max(2.0 * self.t_factor, self.min_handover):
            self.full = Factorised(self.problem, self.petsc_options)
            self.full.factorisations = self.factorisations
            self.name = f"factorised (condensed: {self.num_dofs} contact dofs cost more)"
            self.F = self.S0 = self.K0cc = None
            return self.full.setup(J, None)

    def solve(self, b, x):
        if self.full is not None:
            return self.full.solve(b, x)
        self.F.solve(b, x)

    @property
    def factorisations(self):
        return self._factorisations if self.full is None else self.full.factorisations

    @factorisations.setter
    def factorisations(self, n):
        self._factorisations = n


def _dense(A):
    return A.convert("dense").getDenseArray().copy()


def contact_dofs(problem):
    """The (unrolled, local) dofs the contact tangent can couple: every pair's law points."""
    blocks = [b for g in problem.contact.pairs for b in g.quadrature.coupling_dofs()]
    if not blocks:
        return np.zeros(0, np.int32)
    nodes = np.unique(np.concatenate(blocks))
    return (nodes[:, None] * problem.bs + np.arange(problem.bs)).ravel().astype(np.int32)


def choose(problem, kind="auto", petsc_options=None):
    """kind: "auto" (Condensed for a linear bulk on one process with the default direct solver
    and a contact block well below the dofs; Factorised otherwise), "condensed" (raises where
    it does not apply) or "factorised"."""
    if kind not in ("auto", "condensed", "factorised"):
        raise ValueError(f"linear_solver: 'auto', 'condensed' or 'factorised', not {kind!r}")
    if kind == "factorised":
        return Factorised(problem, petsc_options)
    why = None
    if problem.comm.size > 1:
        why = "MUMPS Schur complements are serial"
    elif problem.bulk.nonlinear:
        why = "the bulk is nonlinear (its tangent changes every iteration)"
    elif petsc_options and {**DEFAULT_OPTIONS, **petsc_options} != DEFAULT_OPTIONS:
        why = "other PETSc solver options were given"
    dofs = contact_dofs(problem) if why is None else None
    if why is None and not 0 < len(dofs) <= min(MAX_CONDENSED, problem.num_dofs // 4):
        why = f"{len(dofs)} contact dofs of {problem.num_dofs}"
    if why is None:
        return Condensed(problem, dofs, petsc_options)
    if kind == "condensed":
        raise ValueError(f"linear_solver: 'condensed' does not apply here: {why}")
    return Factorised(problem, petsc_options)
