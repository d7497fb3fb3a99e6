"""Nonlinear UFL laws in parallel: a neo-Hookean block (body-fitted, and cut along its bottom)
under a flat punch gives the same reaction and Newton history on 2 ranks as on 1 (each rank
also solves the problem on COMM_SELF), to 1e-8 relative."""

import numpy as np
import pytest
from dolfinx import mesh as dmesh
from mpi4py import MPI

from dolfinx_forms import Box, scene_spec
from dolfinx_forms.laws import NeoHookean, OrthotropicElastic
from dolfinx_forms.solver import ContactProblem, Dirichlet, NewtonOptions
from meshes.from_spec import build_scene
from meshes.scene import Body, Scene, tag_boundaries

E, NU, W, H, A = 1000.0, 0.3, 2.0, 1.0, 0.25


def fitted(comm):
    m = dmesh.create_rectangle(comm, [[-W / 2, 0], [W / 2, H]], [16, 8], dmesh.CellType.triangle)
    n = m.topology.index_map(2).size_local + m.topology.index_map(2).num_ghosts
    values = np.ones(n, np.int32)
    body = Body("block", 1, Box([-W / 2, 0], [W / 2, H]), np.array([[-W / 2, 0], [W / 2, H]]))
    markers = {
        "sides": (1, lambda x: np.isclose(np.abs(x[0]), W / 2)),
        "punch": (2, lambda x: np.isclose(x[1], H) & (np.abs(x[0]) <= A + 1e-9)),
    }
    facet_tags, boundaries = tag_boundaries(m, values, [body], markers)
    cells = dmesh.meshtags(m, 2, np.arange(n, dtype=np.int32), values)
    return Scene(m, cells, facet_tags, boundaries, [body], [], H / 8, "triangle")


def cut(comm):
    spec = scene_spec.load(
        {
            "name": "cut_punch",
            "discretization": {"kind": "cut", "h": 1 / 8, "extent": [[-W / 2, 0.0], [W / 2, H]]},
            "bodies": [
                {
                    "name": "block",
                    "window": [[-W / 2, 0.0], [W / 2, H]],
                    "shape": {"type": "half_plane", "point": [0.0, 0.1], "normal": [0.1, -1.0]},
                    "law": {"type": "linear", "E": E, "nu": NU},
                }
            ],
            "boundaries": [
                {"name": "sides", "body": "block", "side": ["left", "right"]},
                {
                    "name": "punch",
                    "box": {"x_min": -A, "x_max": A, "y_min": H - 1e-9, "y_max": H + 1e-9},
                },
            ],
        }
    )
    return build_scene(comm, spec)


def solve(scene, law):
    bcs = [
        Dirichlet("sides", None, 0.0),
        Dirichlet("punch", 0, 0.0),
        Dirichlet("punch", 1, lambda lam: -0.1 * H * lam),
    ]
    p = ContactProblem(
        scene, {1: law}, dirichlet=bcs, newton=NewtonOptions(rtol=1e-11), log=lambda *a: None
    )
    p.solve(1)
    return p.reaction("punch"), p.steps[-1].iterations, p.num_dofs


@pytest.mark.mpi
@pytest.mark.parametrize("build", [fitted, cut])
@pytest.mark.parametrize(
    "law", [NeoHookean(E, NU), OrthotropicElastic(2 * E, E, E, 0.25, 0.3, 0.3, 0.4 * E, 0.3)]
)
def test_two_ranks_match_one(build, law):
    assert MPI.COMM_WORLD.size == 2, "run under mpirun -n 2"
    r2, it2, n2 = solve(build(MPI.COMM_WORLD), law)
    r1, it1, n1 = solve(build(MPI.COMM_SELF), law)
    assert n1 == n2 and it1 == it2
    assert abs(r1[1]) > 1.0
    np.testing.assert_allclose(r2, r1, rtol=1e-8, atol=1e-8 * abs(r1[1]))
