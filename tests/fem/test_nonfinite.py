"""A non-finite Newton residual is reported with where it is (`ContactProblem.nonfinite`): the
part of the residual that first holds it, the body and a position, the same on every rank; a
Newton step into a non-finite residual is halved first. Also under mpirun -n 2."""

import re

import numpy as np
import pytest
from test_laws import E, NU, block_scene

from dolfinx_forms.fem.boundary import Dirichlet
from dolfinx_forms.fem.laws import LinearElastic, NeoHookean
from dolfinx_forms.solvers.newton import newton
from dolfinx_forms.solvers.problem import ContactProblem


def _problem(law, push=0.0):
    bcs = [Dirichlet("bottom", None, 0.0), Dirichlet("punch", 1, lambda lam: -lam * push)]
    return ContactProblem(block_scene(4), {1: law}, dirichlet=bcs, log=lambda *a: None)


def _owned_blocks(p):
    n = p.V.dofmap.index_map.size_local
    return p.V.tabulate_dof_coordinates()[:n, :2]


def test_nonfinite_residual_says_where():
    # a NaN in the iterate at the node (0, 0.5): the displacement, on the block, at that node
    p = _problem(LinearElastic(E, NU))
    x = _owned_blocks(p)
    at = np.flatnonzero(np.hypot(x[:, 0], x[:, 1] - 0.5) < 1e-9)
    p.u.x.array[2 * at] = np.nan
    ok, _, why = newton(p, 1.0)
    assert not ok and why.startswith("non-finite residual at iteration 0 (the displacement")
    assert "not finite at 1 dof(s), on body 'block'" in why
    at = re.search(r"one at x = \(([^,]+), ([^)]+)\)", why)
    assert np.allclose([float(at[1]), float(at[2])], [0.0, 0.5], rtol=0, atol=1e-12)
    p.destroy()

    # F = diag(-1, 1) everywhere (u_x = -2 x): det F < 0, the neo-Hookean's ln det F is NaN
    p = _problem(NeoHookean(E, NU))
    x = _owned_blocks(p)
    p.u.x.array[: 2 * len(x)].reshape(-1, 2)[:, 0] = -2.0 * x[:, 0]
    p.u.x.scatter_forward()
    ok, _, why = newton(p, 1.0)
    assert not ok and "the nonlinear bulk forces (finite strain: det F <= 0" in why
    assert "on body 'block'" in why
    p.destroy()

    # every part finite: nothing to report
    p = _problem(LinearElastic(E, NU))
    assert p.nonfinite() == ""
    p.destroy()


def test_a_step_into_a_nonfinite_residual_is_halved():
    """The residual after the first Newton step reads NaN once (as past a det F = 0): the step
    is halved, Newton goes on from there and reaches the solution of the undisturbed solve."""
    ref = _problem(LinearElastic(E, NU), push=0.01)
    ok, res_ref, _ = newton(ref, 1.0)
    assert ok
    p = _problem(LinearElastic(E, NU), push=0.01)
    residual, calls = p.residual, []

    def once_nan(lam, **kw):
        r = residual(lam, **kw)
        calls.append(r)
        return np.nan if len(calls) == 2 else r

    p.residual = once_nan
    ok, res, why = newton(p, 1.0)
    assert ok, why
    assert np.all(np.isfinite(res)) and len(res) == len(res_ref) + 1  # the halved step's
    assert np.isclose(res[1], 0.5 * res[0], rtol=1e-6)  # linear: half the step, half of R
    scale = np.abs(ref.u.x.array).max()
    assert np.allclose(p.u.x.array, ref.u.x.array, rtol=0, atol=1e-10 * scale)
    for q in (p, ref):
        q.destroy()


@pytest.mark.mpi
def test_nonfinite_residual_says_where_on_two_ranks():
    test_nonfinite_residual_says_where()
    test_a_step_into_a_nonfinite_residual_is_halved()
