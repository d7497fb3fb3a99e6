"""Nonlinear UFL laws in parallel: a neo-Hookean (or orthotropic) block, body-fitted and cut
along its bottom, under a flat punch gives the same reaction and Newton history on 2 ranks as
on 1 (each rank also solves the problem on COMM_SELF), to 1e-8 relative. The scenes are those
of test_laws.py."""

import numpy as np
import pytest
from mpi4py import MPI
from test_laws import E, H, NU, block_scene, cut_block_scene

from dolfinx_forms.fem.boundary import Dirichlet
from dolfinx_forms.fem.laws import NeoHookean, OrthotropicElastic
from dolfinx_forms.solvers.newton import NewtonOptions
from dolfinx_forms.solvers.options import options
from dolfinx_forms.solvers.problem import ContactProblem

SCENES = {  # name -> (scene on a communicator, the clamped boundary)
    "fitted": (lambda comm: block_scene(8, comm=comm), "bottom"),
    "cut": (lambda comm: cut_block_scene(comm, h=1 / 8), "sides"),
}


def solve(scene, clamped, law):
    bcs = [
        Dirichlet(clamped, None, 0.0),
        Dirichlet("punch", 0, 0.0),
        Dirichlet("punch", 1, lambda lam: -0.1 * H * lam),
    ]
    p = ContactProblem(
        scene,
        {1: law},
        dirichlet=bcs,
        log=lambda *a: None,
        **options(newton=NewtonOptions(rtol=1e-11)),
    )
    p.solve(1)
    return p.reaction("punch"), p.steps[-1].iterations, p.num_dofs


@pytest.mark.mpi
@pytest.mark.parametrize("kind", sorted(SCENES))
@pytest.mark.parametrize(
    "law", [NeoHookean(E, NU), OrthotropicElastic(2 * E, E, E, 0.25, 0.3, 0.3, 0.4 * E, 17.0)]
)
def test_two_ranks_match_one(kind, law):
    assert MPI.COMM_WORLD.size == 2, "run under mpirun -n 2"
    build, clamped = SCENES[kind]
    r2, it2, n2 = solve(build(MPI.COMM_WORLD), clamped, law)
    r1, it1, n1 = solve(build(MPI.COMM_SELF), clamped, law)
    assert n1 == n2 and it1 == it2
    assert abs(r1[1]) > 1.0
    np.testing.assert_allclose(r2, r1, rtol=1e-8, atol=1e-8 * abs(r1[1]))
