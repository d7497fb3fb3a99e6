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
  A symmetric bulk (the linear laws) is factorised as LDL^T (MUMPS Cholesky, ~0.7x LU's time
  and half its memory) with the Dirichlet rows *and columns* eliminated; a solve then lifts
  the Dirichlet values (b_F - K_FD b_D). PETSc would factorise its Schur complement as
  symmetric too, so S0 + dC_cc, non-symmetric with friction, is handed over inverted (LAPACK;
  MatSolve then multiplies by it) where m is small enough for that to pay (`INVERT_COST`);
  otherwise the first non-symmetric J refactorises the bulk once as LU for the rest of the run.

* `Iterative` (issue 12, "large problems"): CG preconditioned by PETSc's smoothed-aggregation
  AMG (GAMG) with the rigid-body modes as its near-null space, the AMG set-up reused across
  Newton iterations while the solves stay within a bounded number of iterations.

`choose` picks Condensed where it applies and pays (m well below the dofs), Iterative for a
large body-fitted problem (`ITERATIVE_MIN_DOFS`), else Factorised.
"""

import itertools
import time

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc
from scipy.linalg import lapack

from dolfinx_forms import _cpp, defaults
from dolfinx_forms.common import SolverChoiceError

DEFAULT_OPTIONS = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
# MUMPS's fill-reducing ordering (ICNTL(7)) for a sparsity that serves one load step
# (`SolverOptions.short_lived`: an MPM step's new mesh, 3-6 Newton iterations): METIS's analysis
# costs ~2 numeric factorisations there, AMD's a fifth of one for ~5 % more fill (100 grains,
# 80k dofs: analysis 0.33 -> 0.075 s, factorisation 0.18 -> 0.19 s; 400 grains, 318k dofs:
# 0.98 -> 0.29 s and 0.92 -> 1.09 s, even at 4 factorisations per analysis)
SHORT_LIVED_ORDERING = 0  # AMD
# a symmetric bulk or Schur complement: |A - A^T| <= this * |A| (round-off of the assembly)
SYMMETRY_RTOL = 1e-12
# Condensed: S^-1 per Newton iteration against LU's sparse factorisation per step (after the
# LDL^T one). At 5 Newton iterations a step the break-even was ~18; since a step starts from
# the last increment (mpm/increment.py) the Brazilian disc takes 2.26, and at 40 its steps with
# m = 316-336 (n = 16.4k) invert too: 50 instead of 63 sparse factorisations, the solve phase
# 4.1-4.7 s instead of 5.1-5.7 over the 50 steps (two interleaved pairs), steps.csv to 6e-15
INVERT_COST = 40.0
MAX_CONDENSED = 6000  # the dense m x m blocks (3 of them) stay below ~1 GB
# "auto" condenses only where m^3 <= defaults.TUNING.condensed_cost n^1.5: a Newton iteration
# costs a dense m x m update (~m^3) instead of a sparse factorisation (~n^1.5 in 2D)
# Iterative's defaults: the Krylov method is chosen by the tangent's symmetry (Iterative)
# threshold 0.05: 61 -> 40 CG iterations on body-fitted Hertz (45k dofs); Chebyshev smoothers
# with their own 50-step eigenvalue estimates: GAMG's prolongator estimate misses the modes of
# small cut cells, and the smoother then diverges (CG: "indefinite PC" at eta <= 1e-6)
ITERATIVE_OPTIONS = {
    "pc_type": "gamg",
    "pc_gamg_threshold": 0.05,
    "pc_gamg_use_sa_esteig": 0,
    "mg_levels_ksp_chebyshev_esteig_steps": 50,
    "ksp_max_it": 3000,
}
# "auto" picks Iterative from here on (body-fitted scenes; benchmarks/amg.py, Hertz, side by side
# with the condensed MUMPS: run time 0.63-1.08x from 45k to 882k dofs, parity within the noise
# of a shared machine, but peak memory 1.3 GB instead of 4.2 GB at 702k, 1.6 instead of 5.2 GB
# at 882k: above ~5e5 dofs MUMPS's memory, not its time, is what limits a run). The cut path
# keeps MUMPS: GAMG needs 260-1360 iterations there (the anisotropic graded grid), 5-19x slower.
ITERATIVE_MIN_DOFS = 500_000
KINDS = ("auto", "condensed", "factorised", "iterative")
# a solver's `operator`: a number drawn for each operator it sets up, unique in the process (the
# same number: the same J, whatever solver object holds it)
_OPERATORS = itertools.count(1)


class LinearSolverError(RuntimeError):
    """A failed linear solve (the message names the solver and PETSc's reason)."""


class DirichletLift:
    """Solves with J (Dirichlet rows zeroed, 1 on the diagonal, columns kept) through an operator
    with those columns eliminated too, symmetric where J's free block is: x_D = b_D, the free
    rows see b_F - J_FD b_D (one product with J), and the lifted values are added back.
    Shared by the LDL^T factorisations (`Factorised`, `Condensed`) and CG (`Iterative`)."""

    def __init__(self, problem):
        self.problem = problem
        self.lift = self.t = None  # work vectors, made on first use

    def eliminated(self, J, A=None):
        """A = J with the Dirichlet rows and columns eliminated (A None: a new matrix of J's
        pattern, kept when the rows are zeroed, so that the next copy fits)."""
        if A is None:
            A = J.duplicate(copy=False)
            A.setOption(PETSc.Mat.Option.KEEP_NONZERO_PATTERN, True)
        J.copy(A, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        A.zeroRowsColumns(self.problem.bc_global, diag=1.0)
        return A

    def rhs(self, J, b):
        """(the right-hand side for the eliminated operator, whether b_D != 0 on any rank)."""
        bc = self.problem.bc_owned
        if not self.problem.comm.allreduce(bool(np.any(b.array[bc])), op=MPI.LOR):
            return b, False
        if self.lift is None:
            self.lift, self.t = J.createVecLeft(), J.createVecLeft()
        self.lift.zeroEntries()
        self.lift.array[bc] = b.array[bc]
        J.mult(self.lift, self.t)
        self.t.aypx(-1.0, b)  # b - J lift: its Dirichlet rows are b_D - b_D = 0
        return self.t, True

    def finish(self, x, lifted):
        """x_D = b_D after a solve of rhs(J, b)."""
        if lifted:
            x.axpy(1.0, self.lift)

    def destroy(self):
        destroy(self.lift, self.t)
        self.lift = self.t = None


class Factorised:
    """KSP on the full J, the factorisation reused while J is unchanged.

    symmetric (the default options, frictionless: `choose`): MUMPS Cholesky (LDL^T, ~0.7x LU's
    time, half its memory) of J with its Dirichlet rows *and columns* eliminated, the values
    lifted in each solve (x_D = b_D, b_F - J_FD b_D), as `Iterative` does; the first J that is
    not symmetric (friction switched on, a non-symmetric law's tangent) turns it to LU."""

    name = "factorised"

    def __init__(self, problem, petsc_options=None, symmetric=False):
        self.problem, self.symmetric = problem, bool(symmetric)
        self.petsc_options = petsc_options
        self.ksp = PETSc.KSP().create(problem.comm)
        self.ksp.setOptionsPrefix("ils_")
        opts = PETSc.Options()
        pc = {"pc_type": "cholesky"} if self.symmetric else {}
        for k, v in {**DEFAULT_OPTIONS, **pc, **(petsc_options or {})}.items():
            opts["ils_" + k] = v
        self.ksp.setFromOptions()
        self.key = None  # what the last factorisation was of
        self.factorisations = 0
        self.operator = 0  # the J set up last (`_OPERATORS`; 0: none)
        self.A = self.J = None  # symmetric: J eliminated, and J (the lifting's columns)
        self.dirichlet = DirichletLift(problem)
        # MUMPS's ordering for a short-lived sparsity, unless the user's options choose one
        try:
            mumps = self.ksp.getPC().getFactorSolverType() == "mumps"
        except PETSc.Error:  # not a factorisation (the user's options)
            mumps = False
        chosen = "mat_mumps_icntl_7" in (petsc_options or {})
        short = getattr(problem, "short_lived", False)
        self.ordering = SHORT_LIVED_ORDERING if short and mumps and not chosen else None

    def setup(self, J, key):
        """key: None (J changed), or a hashable description of J (the same key: same J)."""
        reuse = key is not None and key == self.key
        if self.symmetric and not reuse:
            self.A = self.dirichlet.eliminated(J, self.A)
            if not _symmetric(self.A):
                self.symmetric = False  # LU on J from here on (MUMPS: the default options)
                self.ksp.getPC().setType("lu")
                self.ksp.getPC().setFactorSolverType("mumps")
                self.A = self.J = None
        self.ksp.getPC().setReusePreconditioner(reuse)
        self.key = key
        self.factorisations += not reuse
        if not reuse:
            self.operator = next(_OPERATORS)
        if self.symmetric:
            self.J = J  # the lifting's columns
        self.ksp.setOperators(self.A if self.symmetric else J)
        if self.ordering is not None and not reuse:
            # the factorisation now, with the ordering in the options for this analysis only
            # (PETSc 3.18's MUMPS resets an ICNTL set on the factor before its analysis)
            opts = PETSc.Options()
            opts["ils_mat_mumps_icntl_7"] = self.ordering
            try:
                self.ksp.setUp()
            finally:
                opts.delValue("ils_mat_mumps_icntl_7")

    def renewed(self, problem):
        """A solver like this one (options, LDL^T or LU as it is now) for problem's new J."""
        return Factorised(problem, self.petsc_options, self.symmetric)

    def release(self):
        """Free the factorisation (and LDL^T's eliminated copy of J); the next `setup`
        factorises again. A converged material-point step calls it: the next step has a new
        mesh and its own solver, and would otherwise factorise while this factor (~130 MB at
        80k dofs) is still held."""
        self.ksp.reset()
        destroy(self.A)
        self.A = self.J = self.key = None

    def solve(self, b, x):
        rhs, lifted = self.dirichlet.rhs(self.J, b) if self.symmetric else (b, False)
        self.ksp.solve(rhs, x)
        if self.ksp.getConvergedReason() < 0:
            raise LinearSolverError(f"linear solver diverged ({diverged_reason(self.ksp)})")
        self.dirichlet.finish(x, lifted)

    def destroy(self):
        destroy(self.ksp, self.A)
        self.dirichlet.destroy()
        self.ksp = self.A = self.J = None


def diverged_reason(ksp):
    """PETSc's reason of a failed solve by name and number; for a failed factorisation also
    MUMPS's error code INFOG(1) and its detail INFOG(2) (-10: numerically singular, -9: its
    workspace too small, ...; MUMPS users' guide, section 8), which PETSc reports as
    DIVERGED_PCSETUP_FAILED alone."""
    reason = ksp.getConvergedReason()
    names = {v: k for k, v in vars(PETSc.KSP.ConvergedReason).items() if not k.startswith("_")}
    text = f"{names.get(reason, 'reason')} {reason}"
    try:
        F = ksp.getPC().getFactorMatrix()
        if F.getType() == "mumps":
            text += f", MUMPS INFOG(1) = {F.getMumpsInfog(1)}, INFOG(2) = {F.getMumpsInfog(2)}"
    except PETSc.Error:  # no factor (an iterative solver), or none made
        pass
    return text


def destroy(*objects):
    """Free PETSc objects (None skipped). petsc4py 3.18 frees none when garbage-collected:
    whatever a solver or problem made must be destroyed, or a run that makes a problem per
    step keeps every step's matrices and factorisations (~45 MB a step on the Brazilian
    disc, ~220 MB on 100 grains)."""
    for obj in objects:
        if obj is not None:
            obj.destroy()


class Condensed:
    """The bulk factorised once, Newton on the dense Schur complement of the contact dofs.

    The dense update costs ~m^3 and a sparse factorisation ~n^1.5 (2D): should an update take
    longer than twice the sparse factorisation (and 50 ms), the solver hands over to
    `Factorised` for the rest of the run (`name` then says so); "auto" picks it only where m^3
    <= defaults.TUNING.condensed_cost n^1.5 (`choose`)."""

    name = "condensed"
    min_handover = 0.05  # s: below this a dense update is never "too slow"

    def __init__(self, problem, dofs, petsc_options=None):
        self.problem, self.petsc_options = problem, petsc_options
        self.IS = PETSc.IS().createGeneral(np.asarray(dofs, dtype=np.int32), comm=problem.comm)
        self.bc = np.asarray(problem.bc_global, dtype=np.int32)
        self.dirichlet, self.J = DirichletLift(problem), None  # symmetric: the lifting
        # LDL^T needs K symmetric and J - K0 inside the (c, c) block (friction: S^-1, setup)
        # the contact dofs that are Dirichlet dofs (e.g. a symmetry line through the contact):
        # their positions in S. J keeps their columns, the LDL^T factor does not; they meet
        # x_D = 0 (the lifted right-hand side) either way, and are zeroed so that S is
        # symmetric wherever J's free block is
        self.fixed = np.flatnonzero(np.isin(np.asarray(dofs), self.bc))
        symmetric = _symmetric(problem.K)
        # a non-symmetric S (friction) on the LDL^T factor is inverted at each update (~4-7x
        # a dense LU, measured at m = 250-2000): that pays against LU's sparse factorisation
        # (~1.6x LDL^T's; Brazilian disc, m ~ 240-340, n = 16.4k) while m^3 <= INVERT_COST n^1.5
        n = problem.K.getSize()[0]
        self.invert = len(dofs) ** 3 <= INVERT_COST * n**1.5
        self.num_dofs = len(dofs)
        self.factorisations = 0  # sparse
        self.schur_factorisations = 0  # dense, m x m
        self.key, self.full = None, None
        self.operator = 0  # the J set up last (`_OPERATORS`; 0: none)
        self._factor(symmetric)

    def _factor(self, symmetric):
        """The sparse factorisation of the bulk K0 (rows of the Dirichlet dofs zeroed, 1 on
        the diagonal; symmetric: their columns too) and the dense base S0 - K0_cc."""
        t0 = time.perf_counter()
        destroy(getattr(self, "F", None))
        self.F = self.base = self.S = None  # the previous factor's memory first
        self.symmetric = symmetric
        if symmetric:
            A = self.dirichlet.eliminated(self.problem.K)
        else:
            A = self.problem.K.copy()
            A.zeroRows(self.bc, diag=1.0)
        self.F, S0 = _cpp.schur_factor(A, self.IS, symmetric)
        # S = S0 + (J_cc - K0_cc) is formed in one buffer from J_cc's sparse rows: its
        # conversion to a dense Mat and fresh m x m arrays cost 7 ms and 4-6 ms of page faults
        # per update at m = 456 (cut Hertz a/20) on these machines, against 0.3 ms
        # (only base and S are kept: two m x m arrays, 230 MB each at m = 5340)
        # base = S0 - K0_cc in place, from K0_cc's sparse rows: a dense copy of K0_cc and a
        # fresh m x m result cost 14 ms of conversion and page faults at m = 480 (cut Hertz)
        Acc = A.createSubMatrix(self.IS, self.IS)
        _add_sparse(S0, Acc, -1.0)
        destroy(Acc, A)  # the factor keeps none of A (MUMPS holds its own copy)
        self.base, self.S = S0, np.empty_like(S0)
        self.t_factor = time.perf_counter() - t0
        self.factorisations += 1
        self.key = None

    def setup(self, J, key):
        if self.full is not None:
            self.full.setup(J, key)
            self.operator = self.full.operator
            return
        self.J = J
        if key is not None and key == self.key:
            return
        if self.F is None:  # released
            self._factor(self.symmetric)
        self.key = key
        self.operator = next(_OPERATORS)
        t0 = time.perf_counter()
        Jcc = J.createSubMatrix(self.IS, self.IS)
        inverted = not self._schur(Jcc) and self.symmetric
        if inverted and not self.invert:  # friction on, m too large to invert S per iteration
            self._factor(False)  # LU from here on, with LU's S0
            self.key, t0, inverted = key, time.perf_counter(), False
            destroy(Jcc)
            Jcc = J.createSubMatrix(self.IS, self.IS)  # its Dirichlet columns whole (LU)
            self._schur(Jcc)
        destroy(Jcc)
        if inverted:  # PETSc would factorise S as symmetric: hand it S^-1
            _cpp.schur_update(self.F, _invert(self.S), inverted=True)
        else:
            _cpp.schur_update(self.F, self.S)
        self.schur_factorisations += 1
        # m too large for its n (timer noise aside: twice, and 50 ms): refactorise instead
        if time.perf_counter() - t0 > max(2.0 * self.t_factor, self.min_handover):
            self.full = Factorised(self.problem, self.petsc_options)
            self.full.factorisations = self.factorisations
            self.name = f"factorised (condensed: {self.num_dofs} contact dofs cost more)"
            destroy(self.F)
            self.F = self.S = self.base = None
            self.full.setup(J, None)
            self.full.operator = self.operator
            return

    def release(self):
        """Free the factorisations (`Factorised.release`); the next `setup` makes them again."""
        if self.full is not None:
            return self.full.release()
        destroy(self.F)
        self.F = self.S = self.base = self.J = self.key = None

    def _schur(self, Jcc):
        """S = S0 + (J_cc - K0_cc) into self.S; whether it is symmetric. With the LDL^T factor
        J's Dirichlet rows and columns are eliminated first (in Jcc), as the factor's are: S0
        - K0_cc is symmetric, so S is wherever Jcc is."""
        symmetric = False
        if self.symmetric:
            if len(self.fixed):
                Jcc.zeroRowsColumns(self.fixed.astype(np.int32), diag=1.0)
            symmetric = _symmetric(Jcc)
        self.S[...] = self.base
        _add_sparse(self.S, Jcc)
        return symmetric

    def solve(self, b, x):
        if self.full is not None:
            return self.full.solve(b, x)
        if not self.symmetric:
            return self.F.solve(b, x)
        rhs, lifted = self.dirichlet.rhs(self.J, b)  # J's own J_FD (contact included)
        self.F.solve(rhs, x)
        self.dirichlet.finish(x, lifted)

    def destroy(self):
        destroy(self.F, self.IS)
        self.dirichlet.destroy()
        if self.full is not None:
            self.full.destroy()
        self.F = self.IS = self.S = self.base = None

    @property
    def factorisations(self):
        return self._factorisations if self.full is None else self.full.factorisations

    @factorisations.setter
    def factorisations(self, n):
        self._factorisations = n


class Iterative:
    """CG + GAMG on J with the Dirichlet rows *and columns* eliminated, the AMG set-up reused.

    Why CG: J's rows are zeroed but its columns kept, so J is not symmetric; the solve lifts
    the Dirichlet values instead (x_D = b_D, b_F -= J_FD b_D: one product) and iterates on A,
    J with those rows and columns replaced by the identity, which is symmetric positive
    definite where the bulk and the contact tangent are: a linear bulk with frictionless
    penalty contact (the tangent of eq 48 then is symmetric: |A - A^T| / |A| = 6e-17 on Hertz,
    `tests/solvers/test_iterative.py`).
    Friction (slip: a non-symmetric tangent) or a nonlinear law switch the Krylov method to
    GMRES (`krylov`), with the same preconditioner.

    Why the near-null space: smoothed aggregation then interpolates the rigid-body modes on
    every aggregate (3 in 2D: two translations and the rotation, from the dof coordinates);
    without them GAMG interpolates the translations only: 77 instead of 61 CG iterations on
    body-fitted Hertz at 45k dofs, 597 instead of 444 on the cut one at 28k.

    Reuse: J changes in a few hundred contact rows between Newton iterations, so the AMG
    hierarchy of an earlier J often preconditions a later one almost as well. A solve with a
    reused hierarchy gets `reuse_growth` times (and `reuse_slack` more than) the iterations of
    the first solve after the last set-up; short of convergence the hierarchy is rebuilt on
    this J and the solve goes on from its iterate (`cap_reused`; uncapped, a reused hierarchy
    after the first force-control iteration took 99 iterations where a new one takes 33 at
    702k dofs, and 2654 instead of 842 on the cut path at 377k).

    Tolerance: a Newton step solves J du = -R to a residual of a tenth of the residual that
    Newton must reach (`newton_target`, set by `newton.newton`: rtol r0 of the step, or the
    round-off floor), whatever |R|: once the active set settles, one step then lowers the
    residual below Newton's tolerance as a direct solve does, so Newton takes the iterations
    of the direct solvers and the answers agree to Newton's tolerance. (A tolerance relative
    to |R| does not: R grows 3x in the first force-control iteration, and rtol 1e-11 |R| left
    the next residual 10x above the target, one more Newton iteration at 164k dofs.) Other
    solves (the force control's border, which lifts Dirichlet values) use ksp_rtol, default a
    tenth of Newton's rtol."""

    name = "iterative"
    reuse_growth, reuse_slack = 1.5, 10
    cap_reused = True

    def __init__(self, problem, petsc_options=None):
        self.problem = problem
        opts = {**ITERATIVE_OPTIONS, "ksp_rtol": 0.1 * problem.newton.rtol, **(petsc_options or {})}
        symmetric = not problem.bulk.nonlinear and problem.contact.mu == 0
        self.krylov = opts.pop("ksp_type", None) or ("cg" if symmetric else "gmres")
        self.ksp = PETSc.KSP().create(problem.comm)
        self.ksp.setOptionsPrefix("ils_")
        o = PETSc.Options()
        for k, v in {"ksp_type": self.krylov, **opts}.items():
            o["ils_" + k] = v
        self.ksp.setFromOptions()
        self._true_residual()
        self.max_it = self.ksp.getTolerances()[3]
        self.dirichlet = DirichletLift(problem)
        self.A = self.dirichlet.eliminated(problem.J)
        modes = rigid_modes(problem)
        self.A.setNearNullSpace(modes)
        destroy(modes)  # A holds its own reference
        self.J = None
        self.key = None
        self.operator = 0  # the J set up last (`_OPERATORS`; 0: none)
        self.fresh = None  # iterations of the first solve after the last AMG set-up
        self.rebuild = True
        self.setups = 0
        self.iterations = []  # per solve
        self.t_setup = self.t_krylov = 0.0  # s: AMG set-ups, Krylov iterations
        self.rtol = float(opts.get("ksp_rtol", 0.1 * problem.newton.rtol))
        self.newton_target = None  # force units (newton.newton sets it before each step)
        self.user_rtol = "ksp_rtol" in (petsc_options or {})  # then for every solve

    @property
    def factorisations(self):  # the AMG set-ups, in the place of the direct solvers' count
        return self.setups

    def setup(self, J, key):
        self.J = J
        if key is not None and key == self.key and not self.rebuild:
            return
        if self.krylov == "cg" and self.problem.contact.mu > 0:  # friction switched on
            self.krylov = "gmres"
            self.ksp.setType("gmres")
            self._true_residual()
        self.key = key
        self.operator = next(_OPERATORS)
        self.dirichlet.eliminated(J, self.A)
        self._operators(self.rebuild)

    def destroy(self):
        destroy(self.ksp, self.A)
        self.dirichlet.destroy()
        self.ksp = self.A = self.J = None

    def release(self):
        """Nothing: the AMG hierarchy (about the size of J, not of a factor) is kept. A KSP
        reset and a new hierarchy on the same J fail on PETSc 3.18's GAMG ("Cannot change
        local size of Amat after use", tests/solvers/test_linear.py)."""

    def _true_residual(self):
        """Test |J x - b| itself (the tolerances are forces): CG's default norm is the
        preconditioned residual's; GMRES needs right preconditioning for it."""
        if self.ksp.getType() in ("gmres", "fgmres", "fcg", "bcgs"):
            self.ksp.setPCSide(PETSc.PC.Side.RIGHT)
        self.ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)

    def _operators(self, rebuild):
        self.ksp.getPC().setReusePreconditioner(not rebuild)
        self.ksp.setOperators(self.A)
        if rebuild:
            self.setups += 1
            self.fresh, self.rebuild = None, False

    def solve(self, b, x):
        rhs, lifted = self.dirichlet.rhs(self.J, b)
        if lifted or self.newton_target is None or self.user_rtol:
            self.ksp.setTolerances(rtol=self.rtol, atol=1e-50)
        else:  # |J du + R| <= target / 10; rtol 1e-12: a floor that CG reaches in doubles
            self.ksp.setTolerances(rtol=1e-12, atol=0.1 * self.newton_target)
        reused = self.fresh is not None
        if reused and self.cap_reused:  # a reused AMG gets the iterations a fresh one needs
            cap = max(self.reuse_growth * self.fresh, self.fresh + self.reuse_slack)
            self.ksp.setTolerances(max_it=int(cap))
        its, reason = self._solve(rhs, x)
        self.ksp.setTolerances(max_it=self.max_it)
        if reason < 0 and reused:  # rebuilt on this J, the solve goes on from where it stopped
            self._operators(True)
            self.ksp.setInitialGuessNonzero(True)
            its2, reason = self._solve(rhs, x)
            self.ksp.setInitialGuessNonzero(False)
            its, self.fresh, reused = its + its2, its2, False
        self.iterations.append(int(its))
        if reason < 0:
            raise LinearSolverError(
                f"linear solver ({self.krylov} + AMG) diverged ({diverged_reason(self.ksp)}, "
                f"{its} iterations)"
            )
        if self.fresh is None:
            self.fresh = its
        elif reused and its > max(self.reuse_growth * self.fresh, self.fresh + self.reuse_slack):
            self._operators(True)  # now: A is this iteration's J (the border solve follows)
        self.dirichlet.finish(x, lifted)

    def _solve(self, rhs, x):
        t0 = time.perf_counter()
        self.ksp.setUp()  # the AMG set-up, where one is due
        t1 = time.perf_counter()
        self.ksp.solve(rhs, x)
        self.t_setup += t1 - t0
        self.t_krylov += time.perf_counter() - t1
        return self.ksp.getIterationNumber(), self.ksp.getConvergedReason()


def rigid_modes(problem):
    """The near-null space of 2D elasticity on problem.V: the translations in x and y and the
    rotation (-y, x) about the dofs' centroid, orthonormalised (PETSc's requirement)."""
    from dolfinx import la

    V, comm = problem.V, problem.comm
    n = problem.n_owned // problem.bs
    X = V.tabulate_dof_coordinates()[:n, :2]
    centre = comm.allreduce(X.sum(axis=0), op=MPI.SUM) / max(comm.allreduce(n, op=MPI.SUM), 1)
    X = X - centre
    vecs = [problem.K.createVecLeft() for _ in range(3)]
    for i, v in enumerate(vecs[:2]):
        v.array.reshape(-1, 2)[:, i] = 1.0
    r = vecs[2].array.reshape(-1, 2)
    r[:, 0], r[:, 1] = -X[:, 1], X[:, 0]
    la.orthonormalize(vecs)
    ns = PETSc.NullSpace().create(vectors=vecs, comm=comm)
    destroy(*vecs)  # the null space keeps its own copies
    return ns


def _add_sparse(D, A, scale=1.0):
    """D += scale A for a dense array D and a sequential sparse A of its shape (one entry of A
    per (i, j): no duplicate indices in its CSR rows)."""
    ai, aj, av = A.getValuesCSR()
    D[np.repeat(np.arange(len(ai) - 1), np.diff(ai)), aj] += scale * av


def _invert(S):
    """S^-1 in S's own buffer (LAPACK getrf + getri on S^T, which is S's C-ordered buffer read
    in Fortran order: a fresh m x m array per Newton iteration costs page faults at large m).
    RuntimeError on an exactly singular S (a zero pivot), as PETSc's dense LU would."""
    lu, piv, info = lapack.dgetrf(S.T, overwrite_a=True)
    if info == 0:
        inv, info = lapack.dgetri(lu, piv, overwrite_lu=True)
    if info != 0:
        raise RuntimeError(f"the contact dofs' Schur complement is singular (LAPACK info {info})")
    if not np.shares_memory(inv, S):  # f2py copied: S^-1 = (S^T)^-1 transposed
        S[...] = inv.T
    return S


def _symmetric(A):
    """A (sparse) symmetric to SYMMETRY_RTOL of its norm (MatIsSymmetric's tol is absolute)."""
    return A.isSymmetric(SYMMETRY_RTOL * A.norm(PETSc.NormType.INFINITY))


def contact_dofs(problem):
    """The (unrolled, local) dofs the contact tangent can couple: every pair's law points."""
    blocks = [b for g in problem.contact.pairs for b in g.quadrature.coupling_dofs()]
    if not blocks:
        return np.zeros(0, np.int32)
    nodes = np.unique(np.concatenate(blocks))
    return (nodes[:, None] * problem.bs + np.arange(problem.bs)).ravel().astype(np.int32)


def choose(problem, kind="auto", petsc_options=None, picked=None):
    """kind: "auto", "condensed" (raises where it does not apply), "factorised" or "iterative".
    "auto": Iterative for a body-fitted scene of at least ITERATIVE_MIN_DOFS dofs with the
    default solver options (or for options naming pc_type=gamg); else Condensed for a linear
    bulk on one process with the default direct solver and a contact block of m dofs well
    below the n dofs, m^3 <= defaults.TUNING.condensed_cost n^1.5; Factorised otherwise.
    picked: `pick`'s answer for these options, if the caller has it (the contact dofs once)."""
    picked, dofs = picked or pick(problem, kind, petsc_options)
    if picked == "iterative":
        return Iterative(problem, _without_direct(petsc_options) if kind == "iterative" else (
            petsc_options if (petsc_options or {}).get("pc_type") == "gamg" else None))  # fmt: skip
    if picked == "condensed":
        return Condensed(problem, dofs, petsc_options)
    # Factorised's LDL^T, LU once J is not symmetric
    symmetric = _default(petsc_options) and problem.mu == 0
    return Factorised(problem, petsc_options, symmetric)


def pick(problem, kind="auto", petsc_options=None):
    """(the solver `choose` builds for these options: "factorised", "condensed" or
    "iterative", Condensed's contact dofs or None); ValueError where "condensed" does not
    apply. Only a factorisation of the whole J pays for the explicit zeros of its sparsity
    (`ContactProblem.coupled`)."""
    if kind not in KINDS:
        raise ValueError(f"linear_solver: {', '.join(map(repr, KINDS))}, not {kind!r}")
    if kind in ("factorised", "iterative"):
        return kind, None
    default = _default(petsc_options)
    body_fitted = getattr(problem.scene, "cut", None) is None
    if kind == "auto" and (
        (petsc_options or {}).get("pc_type") == "gamg"
        or (default and body_fitted and problem.num_dofs >= ITERATIVE_MIN_DOFS)
    ):
        return "iterative", None
    why, dofs = _not_condensed(problem, kind, petsc_options)
    if why is None:
        return "condensed", dofs
    if kind == "condensed":
        raise SolverChoiceError(
            f"'condensed' does not apply here: {why}; give auto, factorised or iterative"
        )
    return "factorised", None


def _not_condensed(problem, kind, petsc_options):
    """(why Condensed does not apply, or does not pay under "auto"; None where it does, the
    contact dofs)."""
    default = _default(petsc_options)
    why = None
    if problem.comm.size > 1:
        why = "MUMPS Schur complements are serial"
    elif problem.bulk.nonlinear:
        why = "the bulk is nonlinear (its tangent changes every iteration)"
    elif not default:
        why = "other PETSc solver options were given"
    dofs = contact_dofs(problem) if why is None else None
    m, n = (0, problem.num_dofs) if dofs is None else (len(dofs), problem.num_dofs)
    if why is None and not 0 < m <= min(MAX_CONDENSED, n // 4):
        why = f"{m} contact dofs of {n} (it takes 0 < m <= min({MAX_CONDENSED}, n / 4))"
    costly = float(m) ** 3 > defaults.TUNING.condensed_cost * float(n) ** 1.5
    if why is None and kind == "auto" and costly:
        why = f"{m} contact dofs of {n}: a dense update would cost more than a factorisation"
    return why, dofs


def _default(petsc_options):
    """Whether the options are the default direct solver's (none, or equal to them)."""
    return not petsc_options or {**DEFAULT_OPTIONS, **petsc_options} == DEFAULT_OPTIONS


def _without_direct(petsc_options):
    """The user's options minus the direct solver's defaults (an explicit "iterative" keeps
    its own Krylov method and AMG)."""
    return {k: v for k, v in (petsc_options or {}).items() if DEFAULT_OPTIONS.get(k) != v}
