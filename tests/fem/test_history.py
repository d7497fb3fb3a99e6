"""Finite strain with history on the single-step paths (fem/history.py HistoryLaw, total
Lagrangian, F_n and the history at the quadrature points): the patch-test blocks compressed by
20 % in 10 load steps through their frictionless contact (augmented Lagrangian: the constraint
exact) are homogeneous, so the top reaction equals the homogeneous block's force
(analytic.block_j2, block_drucker_prager: independent principal-space return mappings;
block_neo_hookean) to the
Uzawa tolerance, and every quadrature point carries the reference's plastic strain."""

import numpy as np
import pytest
from mpi4py import MPI

from dolfinx_forms.analysis import analytic
from dolfinx_forms.fem.history import HistoryLaw
from dolfinx_forms.fem.laws import NeoHookean
from dolfinx_forms.fem.plasticity import DruckerPrager, J2Plasticity
from dolfinx_forms.solvers.options import options
from dolfinx_forms.solvers.problem import ContactProblem
from meshes.patch import patch_dirichlet, patch_scene

E, NU, TOTAL, STEPS = 1000.0, 0.3, 0.2, 10
DP = (5.0, 30.0, 10.0, 50.0)  # cohesion, friction and dilatancy angles (degrees), hardening


@pytest.mark.parametrize("quads", [True, False], ids=["quads", "triangles"])
@pytest.mark.parametrize("name", ["j2", "drucker-prager", "neo-hookean"])
def test_homogeneous_compression_matches_the_reference(name, quads):
    scene = patch_scene(MPI.COMM_WORLD, 4, 2, quads)
    base = {"j2": J2Plasticity(E, NU, 50.0, 100.0), "drucker-prager": DruckerPrager(E, NU, *DP),
            "neo-hookean": NeoHookean(E, NU)}[name]  # fmt: skip
    law = HistoryLaw(base, scene.mesh)  # one law, one history, for both blocks
    kw = options(mu=0.0, enforcement="augmented", band=0.25, pair_grid_origin=(0.0, 0.0))
    problem = ContactProblem(scene, {1: law, 2: law}, dirichlet=patch_dirichlet(TOTAL),
                             log=lambda *a, **k: None, **kw)  # fmt: skip
    ly = 1 - TOTAL * np.arange(1, STEPS + 1) / STEPS
    if name == "j2":
        force, lx, alpha = analytic.block_j2(ly, 1.0, E, NU, 50.0, 100.0)
        assert alpha[2] > 0  # the path yields
    elif name == "drucker-prager":
        force, lx, alpha = analytic.block_drucker_prager(ly, 1.0, E, NU, *DP)
        assert alpha[1] > 0
    else:
        force, lx = analytic.block_neo_hookean(ly, 1.0, base.mu, base.lmbda)
    for k in range(STEPS):
        problem.solve(1, (k + 1) / STEPS)
        law.commit(problem.u)
        assert -problem.reaction("upper_top")[1] == pytest.approx(force[k], rel=1e-6)
    F = law.Fn.x.array.reshape(-1, 4)
    assert np.allclose(F[:, 3], ly[-1], rtol=0, atol=1e-7)  # F_yy everywhere
    assert np.allclose(F[:, 0], lx[-1], rtol=0, atol=1e-7)
    if name != "neo-hookean":
        assert np.allclose(law.history.x.array.reshape(-1, 5)[:, 4], alpha[-1], rtol=1e-6)


@pytest.mark.mpi
def test_homogeneous_compression_on_two_ranks():
    """The same on 2 ranks (each rank commits the history of its own and ghost cells)."""
    assert MPI.COMM_WORLD.size == 2, "run under mpirun -n 2"
    test_homogeneous_compression_matches_the_reference("j2", True)
