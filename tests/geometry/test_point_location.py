"""Point location on DOLFINx meshes (CellLocator) against dolfinx.geometry and the P1 basis."""


import basix
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx
import dolfinx.geometry
from dolfinx.mesh import CellType, create_unit_square, locate_entities
from dolfinx_forms._cpp import CellLocator

CELL_TYPES = [CellType.triangle, CellType.quadrilateral]


def mesh_arrays(mesh):
    """x (nv, 3) and cells (nc, nverts) of the geometry, as a CellLocator takes them."""
    nverts = 3 if mesh.topology.cell_type == CellType.triangle else 4
    return mesh.geometry.x, mesh.geometry.dofmap.array.reshape(-1, nverts)


def dolfinx_colliding_cells(mesh, points):
    """For each (n, 2) point, the set of cells dolfinx.geometry finds containing it."""
    p3 = np.c_[points, np.zeros(len(points))]
    tree = dolfinx.geometry.BoundingBoxTree(mesh, mesh.topology.dim)
    candidates = dolfinx.geometry.compute_collisions(tree, p3)
    colliding = dolfinx.geometry.compute_colliding_cells(mesh, candidates, p3)
    return [set(colliding.links(i)) for i in range(len(points))]


def p1_basis(cell_type, X):
    """P1 basis functions at reference points X (n, 2), (n, nverts), via basix."""
    ct = basix.CellType.triangle if cell_type == CellType.triangle else basix.CellType.quadrilateral
    e = basix.create_element(basix.ElementFamily.P, ct, 1, basix.LagrangeVariant.equispaced)
    return e.tabulate(0, X)[0, :, :, 0]


def interpolate_at(mesh, u, cells, X):
    """Values of the P1 function u at the points (cells, X) through the basis functions."""
    phi = p1_basis(mesh.topology.cell_type, X)
    dofs = np.array([u.function_space.dofmap.cell_dofs(c) for c in cells])
    return np.sum(phi * u.x.array[dofs], axis=1)


def linear(x):
    return 1.0 + 2.0 * x[0] - 3.0 * x[1]


@pytest.mark.parametrize("cell_type", CELL_TYPES)
def test_matches_dolfinx_and_interpolates_linear(cell_type):
    mesh = create_unit_square(MPI.COMM_SELF, 8, 8, cell_type)
    x, cells = mesh_arrays(mesh)
    loc = CellLocator(x, cells, np.arange(len(cells), dtype=np.int32))
    assert loc.num_cells == len(cells) and loc.num_vertices == cells.shape[1]
    pts = np.random.default_rng(0).random((1000, 2))
    r = loc.locate(pts, 0.0)
    assert r["cells"].dtype == np.int32 and r["X"].shape == (1000, 2)
    assert np.all(r["outside"] == 0.0)
    expected = dolfinx_colliding_cells(mesh, pts)
    assert all(c in e for c, e in zip(r["cells"], expected))
    # X is DOLFINx's reference point: the coordinate map pulls the point back to it ...
    for i in range(0, 1000, 97):
        geom = x[cells[r["cells"][i]]]
        Xd = mesh.geometry.cmap.pull_back(np.array([[*pts[i], 0.0]]), geom)
        assert np.allclose(Xd[0, :2], r["X"][i], atol=1e-12)
    # ... and the P1 basis at X interpolates a linear function exactly
    V = dolfinx.fem.FunctionSpace(mesh, ("Lagrange", 1))
    u = dolfinx.fem.Function(V)
    u.interpolate(linear)
    vals = interpolate_at(mesh, u, r["cells"], r["X"])
    assert np.abs(vals - linear(pts.T)).max() < 1e-12


