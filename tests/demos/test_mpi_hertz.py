"""Hertz contact on 2 MPI ranks gives the reaction of 1 rank (run under mpirun -n 2),
body-fitted (gmsh or layers) and cut (cut cells, ghost-penalty facets across the partition
boundary).

The scene partitioner puts every cell of the contact search box on rank 0, so the contact
points and both bodies' cells around them are local there; the other rank only assembles
bulk elasticity. The reaction of the distributed problem must equal the serial one (each rank
also solves the same problem on COMM_SELF) to 1e-8 relative, with the penalty and with the
augmented Lagrangian (its loop's tests and Anderson's inner products reduced over the ranks),
with its lumped, consistent and hybrid (the default) projections.
"""

import numpy as np
import pytest
from mpi4py import MPI

from dolfinx_forms.fem.boundary import Dirichlet
from dolfinx_forms.solvers.options import options
from dolfinx_forms.solvers.problem import ContactProblem
from meshes.cut import hertz_cut_scene
from meshes.hertz import hertz_scene


def reaction(comm, mu, disc="conforming", enforcement="penalty", band=0.13, box=None, **size):
    """box: the band the scene's contact box covers (None: the scene's default)."""
    # "augmented/consistent": its mass ("augmented": the lumped one, "augmented/hybrid" the default)
    enforcement, _, mass = enforcement.partition("/")
    make = hertz_cut_scene if disc == "cut" else hertz_scene
    if disc == "layers":  # body-fitted, meshed by meshes/layers.py
        size["mesher"] = "layers"
    size = {**dict(R=10.0, width=20.0, depth=10.0, h=0.1, zone=1.6), **size}
    scene = make(comm, **size, band=box)
    mat = {b.tag: (1e4, 0.3) for b in scene.bodies}
    top_x = Dirichlet("cylinder_top", 0, 0.0)
    top_y = Dirichlet("cylinder_top", 1, lambda lam: -0.15 * lam)
    p = ContactProblem(
        scene,
        mat,
        dirichlet=[Dirichlet("block_bottom", None, 0.0), top_x, top_y],
        log=lambda *a: None,
        **options(
            mu=0.0, eps0=0.5, band=band, enforcement=enforcement, multiplier_mass=mass or "lumped"
        ),
    )
    p.solve(2)
    if mu > 0:  # a frictional tangential step: history and stick/slip in parallel too
        p.set_friction(mu)
        top_y.value = -0.15
        top_x.value = lambda lam: 0.01 * lam
        p.lam = 0.0
        p.solve(2)
    reaction.owned = p.n_owned / p.num_dofs
    return p.reaction("block_bottom"), p.num_dofs


@pytest.mark.mpi
@pytest.mark.parametrize(
    "mu,disc,enforcement",
    [
        (0.0, "conforming", "penalty"),
        (0.3, "conforming", "penalty"),
        (0.0, "cut", "penalty"),
        (0.3, "cut", "penalty"),
        (0.3, "conforming", "augmented"),
        (0.0, "cut", "augmented"),
        (0.3, "cut", "augmented/consistent"),  # Uzawa's L2 projection, unclipped
        (0.3, "conforming", "augmented/hybrid"),  # consistent rows in contact, lumped at the edge
        (0.0, "cut", "augmented/hybrid"),
        (0.3, "layers", "penalty"),
    ],
)
def test_two_ranks_match_one(mu, disc, enforcement):
    world = MPI.COMM_WORLD
    assert world.size == 2, "run under mpirun -n 2"
    r2, n2 = reaction(world, mu, disc, enforcement)
    r1, n1 = reaction(MPI.COMM_SELF, mu, disc, enforcement)
    assert n1 == n2
    assert abs(r2[1]) > 100
    np.testing.assert_allclose(r2, r1, rtol=1e-8, atol=1e-8 * abs(r1[1]))


@pytest.mark.mpi
@pytest.mark.parametrize("disc", ["conforming", "cut"])
def test_wide_band_on_rank0_and_the_rest_shared(disc):
    """The scene's contact box is the strip of Gamma_c for the problem's band
    (meshes.hertz.hertz_contact_box): a band reaching past the fine zone (|x| < 3.1 against
    1.8) keeps its cells on rank 0 (a fixed box failed: "closest point ... is not within ... of
    any of its cells on this rank"), and the fine zone around the strip is shared (a square
    around it gave rank 0 91 % of the dofs at a/20)."""
    world = MPI.COMM_WORLD
    assert world.size == 2, "run under mpirun -n 2"
    size = dict(h=0.05, zone=1.2, band=0.5, box=0.5)  # the demo's h and zone (a = 1)
    r2, n2 = reaction(world, 0.0, disc, **size)
    share = world.allgather(reaction.owned)
    r1, n1 = reaction(MPI.COMM_SELF, 0.0, disc, **size)
    assert n1 == n2
    np.testing.assert_allclose(r2, r1, rtol=1e-8, atol=1e-8 * abs(r1[1]))
    assert max(share) < 0.65, share
