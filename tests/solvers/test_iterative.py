"""The iterative linear solver (dolfinx_forms.solvers.linear.Iterative: CG + GAMG with the
rigid-body modes as near-null space) against the factorised one, its near-null space, and its
iteration counts on small cut cells."""

import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_forms.solvers import linear, protocol
from dolfinx_forms.solvers.newton import ContactSolverError
from dolfinx_forms.solvers.options import options
from dolfinx_forms.solvers.problem import ContactProblem

from test_linear import P, hertz_problem, scene

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial scenes")


def hertz(sc, linear_solver):
    pb, _, top_y = hertz_problem(sc, linear_solver)
    protocol.reach_force(pb, top_y, "block_bottom", 1, P, first_guess=-0.05)
    return pb


@pytest.mark.parametrize("kind", ["conforming", "cut"])
def test_iterative_equals_factorised(kind):
    """The Krylov tolerance is a tenth of Newton's (1e-10 of the residual): each Newton step is
    then as good as a direct one, so Newton takes the same iterations, and both stop at a
    residual below 1e-10 of the first one, i.e. states equal to that residual through K^-1
    (measured 5e-15 and 4e-15 of |u| here; test_linear's direct solvers: 1e-9). A looser
    Krylov tolerance (1e-4 or 1e-6) costs Newton one more iteration and fails the count."""
    sc = scene(kind)
    a, b = hertz(sc, "iterative"), hertz(sc, "factorised")
    assert a.linear.name == "iterative" and a.linear.krylov == "cg"
    # CG's premise: the Dirichlet-eliminated frictionless tangent is symmetric
    A = a.linear.A
    assert A.isSymmetric(1e-12 * A.norm(PETSc.NormType.INFINITY))
    assert [s.iterations for s in a.steps] == [s.iterations for s in b.steps]
    ua, ub = a.u.x.array, b.u.x.array
    assert np.abs(ua - ub).max() <= 1e-9 * np.abs(ub).max()
    assert a.reaction("block_bottom")[1] == pytest.approx(b.reaction("block_bottom")[1], rel=1e-9)
    # the AMG hierarchy is reused: fewer set-ups than solves, bounded iterations
    its = a.linear.iterations
    assert a.linear.setups < len(its) and max(its) < 100


def test_near_null_space_is_the_rigid_body_modes():
    """3 orthonormal modes that the bulk stiffness K of free bodies (no Dirichlet rows)
    annihilates, on both paths (cut forms and ghost penalty included); a mode that is not rigid
    (a stretch) is not annihilated."""
    for kind in ("conforming", "cut"):
        pb, _, _ = hertz_problem(scene(kind), "factorised")
        modes = linear.rigid_modes(pb).getVecs()
        assert len(modes) == 3
        gram = np.array([[u.dot(v) for v in modes] for u in modes])
        assert np.allclose(gram, np.eye(3), atol=1e-12)
        Km = pb.K.createVecLeft()
        # the yardstick: a unit uniform stretch (x, 0), a smooth field K does not annihilate
        stretch = pb.K.createVecLeft()
        stretch.array.reshape(-1, 2)[:, 0] = pb.V.tabulate_dof_coordinates()[:, 0]
        stretch.scale(1 / stretch.norm())
        pb.K.mult(stretch, Km)
        ref = Km.norm()
        for m in modes:
            pb.K.mult(m, Km)
            assert Km.norm() <= 1e-10 * ref, (kind, Km.norm() / ref)


def patch_iterations(eta, gamma, petsc_options=None, n=20, eps0=0.5):
    from benchmarks.small_cuts import interface_height
    from meshes.cut import patch_cut_scene
    from meshes.patch import patch_dirichlet

    sc = patch_cut_scene(MPI.COMM_WORLD, n=n, interface=interface_height(n, eta))
    pb = ContactProblem(
        sc,
        {b.tag: (1.0, 0.3) for b in sc.bodies},
        dirichlet=patch_dirichlet(0.01, 1.0),
        log=lambda *a, **k: None,
        **options(
            eps0=eps0,
            band=0.5 / n,
            ghost_penalty=gamma,
            linear_solver="iterative",
            petsc_options=petsc_options,
        ),
    )
    pb.solve()
    return max(pb.linear.iterations)


@pytest.mark.parametrize("gamma", [0.0, 0.01])
def test_patch_iterations_bounded_in_the_cut_fraction(gamma):
    """The cut patch test (the lower body's top row cut with inside fraction eta, Hertz's
    penalty eps0 = 0.5): the CG iterations stay within 1.2x (+2) of those at eta = 0.5 down to
    eta = 1e-8, with or without ghost penalty (measured 23-27 at n = 20; benchmarks/amg.py:
    32-38 at n = 60; the patch test's stiff eps0 = 1e-3: 154, 95, 107 at eta = 0.5, 1e-4,
    1e-8). Without ghost penalty PETSc's GAMG defaults (the prolongator's eigenvalue estimate
    reused by the Chebyshev smoothers) stop at eta = 1e-8 on an indefinite preconditioner."""
    ref = patch_iterations(0.5, gamma)
    assert ref <= 40
    for eta in (1e-4, 1e-8):
        assert patch_iterations(eta, gamma) <= 1.2 * ref + 2, eta
    if gamma == 0.0:
        defaults = {"pc_gamg_use_sa_esteig": "1", "mg_levels_ksp_chebyshev_esteig_steps": "10"}
        with pytest.raises(ContactSolverError, match="diverged"):
            patch_iterations(1e-8, gamma, defaults)


def test_auto_choice(monkeypatch):
    """ "auto": Iterative for a body-fitted scene from ITERATIVE_MIN_DOFS on (and for options
    naming GAMG), never for a cut scene; below it today's choice (condensed)."""
    conforming, _, _ = hertz_problem(scene("conforming"), "factorised")
    cut, _, _ = hertz_problem(scene("cut"), "factorised")
    assert linear.choose(conforming, "auto").name == "condensed"
    assert linear.choose(conforming, "auto", {"pc_type": "gamg"}).name == "iterative"
    monkeypatch.setattr(linear, "ITERATIVE_MIN_DOFS", conforming.num_dofs)
    assert linear.choose(conforming, "auto").name == "iterative"
    assert linear.choose(cut, "auto").name == "condensed"
    # an explicit "iterative" drops the direct solver's defaults, keeps the user's options
    it = linear.choose(cut, "iterative", dict(linear.DEFAULT_OPTIONS, ksp_rtol="1e-6"))
    assert it.krylov == "cg" and it.rtol == 1e-6 and it.user_rtol
    with pytest.raises(ValueError, match="'iterative'"):
        linear.choose(cut, "amg")


def test_friction_switches_to_gmres():
    """Friction switched on (a non-symmetric tangent with slip): GMRES with the same AMG; the
    Cattaneo-Mindlin path of test_linear equals the factorised one (same Newton iterations,
    u to 1e-9; measured 1e-12)."""
    from test_linear import mindlin

    sc = scene("conforming")
    a, b = mindlin(sc, "iterative"), mindlin(sc, "factorised")
    assert a.linear.krylov == "gmres"
    assert [s.iterations for s in a.steps] == [s.iterations for s in b.steps]
    ua, ub = a.u.x.array, b.u.x.array
    assert np.abs(ua - ub).max() <= 1e-9 * np.abs(ub).max()
    assert a.reached == pytest.approx(b.reached, rel=1e-9)
