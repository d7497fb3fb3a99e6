"""Newton's linear solves (dolfinx_forms.solvers.linear): the condensed bulk (one sparse
factorisation, Newton on the dense Schur complement of the contact dofs) against a full
factorisation per iteration, on the same frictional Hertz path (normal force, then a tangential
one), both paths.

Both solve J du = -R exactly (direct solvers): the iterates, hence the converged states, agree
to round-off amplified by the conditioning, far below the Newton tolerance (1e-10 of R)."""

import dataclasses

import numpy as np
import pytest
from mpi4py import MPI

from dolfinx_forms import defaults
from dolfinx_forms.fem.boundary import Dirichlet
from dolfinx_forms.fem.laws import NeoHookean
from dolfinx_forms.solvers import linear, protocol
from dolfinx_forms.solvers.options import options
from dolfinx_forms.solvers.problem import ContactProblem

E, NU, R, P = 1.0e4, 0.3, 10.0, 430.0
pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial: MUMPS Schur")


def scene(kind):
    from meshes.cut import hertz_cut_scene
    from meshes.hertz import hertz_scene

    size = dict(R=R, width=20.0, depth=10.0, h=0.25, zone=1.6)
    if kind == "cut":
        return hertz_cut_scene(MPI.COMM_WORLD, **size)
    return hertz_scene(MPI.COMM_WORLD, **size)


def hertz_problem(sc, linear_solver, materials=None, **extra):
    top_x, top_y = Dirichlet("cylinder_top", 0, 0.0), Dirichlet("cylinder_top", 1, 0.0)
    pb = ContactProblem(
        sc,
        materials or {b.tag: (E, NU) for b in sc.bodies},
        dirichlet=[Dirichlet("block_bottom", None, 0.0), top_x, top_y],
        log=lambda *a, **k: None,
        **options(eps0=0.5, band=1.6**2 / (2 * R), linear_solver=linear_solver, **extra),
    )
    return pb, top_x, top_y


def mindlin(sc, linear_solver, materials=None, before=None, **extra):
    """Normal force P (frictionless), friction on, tangential force Q = 0.5 mu P; returns the
    problem and the reactions reached by the two force stages (each right after its stage)."""
    pb, top_x, top_y = hertz_problem(sc, linear_solver, materials, **extra)
    if before is not None:
        before(pb)
    protocol.reach_force(pb, top_y, "block_bottom", 1, P, first_guess=-0.05)
    reached = [pb.reaction("block_bottom")[1]]
    protocol.friction_on(pb, 0.3)
    protocol.reach_force(pb, top_x, "cylinder_top", 0, 0.5 * 0.3 * P, 1e-5, monotone=True)
    pb.reached = reached + [pb.reaction("cylinder_top")[0]]
    return pb


@pytest.mark.parametrize("kind", ["conforming", "cut"])
def test_condensed_equals_factorised(kind, monkeypatch):
    """m too large to invert S per iteration (`INVERT_COST` 0 here): the first slip's
    non-symmetric J refactorises the bulk as LU; the same path as `Factorised`."""
    monkeypatch.setattr(linear, "INVERT_COST", 0.0)
    sc = scene(kind)
    a, b = mindlin(sc, "condensed"), mindlin(sc, "factorised")
    assert a.linear.name == "condensed" and b.linear.name == "factorised"
    assert 0 < a.linear.num_dofs < a.num_dofs // 4
    ua, ub = a.u.x.array, b.u.x.array
    assert np.abs(ua - ub).max() <= 1e-9 * np.abs(ub).max()
    assert [s.iterations for s in a.steps] == [s.iterations for s in b.steps]
    # two sparse factorisations for the whole path (LDL^T while frictionless, LU from the
    # first slip's non-symmetric J on), one dense Schur update per changed J
    assert a.factorisations == 2 and b.factorisations > 2
    assert not a.linear.symmetric and not b.linear.symmetric  # both LU since friction on
    pc = b.linear.ksp.getPC()
    assert (pc.getType(), pc.getFactorSolverType()) == ("lu", "mumps")
    assert 0 < a.linear.schur_factorisations <= b.factorisations  # none while nothing touches
    assert a.reaction("cylinder_top")[0] == pytest.approx(0.5 * 0.3 * P, rel=1e-9)


