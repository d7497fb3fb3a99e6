"""Load protocols (dolfinx_forms.solvers.protocol) on the cut patch test (n = 3: 3 x 3 cells, the
interface y = 0.5 cuts the middle row).

The frictionless patch problem is linear while the interface stays closed: the reaction on the
top is -p width with p = E' d / (H + E' eps_n) (E' = E / (1 - nu^2), H = 1) for a top
displacement -d, to round-off. So a ramp must be linear in the displacement, and force control
(secant) converges in two iterations.
"""

import numpy as np
import pytest
from mpi4py import MPI

from dolfinx_forms.fem.boundary import Dirichlet, Traction
from dolfinx_forms.solvers import protocol
from dolfinx_forms.solvers.newton import ContactSolverError
from dolfinx_forms.solvers.options import options
from dolfinx_forms.solvers.problem import ContactProblem

E, NU, N = 1.0, 0.3, 3


@pytest.fixture(scope="module")
def scene():
    from meshes.cut import patch_cut_scene

    return patch_cut_scene(MPI.COMM_WORLD, n=N)


def patch_problem(scene, tractions=(), log=lambda *a, **k: None):
    def corner(y):
        return lambda x: np.isclose(x[0], 0.0) & np.isclose(x[1], y)

    top = Dirichlet("upper_top", 1, 0.0)
    bcs = [
        Dirichlet("lower_bottom", 1, 0.0),
        top,
        Dirichlet(corner(0.0), 0, 0.0),
        Dirichlet(corner(1.0), 0, 0.0),
    ]
    p = ContactProblem(
        scene,
        {b.tag: (E, NU) for b in scene.bodies},
        dirichlet=bcs,
        tractions=tractions,
        log=log,
        **options(eps0=1.0, band=0.5 / N),
    )
    return p, top


def penalised_reaction(problem, d):
    Ep = E / (1 - NU**2)
    return -Ep * d / (1.0 + Ep * problem.eps_n)  # force on the top, width 1


def test_ramp_is_linear_in_the_displacement(scene):
    lines = []
    problem, top = patch_problem(scene, log=lines.append)
    forces = []
    for target in (-0.0025, -0.005, -0.01):  # each ramp starts where the last one ended
        rec = protocol.ramp(problem, top, target, steps=2, label="press")
        assert rec.kind == "ramp" and rec.load_steps == 2 and rec.boundary == "upper_top"
        assert rec.values == {"upper_top.u_y": pytest.approx(target, abs=1e-15)}
        assert protocol.current_value(problem, top) == pytest.approx(target, abs=1e-15)
        forces.append(rec.force[1])
        assert rec.force[1] == pytest.approx(penalised_reaction(problem, -target), rel=1e-9)
        assert abs(rec.force[0]) <= 1e-12
    assert forces[1] == pytest.approx(2 * forces[0], rel=1e-9)
    assert forces[2] == pytest.approx(4 * forces[0], rel=1e-9)
    # one progress line per stage (besides the solver's line per load step), with the load
    stage_lines = [ln for ln in lines if ln.startswith("press:")]
    assert len(stage_lines) == 3 and "reaction on upper_top" in stage_lines[-1]
    # the other conditions were held at their values
    assert protocol.current_value(problem, problem.dirichlet[0]) == 0.0


def test_ramp_moves_tractions_and_holds_them(scene):
    """A traction's load factor is ramped like a Dirichlet value, then held by later stages."""
    from dolfinx import fem

    side = Traction("lower_right", fem.Constant(scene.mesh, np.array([-1e-3, 0.0])))
    problem, top = patch_problem(scene, tractions=[side])
    protocol.ramp(problem, [top, side], [-0.005, 1.0], steps=2)
    assert protocol.current_value(problem, side) == pytest.approx(1.0)
    u1 = problem.u.x.array.copy()
    protocol.ramp(problem, top, -0.005)  # nothing moves: the same state
    assert protocol.current_value(problem, side) == pytest.approx(1.0)
    assert np.allclose(problem.u.x.array, u1, atol=1e-14)
    protocol.ramp(problem, side, 0.0)  # the side load removed, the top held
    assert protocol.current_value(problem, top) == pytest.approx(-0.005)
    assert problem.reaction("upper_top")[1] == pytest.approx(
        penalised_reaction(problem, 0.005), rel=1e-9
    )


@pytest.mark.parametrize(
    "method,monotone", [("secant", False), ("secant", True), ("newton", False)]
)
def test_reach_force(scene, method, monotone):
    problem, top = patch_problem(scene)
    target, tol = -0.004, 1e-6
    # monotone: approach from below (a first guess short of the answer -0.00497)
    rec = protocol.reach_force(
        problem,
        top,
        "upper_top",
        1,
        target,
        first_guess=-0.002,
        tol=tol,
        monotone=monotone,
        method=method,
    )
    force = problem.reaction("upper_top")[1]
    assert rec.force[1] == pytest.approx(force, rel=1e-12)
    assert rec.kind == "force" and rec.target == target and rec.boundary == "upper_top"
    assert rec.method == method
    if method == "secant":
        assert abs(force - target) <= tol * abs(target)
        assert rec.secant_iterations <= 3  # linear: the secant is exact after the first step
    else:  # solved with the displacement: the target to Newton's tolerance, in one solve
        assert force == pytest.approx(target, rel=1e-9)
        assert rec.secant_iterations is None and rec.load_steps == 1
        assert rec.newton_iterations <= 4  # one to close the gap, then the linear answer
    d = protocol.current_value(problem, top)
    assert force == pytest.approx(penalised_reaction(problem, -d), rel=1e-9)


def test_reach_force_failures(scene):
    problem, top = patch_problem(scene)
    with pytest.raises(ContactSolverError, match="did not reach"):
        protocol.reach_force(
            problem, top, "upper_top", 1, -0.004, first_guess=-0.001, max_iter=1, method="secant"
        )
    # monotone loading refuses to go back
    with pytest.raises(ContactSolverError, match="reverse"):
        protocol.reach_force(
            problem,
            top,
            "upper_top",
            1,
            -0.0005,
            first_guess=-0.002,
            monotone=True,
            method="secant",
        )


def test_friction_on(scene):
    problem, top = patch_problem(scene)
    protocol.ramp(problem, top, -0.005)
    rec = protocol.friction_on(problem, 0.3)
    assert problem.mu == 0.3 and rec.kind == "friction" and rec.values == {"mu": 0.3}
    # uniform compression: friction adds no tangential traction, the ramp stays linear
    rec = protocol.ramp(problem, top, -0.01)
    assert rec.force[1] == pytest.approx(penalised_reaction(problem, 0.01), rel=1e-9)
    pts = problem.contact_points()
    assert max(np.abs(p["p_t"]).max() for p in pts) <= 1e-12