@pytest.mark.parametrize("cell_type", CELL_TYPES)
def test_points_slightly_outside(cell_type):
    """Boundary points pushed out of the mesh: nearest cell, exact distance, extrapolated X
    at which the P1 basis still reproduces linear functions."""
    mesh = create_unit_square(MPI.COMM_SELF, 8, 8, cell_type)
    x, cells = mesh_arrays(mesh)
    loc = CellLocator(x, cells)  # all cells
    rng = np.random.default_rng(1)
    t, d = rng.uniform(0.01, 0.99, 100), rng.uniform(1e-9, 1e-3, 100)
    pts = np.r_[np.c_[t, -d], np.c_[t, 1 + d], np.c_[-d, t], np.c_[1 + d, t]]
    dist = np.r_[d, d, d, d]
    r = loc.locate(pts, 2e-3)
    assert np.all(r["cells"] >= 0)
    assert np.allclose(r["outside"], dist, rtol=1e-10, atol=1e-15)
    # The located cell touches the boundary right next to the point
    edge = np.abs(x[cells[r["cells"]], :2] - np.clip(pts, 0, 1)[:, None, :]).max(axis=2).min(axis=1)
    assert edge.max() <= 1 / 8 + 1e-12
    V = dolfinx.fem.FunctionSpace(mesh, ("Lagrange", 1))
    u = dolfinx.fem.Function(V)
    u.interpolate(linear)
    vals = interpolate_at(mesh, u, r["cells"], r["X"])
    assert np.abs(vals - linear(pts.T)).max() < 1e-12
    # Beyond max_distance: not located
    far = loc.locate(np.array([[0.5, -0.01], [3.0, 3.0]]), 2e-3)
    assert list(far["cells"]) == [-1, -1]
    assert np.isnan(far["X"]).all() and np.isinf(far["outside"]).all()


@pytest.mark.parametrize("cell_type", CELL_TYPES)
def test_subset(cell_type):
    mesh = create_unit_square(MPI.COMM_SELF, 8, 8, cell_type)
    x, cells = mesh_arrays(mesh)
    left = locate_entities(mesh, 2, lambda p: p[0] <= 0.5 + 1e-12).astype(np.int32)
    loc = CellLocator(x, cells, left)
    assert loc.num_cells == len(left) < len(cells)
    pts = np.array([[0.25, 0.5], [0.75, 0.5], [0.6, 0.3]])
    r = loc.locate(pts, 0.3)
    assert np.all(np.isin(r["cells"], left))
    assert np.allclose(r["outside"], [0.0, 0.25, 0.1], atol=1e-14)
    assert list(loc.locate(pts, 0.2)["cells"] == -1) == [False, True, False]


def test_bad_shapes_raise_value_error():
    mesh = create_unit_square(MPI.COMM_SELF, 2, 2, CellType.triangle)
    x, cells = mesh_arrays(mesh)
    with pytest.raises(ValueError, match="x"):
        CellLocator(np.c_[x, x[:, :1]], cells)
    with pytest.raises(ValueError, match="cells"):
        CellLocator(x, np.c_[cells, cells[:, :2]])
    with pytest.raises(ValueError, match="cells"):
        CellLocator(x, cells.ravel())
    with pytest.raises(ValueError, match="subset"):
        CellLocator(x, cells, np.array([[0, 1]], dtype=np.int32))
    with pytest.raises(ValueError, match="subset"):
        CellLocator(x, cells, np.array([0, 99], dtype=np.int32))
    loc = CellLocator(x, cells)
    with pytest.raises(ValueError, match="points"):
        loc.locate(np.zeros((4, 3)), 0.0)
    with pytest.raises(ValueError, match="max_distance"):
        loc.locate(np.zeros((4, 2)), -1.0)


def test_grid_locator_matches_binned_location_on_a_cut_scene():
    """Cut scenes locate points by grid index (O(1)); same cells and reference coordinates as
    the binned C++ locator for points inside active cells, and the nearest active cell for
    points in inactive grid cells near the boundary."""
    from dolfinx_forms.geometry.pairs import BodyLocator, GridLocator
    from meshes.cut import hertz_cut_scene

    scene = hertz_cut_scene(MPI.COMM_SELF, R=10.0, width=20.0, depth=10.0, h=0.1, zone=1.0)
    rng = np.random.default_rng(3)
    for body in scene.bodies:
        grid = GridLocator(scene.mesh, scene.cell_tags, body.tag, scene.cut, 1)
        bins = BodyLocator(scene.mesh, scene.cell_tags, body.tag, "quadrilateral", 1)
        pts = rng.uniform([-2, -1], [2, 1.5], size=(4000, 2))
        c1, X1, out1 = grid.locate(pts, 0.05)
        c2, X2, out2 = bins.locate(pts, 0.05)
        inside = out2 == 0
        assert inside.sum() > 500
        np.testing.assert_array_equal(c1[inside], c2[inside])
        np.testing.assert_allclose(X1[inside], X2[inside], atol=1e-12)
        # points outside every cell but within reach: both find a cell at the same distance
        near = (out2 > 0) & (c2 >= 0)
        assert near.sum() > 10
        np.testing.assert_array_equal(c1 < 0, c2 < 0)
        np.testing.assert_allclose(out1[near], out2[near], atol=1e-12)
        np.testing.assert_allclose(grid.basis(X1[inside]), bins.basis(X2[inside]), atol=1e-12)