@pytest.mark.parametrize("kind", ["conforming", "cut"])
def test_friction_on_the_symmetric_factor(kind, monkeypatch):
    """m small enough for its n (`INVERT_COST`, raised here: these scenes are small): the bulk
    stays LDL^T through the frictional stage, the non-symmetric Schur complement handed to PETSc
    inverted; the same iterates and state as a full LU factorisation per iteration."""
    monkeypatch.setattr(linear, "INVERT_COST", 1e9)
    sc = scene(kind)
    a, b = mindlin(sc, "condensed"), mindlin(sc, "factorised")
    assert a.linear.name == "condensed" and a.linear.symmetric and a.factorisations == 1
    assert not b.linear.symmetric  # LU since friction on
    assert a.linear.schur_factorisations >= 3
    ua, ub = a.u.x.array, b.u.x.array
    assert np.abs(ua - ub).max() <= 1e-9 * np.abs(ub).max()
    assert [s.iterations for s in a.steps] == [s.iterations for s in b.steps]
    assert a.reached == pytest.approx(b.reached, rel=1e-9)


def test_invert_in_place():
    """linear._invert: S^-1 in S's buffer (C order), and a clear error on a singular S."""
    rng = np.random.default_rng(0)
    S = rng.random((40, 40)) + 40 * np.eye(40)
    S0 = S.copy()
    X = linear._invert(S)
    assert X is S and np.abs(X @ S0 - np.eye(40)).max() < 1e-12
    with pytest.raises(RuntimeError, match="singular"):
        linear._invert(np.zeros((3, 3)))


@pytest.mark.parametrize("solver", ["condensed", "factorised", "lu", "iterative"])
def test_release_frees_the_factors_and_solves_again(solver):
    """`release` (what a converged MPM step calls: the next step has its own solver): the
    factors are gone, and the next setup factorises again and solves as before (`Iterative`
    keeps its AMG hierarchy and solves as before)."""
    pb, top_x, top_y = hertz_problem(scene("cut"), "factorised" if solver == "lu" else solver)
    if solver == "lu":
        pb.linear = linear.Factorised(pb)
    protocol.reach_force(pb, top_y, "block_bottom", 1, P, first_guess=-0.05)
    b = pb.R.duplicate()
    b.array[:] = np.linspace(-1.0, 1.0, len(b.array))
    x0, x1 = b.duplicate(), b.duplicate()
    pb.linear.setup(pb.J, None)
    pb.linear.solve(b, x0)
    n = pb.factorisations
    pb.release_solver()
    if solver == "condensed":
        assert pb.linear.F is None and pb.linear.S is None
    elif solver == "iterative":
        n -= 1  # the AMG hierarchy is kept (`Iterative.release`): no new set-up
    else:
        with pytest.raises(Exception):  # no factor left on the PC
            pb.linear.ksp.getPC().getFactorMatrix()
    pb.linear.setup(pb.J, None)
    pb.linear.solve(b, x1)
    assert pb.factorisations == n + 1
    assert np.abs(x1.array - x0.array).max() <= 1e-10 * np.abs(x0.array).max()


