"""A user scene built without a contact box works on 2 ranks (run under mpirun -n 2): the box
is derived from the contact pairs (dolfinx_forms.mesh.scene.pairs_contact_boxes), its cells are
owned by rank 0 where the contact geometry is computed, and the patch test gives the reaction of one
rank and the penalised exact pressure. DOLFINx's own partitioner (contact_box=False) would
put cells of that box on rank 1: the case that used to raise on rank 0 and hang rank 1."""

import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_forms as df
from dolfinx_forms.mesh.cut_scene import CutBody, cut_scene, half_plane
from dolfinx_forms.solvers.options import options
from dolfinx_forms.solvers.problem import ContactProblem
from meshes.patch import patch_dirichlet
from dolfinx_forms.mesh.scene import (
    Body,
    add_polygon,
    cell_bboxes,
    gmsh_model,
    on_box_side,
    pairs_contact_boxes,
    scene_from_gmsh,
)

pytestmark = pytest.mark.mpi
E, NU, D = 1.0, 0.3, 0.01
N = 24  # cells over the height: the derived box (+-4 h) is a strip, not the whole square


def _markers(boxes, tol=1e-9):
    return {
        "lower_bottom": (1, on_box_side(*boxes[0], ["bottom"], tol), 0),
        "upper_top": (2, on_box_side(*boxes[1], ["top"], tol), 1),
    }


def cut_user_scene(comm, contact_box=None):
    """Two blocks cut at y = 0.5 + 0.3 h on a uniform grid, built with cut_scene directly."""
    h = 1.0 / N
    y = 0.5 + 0.3 * h
    lines = np.linspace(0.0, 1.0, N + 1)
    k = int(np.floor(y / h))
    windows = [np.array([[0.0, 0.0], [1.0, lines[k + 1]]]), np.array([[0.0, lines[k]], [1.0, 1.0]])]
    bodies = [
        CutBody(
            "lower",
            1,
            windows[0],
            half_plane((0, y), (0, 1), 100.0),
            np.array([[0.0, 0.0], [1.0, y]]),
        ),
        CutBody(
            "upper",
            2,
            windows[1],
            half_plane((0, y), (0, -1), 100.0),
            np.array([[0.0, y], [1.0, 1.0]]),
        ),
    ]
    return cut_scene(
        comm, lines, lines, bodies, _markers(windows), [(0, 1)], h, contact_box=contact_box
    )


def gmsh_user_scene(comm, contact_box=None):
    """Two stacked structured blocks meeting at y = 0.5, built with scene_from_gmsh directly."""
    boxes = [np.array([[0.0, 0.0], [1.0, 0.5]]), np.array([[0.0, 0.5], [1.0, 1.0]])]
    bodies = [
        Body(n, i + 1, df.Box(*b), b) for i, (n, b) in enumerate(zip(("lower", "upper"), boxes))
    ]
    with gmsh_model(comm, "user") as gmsh:
        if comm.rank == 0:
            for lo, hi in boxes:
                add_polygon(
                    gmsh, [lo, (hi[0], lo[1]), hi, (lo[0], hi[1])], n=(N, N // 2), quads=True
                )
            gmsh.model.geo.synchronize()
            gmsh.model.mesh.generate(2)
        return scene_from_gmsh(
            comm, bodies, _markers(boxes), [(0, 1)], 1.0 / N, contact_box=contact_box
        )


BUILDERS = {"cut": cut_user_scene, "gmsh": gmsh_user_scene}


def owned_in_boxes(scene):
    """Number of this rank's owned cells whose vertex bbox meets a derived contact box."""
    mesh = scene.mesh
    nloc = mesh.topology.index_map(2).size_local
    cells = mesh.geometry.dofmap.array.reshape(-1, 4)[:nloc]
    lo, hi = cell_bboxes(mesh.geometry.x, cells)
    boxes = pairs_contact_boxes(scene.bodies, scene.pairs, scene.h_contact)
    assert len(boxes) == 1
    hit = np.zeros(nloc, bool)
    for b in boxes:
        hit |= np.all((lo <= b[1]) & (hi >= b[0]), axis=1)
    return int(hit.sum()), nloc


def solve(scene):
    p = ContactProblem(
        scene,
        {b.tag: (E, NU) for b in scene.bodies},
        dirichlet=patch_dirichlet(D),
        log=lambda *a, **k: None,
        **options(mu=0.0, eps0=1.0, band=0.5 / N),
    )
    p.solve(1)
    pts = p.contact_points()
    pn = np.concatenate([q["p_n"] for q in pts]) if pts else np.zeros(0)
    return np.asarray(p.reaction("upper_top")), pn, p.eps_n


@pytest.mark.parametrize("kind", ["cut", "gmsh"])
def test_user_scene_without_box_on_two_ranks(kind):
    comm = MPI.COMM_WORLD
    assert comm.size == 2, "run under mpirun -n 2"
    build = BUILDERS[kind]
    # DOLFINx's partitioner splits the contact strip: the failure case without a box
    hits, _ = owned_in_boxes(build(comm, contact_box=False))
    assert comm.bcast(hits, root=1) > 0
    scene = build(comm)  # no contact_box: derived from the pairs
    hits, nloc = owned_in_boxes(scene)
    if comm.rank == 1:
        assert hits == 0 and nloc > 0
    r2, pn, eps_n = solve(scene)
    r1, _, _ = solve(build(MPI.COMM_SELF))
    np.testing.assert_allclose(r2, r1, rtol=1e-8, atol=1e-10)
    Ep = E / (1 - NU**2)
    penalised = Ep * D / (1.0 + Ep * eps_n)
    if comm.rank == 0:  # contact points live on rank 0
        assert len(pn) > 0
        np.testing.assert_allclose(pn, -penalised if pn.mean() < 0 else penalised, rtol=1e-8)
    assert abs(r2[1]) == pytest.approx(penalised, rel=1e-8)