@pytest.mark.parametrize("kind", ["conforming", "cut"])
def test_symmetric_factor_while_frictionless(kind):
    """Normal force only: the bulk stays factorised once, as LDL^T with the Dirichlet columns
    eliminated and the moving top's values lifted in each solve (force control moves them:
    the border solves have b_D != 0); the same iterates as LU per iteration."""
    sc = scene(kind)
    runs = []
    for solver in ("condensed", "factorised", "lu"):
        pb, top_x, top_y = hertz_problem(sc, "factorised" if solver == "lu" else solver)
        if solver == "lu":
            pb.linear = linear.Factorised(pb)  # LU of J, rows eliminated: the plain reference
        protocol.reach_force(pb, top_y, "block_bottom", 1, P, first_guess=-0.05)
        runs.append(pb)
    a, b, c = runs
    assert c.linear.ksp.getPC().getType() == "lu"
    for other in (a, b):
        uo, uc = other.u.x.array, c.u.x.array
        assert np.abs(uo - uc).max() <= 1e-9 * np.abs(uc).max()
        assert [s.iterations for s in other.steps] == [s.iterations for s in c.steps]
    assert a.linear.symmetric and a.factorisations == 1
    assert b.linear.symmetric  # Factorised's LDL^T of J with the Dirichlet columns eliminated
    assert b.linear.ksp.getPC().getType() == "cholesky"
    assert a.linear.schur_factorisations >= 2
    ua, ub = a.u.x.array, b.u.x.array
    assert np.abs(ua - ub).max() <= 1e-9 * np.abs(ub).max()
    assert [s.iterations for s in a.steps] == [s.iterations for s in b.steps]
    assert a.reaction("block_bottom")[1] == pytest.approx(P, rel=1e-9)


def test_symmetric_solve_lifts_dirichlet_values():
    """One solve with the LDL^T factor against LU on J = K0 with b_D != 0 (rows of the
    Dirichlet dofs zeroed, columns kept): the same x to round-off."""
    pb, top_x, top_y = hertz_problem(scene("conforming"), "condensed")
    lin = pb.linear
    assert lin.symmetric
    K0 = pb.K.copy()
    K0.zeroRows(pb.bc_global, diag=1.0)
    lin.setup(K0, None)  # S = S0: J = K0, no contact
    ref = linear.Factorised(pb)
    ref.setup(K0, None)
    b = K0.createVecLeft()
    b.setArray(np.random.default_rng(1).standard_normal(b.getLocalSize()))
    x, y = b.duplicate(), b.duplicate()
    lin.solve(b, x)
    ref.solve(b, y)
    assert np.abs(b.array[lin.bc]).min() > 0
    assert np.abs(x.array - y.array).max() <= 1e-10 * np.abs(y.array).max()


def test_choice():
    sc = scene("cut")
    pb = mindlin(sc, "auto")
    # the choice, not its timing: on a loaded machine a dense update may cost more than
    # twice the sparse factorisation and hand over (`test_hand_over_...`)
    assert isinstance(pb.linear, linear.Condensed)
    assert linear.choose(pb, "auto").name == "condensed"
    with pytest.raises(
        ValueError, match="linear_solver: 'auto', 'condensed', 'factorised', 'iterative'"
    ):
        linear.choose(pb, "schur")
    # the user's solver options are honoured: a full factorisation
    assert linear.choose(pb, "auto", {"pc_factor_mat_solver_type": "superlu"}).name == "factorised"
    assert linear.choose(pb, "auto", dict(linear.DEFAULT_OPTIONS)).name == "condensed"


def test_auto_factorises_a_large_contact_block(monkeypatch):
    """ "auto" condenses only where a dense update (~m^3) is cheaper than a sparse
    factorisation (~n^1.5): with the bound at 0 every contact block is too large, and an
    explicit "condensed" still condenses."""
    pb = mindlin(scene("cut"), "auto")
    m, n = len(linear.contact_dofs(pb)), pb.num_dofs
    assert m**3 <= defaults.TUNING.condensed_cost * n**1.5  # this scene: condensed by default
    never = dataclasses.replace(defaults.TUNING, condensed_cost=0.0)
    monkeypatch.setattr(defaults, "TUNING", never)
    assert linear.choose(pb, "auto").name == "factorised"
    assert linear.choose(pb, "condensed").name == "condensed"


def test_nonlinear_bulk_is_factorised():
    sc = scene("conforming")
    laws = {b.tag: NeoHookean(E, NU) for b in sc.bodies}
    with pytest.raises(ValueError, match="nonlinear"):
        mindlin(sc, "condensed", laws)


def test_hand_over_when_the_dense_block_costs_more():
    """A dense update slower than the sparse factorisation: the rest of the run refactorises
    the full J, with the same answer."""
    sc = scene("cut")

    def slow(pb):
        pb.linear.t_factor = pb.linear.min_handover = 0.0  # every dense update "costs more"

    a, b = mindlin(sc, "condensed", before=slow), mindlin(sc, "factorised")
    assert a.linear.name.startswith("factorised (condensed:")
    assert a.linear.schur_factorisations == 1 and a.factorisations > 1
    ua, ub = a.u.x.array, b.u.x.array
    assert np.abs(ua - ub).max() <= 1e-9 * np.abs(ub).max()


def test_force_control_with_a_nonlinear_law():
    """Neo-Hookean bodies (finite strain): a full factorisation per iteration, and the force
    control's gradient k = J^T 1_b takes the nonlinear bulk rows: each force reached to 1e-9
    (the normal one right after its stage: at finite strain the tangential stage shifts it)."""
    sc = scene("cut")
    pb = mindlin(sc, "auto", {b.tag: NeoHookean(E, NU) for b in sc.bodies})
    assert pb.linear.name == "factorised"
    assert pb.reached == pytest.approx([P, 0.5 * 0.3 * P], rel=1e-9)


@pytest.mark.parametrize("kind,enforcement", [("cut", "augmented"), ("conforming", "penalty")])
def test_tangent_kept_while_its_key_holds(kind, enforcement, monkeypatch):
    """newton._keep: an iteration whose key (active set, mu, force control) is the one J was
    assembled for skips the tangent's assembly. The Mindlin path (two force controls, mu
    switched on, slip) gives the same iterates as assembling J every iteration, with fewer
    assemblies."""
    from dolfinx_forms.solvers import newton
    from dolfinx_forms.solvers.problem import ContactProblem as CP

    sc = scene(kind)
    counts = []

    def counted(self, lam, with_tangent=False, **kw):
        counts[-1] += with_tangent
        return CP.residual.__wrapped__(self, lam, with_tangent, **kw)

    counted.__wrapped__ = CP.residual
    monkeypatch.setattr(CP, "residual", counted)
    from dolfinx_forms.solvers.options import ContactOptions

    init = CP.__init__

    def with_enforcement(s, *a, contact=None, **k):
        contact = dataclasses.replace(contact or ContactOptions(), enforcement=enforcement)
        init(s, *a, contact=contact, **k)

    monkeypatch.setattr(CP, "__init__", with_enforcement)

    def run():
        counts.append(0)
        return mindlin(sc, "condensed")

    kept = run()
    keep = newton._keep

    def always(problem, key, lazy, lam):  # every iteration assembles J (the reference)
        keep(problem, key, lazy, lam)
        problem.J_key = None

    monkeypatch.setattr(newton, "_keep", always)
    ref = run()
    assert [s.residuals for s in kept.steps] == [s.residuals for s in ref.steps]
    assert np.array_equal(kept.u.x.array, ref.u.x.array)
    print(f"tangent assemblies: {counts[0]} kept against {counts[1]}")
    assert counts[0] < counts[1]


def test_a_failed_factorisation_names_mumps_error():
    # a singular matrix (a zero row) factorised by MUMPS: PETSc reports DIVERGED_PCSETUP_FAILED
    # only; the message adds MUMPS's INFOG(1) = -10 (numerically singular)
    from petsc4py import PETSc

    A = PETSc.Mat().createAIJ([3, 3], nnz=1, comm=MPI.COMM_SELF)
    for i, v in ((0, 2.0), (1, 0.0), (2, 3.0)):
        A.setValue(i, i, v)
    A.assemble()
    ksp = PETSc.KSP().create(MPI.COMM_SELF)
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    ksp.setErrorIfNotConverged(False)
    x, b = A.createVecs()
    b.set(1.0)
    try:
        ksp.solve(b, x)
    except PETSc.Error:
        pass
    assert ksp.getConvergedReason() == PETSc.KSP.ConvergedReason.DIVERGED_PCSETUP_FAILED
    text = linear.diverged_reason(ksp)
    assert text.startswith("DIVERGED_PCSETUP_FAILED -11, MUMPS INFOG(1) = -10"), text
    ksp.destroy()
    A.destroy()
