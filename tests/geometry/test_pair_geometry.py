"""The solver's pair geometry calls one function per equation: eq 25 through `closest_points`
(exact on an analytic shape, the grid iteration for a body given by a level set), eq 28
through `_cpp.compute_gaps`, and the marching squares of the cut cells (`_cpp.cell_contours`)
for the bounding boxes of cut bodies."""

import dataclasses

import numpy as np
import pytest
from dolfinx import fem
from mpi4py import MPI

import dolfinx_forms as df
from dolfinx_forms import _cpp
from dolfinx_forms.geometry.pairs import (
    body_levelset,
    closest_points,
    has_exact_shape,
    pair_geometry,
)

R = 10.0


@pytest.fixture(scope="module")
def hertz():
    from meshes.cut import hertz_cut_scene

    scene = hertz_cut_scene(MPI.COMM_SELF, R=R, width=20.0, depth=10.0, h=0.1, zone=1.0)
    V = fem.VectorFunctionSpace(scene.mesh, ("Q", 1))
    return scene, V


def on_circle(p):
    return np.abs(np.linalg.norm(p - [0.0, R], axis=1) - R)


def test_exact_shapes_project_exactly_and_g_n0_is_eq_28(hertz):
    scene, V = hertz
    g = pair_geometry(V, scene, (0, 1), 0.2)
    assert all(has_exact_shape(b) for b in scene.bodies)
    assert on_circle(g.p_j).max() < 1e-10  # exact projection onto the cylinder (to rtol h)
    np.testing.assert_allclose(g.p_i[:, 1], 0.0, atol=1e-10)  # and onto the block's top
    np.testing.assert_allclose(
        g.g_n0, np.einsum("ij,ij->i", g.p_j - g.p_i, g.normals), rtol=0, atol=1e-15
    )
    # eq 25 on the grid level sets: the same points to the interpolation error
    gl = pair_geometry(V, scene, (0, 1), 0.2, projection="levelset")
    np.testing.assert_array_equal(gl.points, g.points)
    assert np.abs(gl.p_j - g.p_j).max() < 1e-6
    with pytest.raises(ValueError, match="projection"):
        pair_geometry(V, scene, (0, 1), 0.2, projection="shape")


def test_body_without_exact_shape_uses_eq_25_on_its_level_set(hertz):
    scene, V = hertz
    cyl = scene.bodies[1]
    grid = df.StructuredGrid.uniform([-10.6, -0.6], [10.6, 0.6], [1060, 60])
    phi = df.levelset_from_shape(grid, cyl.shape)  # the cylinder known only on a grid
    grid_body = dataclasses.replace(cyl, shape=phi)
    assert not has_exact_shape(grid_body)
    # the dispatch: exact shape -> shape projection, level set -> eq 25 on the level set
    pts = np.array([[0.1, 0.05], [-0.3, 0.02], [0.5, 0.1]])
    pair_grid = df.StructuredGrid.uniform([-1.0, -0.5], [1.0, 0.5], [80, 40])
    phi_pair = body_levelset(pair_grid, grid_body)
    for got, want in (
        (
            closest_points(cyl, phi_pair, pts, 0.1),
            _cpp.closest_point_projection(cyl.shape, pts, 0.1),
        ),
        (
            closest_points(grid_body, phi_pair, pts, 0.1),
            _cpp.closest_point_projection(phi_pair, pts),
        ),
    ):
        np.testing.assert_array_equal(got["points"], want["points"])
    # end to end through pair_geometry
    scene2 = dataclasses.replace(scene, bodies=[scene.bodies[0], grid_body])
    g = pair_geometry(V, scene2, (0, 1), 0.2)
    assert len(g.weights) > 10
    assert on_circle(g.p_j).max() < 1e-6  # eq 25 on the interpolant, not exact
    exact = pair_geometry(V, scene, (0, 1), 0.2)
    np.testing.assert_allclose(
        g.g_n0, np.einsum("ij,ij->i", g.p_j - g.p_i, g.normals), rtol=0, atol=1e-15
    )
    order = np.argsort(exact.points[:, 0])
    g0 = np.interp(g.points[:, 0], exact.points[order, 0], exact.g_n0[order])
    assert np.abs(g.g_n0 - g0).max() < 1e-5
    # a level set that does not cover the search box is named
    short = dataclasses.replace(
        cyl,
        shape=df.levelset_from_shape(
            df.StructuredGrid.uniform([-1.0, -0.6], [1.0, 0.6], [100, 60]), cyl.shape
        ),
    )
    with pytest.raises(ValueError, match="does not cover"):
        pair_geometry(V, dataclasses.replace(scene, bodies=[scene.bodies[0], short]), (0, 1), 0.2)


def test_cell_contours_binding():
    phi = np.array(
        [
            [-0.3, 0.7, -0.1, 0.9],  # one segment, bottom to top
            [0.25, -0.25, -0.25, 0.25],  # saddle, centre 0 (outside): v1, v2 cut off
            [1.0, 2.0, 3.0, 4.0],
        ]
    )  # outside
    c = _cpp.cell_contours(phi)
    np.testing.assert_array_equal(c["num_segments"], [1, 2, 0])
    np.testing.assert_allclose(c["t"][0], [0.3, np.nan, 0.1, np.nan])
    np.testing.assert_array_equal(c["segments"][0], [[0, 2], [-1, -1]])
    np.testing.assert_array_equal(c["segments"][1], [[0, 1], [3, 2]])
    assert np.isnan(c["t"][2]).all()
    np.testing.assert_array_equal(c["edges"], [[0, 1], [1, 3], [2, 3], [0, 2]])


def test_near_box_leaves_the_contact_unchanged(hertz, monkeypatch):
    """The fine pair grid on the part of the search box where both bodies come within the band
    (contact.near_box: |x| < ~2 a instead of the 20 R wide overlap) gives the same Gamma_c
    (same lattice: weights and normals to round-off) and the same closest points to the
    projection's tolerance (1e-8 relative: its start differs)."""
    from dolfinx_forms.geometry import pairs as contact

    scene, V = hertz
    band = 0.2
    fast = pair_geometry(V, scene, (0, 1), band)
    calls = []
    monkeypatch.setattr(contact, "near_box", lambda box, *a: calls.append(box) or box)
    full = pair_geometry(V, scene, (0, 1), band)
    assert calls, "near_box not called for exact shapes"
    whole = calls[0]
    assert len(fast.weights) == len(full.weights)
    for k in ("weights", "normals"):
        np.testing.assert_allclose(getattr(fast, k), getattr(full, k), rtol=0, atol=1e-12)
    for k in ("p_i", "p_j", "g_n0"):
        np.testing.assert_allclose(getattr(fast, k), getattr(full, k), rtol=0, atol=1e-6 * 0.1)
    # the contact lies well inside the kept part, which is a fraction of the whole width
    x = fast.p_i[:, 0]
    assert np.ptp(x) < 0.5 * (whole[1, 0] - whole[0, 0])


def test_split_segments_and_label_breaks():
    """Pieces split where a label of their points changes (a k-ary search), never into pieces
    shorter than tol, and the ends of the multiplier elements along a chain."""
    from dolfinx_forms.geometry.pairs import label_breaks, multiplier_breaks, split_segments

    pieces = np.array([[[0.0, 0.0], [1.0, 0.0]], [[2.0, 0.0], [1.0, 0.0]]])  # one chain, 2 pieces
    cells = np.array([7, 8], np.int32)

    def labels(x):  # cells of a mesh with edges at x = 0.3, 0.7, 1.6
        return np.searchsorted([0.3, 0.7, 1.6], x[:, 0])[:, None]

    segs = pieces
    for _ in range(4):
        k, t = label_breaks(segs, labels, 1e-10)
        if len(k) == 0:
            break
        segs, cells = split_segments(segs, cells, k, t, 1e-10)
    ends = np.sort(np.unique(np.round(segs[..., 0].ravel(), 12)))
    assert np.allclose(ends, [0.0, 0.3, 0.7, 1.0, 1.6, 2.0], atol=1e-12)
    assert set(cells.tolist()) == {7, 8}
    # the first change of a piece, in one round, whatever the search's branching (a change
    # back to the first label inside a bracket hides nothing: the first point past it is read)
    for branching in (2, 8, 16):
        k, t = label_breaks(pieces[:1], labels, 1e-10, branching=branching)
        assert list(k) == [0] and abs(t[0] - 0.3) < 1e-10, (branching, t)
    # every piece has one label along it
    mid = 0.5 * (segs[:, 0] + segs[:, 1])
    assert np.array_equal(labels(segs[:, 0] * 0.999 + mid * 0.001), labels(mid))
    # multiplier elements of length 0.5 on the chain of length 2: ends at 0.5, 1.0, 1.5 of the
    # arc from the chain's start (x = 0 or 2); the piece [2, 1] is read from its first end
    k, t = multiplier_breaks(pieces, 0.5, 1e-10)
    x = pieces[k, 0, 0] + t * (pieces[k, 1, 0] - pieces[k, 0, 0])
    assert np.allclose(np.sort(x), [0.5, 1.5])  # 1.0 is a piece end already
    # cuts closer than tol to an end or to each other are skipped
    s2, _ = split_segments(
        pieces[:1], cells[:1], np.array([0, 0, 0]), np.array([1e-12, 0.5, 0.5 + 1e-13]), 1e-10
    )
    assert len(s2) == 2


def test_beyond_end_flags_points_past_a_corner_only():
    """Gamma_c along y = 0, a body ending at x = 0 (its corner): past the corner the offset to
    the closest point runs along Gamma_c; inside the face's shadow it is across (a gap), also
    tilted by a curved partner's normal (up to 45 degrees)."""
    from dolfinx_forms.geometry.pairs import beyond_end

    n = np.tile([0.0, 1.0], (5, 1))
    pts = np.array([[-0.3, 0.0], [-1e-9, 0.0], [0.2, 0.0], [0.5, 0.01], [0.7, 0.0]])
    closest = np.array([[0.0, 0.0], [0.0, 0.0], [0.2, -0.05], [0.49, 0.0], [0.7, 0.0]])
    assert beyond_end(pts, closest, n, 1e-12).tolist() == [True, True, False, False, False]


def test_point_wise_traction_keeps_the_points_as_law_points(hertz):
    """traction="points": the same points and multiplier nodes as "nodes", but the law acts at
    the points (the kernel gets no nodes); `project` is the hats' weighted mean (the lumped L2
    projection): exact for constants, and for linear data at nodes whose hat lies wholly on
    one chain of equal elements; `interpolate` is the P1 interpolant."""
    scene, V = hertz
    gn = pair_geometry(V, scene, (0, 1), 0.2, multipliers="P1", traction="nodes")
    gp = pair_geometry(V, scene, (0, 1), 0.2, multipliers="P1", traction="points")
    np.testing.assert_array_equal(gp.points, gn.points)
    np.testing.assert_array_equal(gp.mult_nodes, gn.mult_nodes)
    assert gn.law_at_nodes and not gp.law_at_nodes and gp.law_at_points_with_nodes
    assert gn.num_law_points == gn.num_nodes < len(gn.weights) == gp.num_law_points
    assert gp.quadrature.num_law_points == len(gp.weights)  # the kernel's law points
    x = gp.points[:, 0]
    one, W = gp.project(np.ones_like(x))
    np.testing.assert_allclose(one, 1.0, rtol=1e-13)
    np.testing.assert_allclose(W.sum(), gp.weights.sum(), rtol=1e-13)
    node_x, _ = gp.project(x)
    lin = gp.interpolate(node_x)
    inner = (x > x.min() + 0.3) & (x < x.max() - 0.3)  # away from the chain's end elements
    # x is linear in Gamma_c's arc length to ~1e-5 here (it curves as x^2 / 4R)
    np.testing.assert_allclose(lin[inner], x[inner], atol=1e-4)
    assert np.abs(gp.interpolate(gp.project(x * x)[0]) - x * x)[inner].max() > 1e-4
    np.testing.assert_array_equal(gp.to_points(x), x)
    with pytest.raises(ValueError, match="traction"):
        pair_geometry(V, scene, (0, 1), 0.2, multipliers="P1", traction="both")


def test_mass_solver_dense_and_sparse(monkeypatch):
    """contact.mass_solver: numpy's dense inverse (small pairs: no scipy import) and scipy's
    sparse LU (above DENSE_MASS_NODES) solve the same hat mass matrix, repeated entries summed
    and a diagonal added (the hybrid projection's lumped rows)."""
    from dolfinx_forms.geometry import pairs as contact

    rng = np.random.default_rng(3)
    n = 40
    a = np.arange(n - 1)
    rows = np.concatenate([a, a + 1, a, a + 1])  # per element: its 2 x 2 block
    cols = np.concatenate([a, a + 1, a + 1, a])
    w = rng.uniform(0.5, 1.5, n - 1)
    vals = np.concatenate([w / 3, w / 3, w / 6, w / 6])
    diag = np.where(np.arange(n) % 7 == 0, 1.0, 0.0)
    A = np.zeros((n, n))
    np.add.at(A, (rows, cols), vals)
    A += np.diag(diag)
    b = rng.normal(size=n)
    x = np.linalg.solve(A, b)
    dense = contact.mass_solver(rows, cols, vals, diag)(b)
    monkeypatch.setattr(contact, "DENSE_MASS_NODES", 0)
    sparse = contact.mass_solver(rows, cols, vals, diag)(b)
    assert np.allclose(dense, x, rtol=0, atol=1e-12 * np.abs(x).max())
    assert np.allclose(sparse, x, rtol=0, atol=1e-12 * np.abs(x).max())


def test_a_point_without_closest_point_is_left_out_and_reported(hertz, monkeypatch):
    """A contact point whose closest point is not found (here forced: the iterate left the
    pair grid) is left out of a pair without multiplier nodes, named in `dropped` and in the
    pair's warnings; with P1 multiplier nodes (which refer to the points) the step fails."""
    from dolfinx_forms.geometry import pairs as contact
    from dolfinx_forms.solvers.checks import pair_warnings

    scene, V = hertz
    full = pair_geometry(V, scene, (0, 1), 0.2)
    assert not full.dropped
    real = contact.closest_points

    def failing(body, phi, points, scale, exact=True):
        r = real(body, phi, points, scale, exact)
        if scale > 1e-2:  # the quadrature's call (h), not a label's (1e-3 h)
            r["converged"][3], r["status"][3] = False, int(_cpp.ProjectionStatus.left_grid)
        return r

    monkeypatch.setattr(contact, "closest_points", failing)
    g = pair_geometry(V, scene, (0, 1), 0.2)
    assert len(g.weights) == len(full.weights) - 1 and len(g.dropped) == 1
    assert "1 points left out" in g.dropped[0] and "left_grid" in g.dropped[0]
    keep = np.r_[0:3, 4 : len(full.weights)]
    np.testing.assert_array_equal(g.points, full.points[keep])
    state = dict(state=np.zeros(len(g.weights), np.int8))
    assert any(
        "closest-point projection failed" in w for w in pair_warnings(g, state, 0.1, 0.2, "a-b")
    )
    with pytest.raises(RuntimeError, match="closest-point projection failed"):
        pair_geometry(V, scene, (0, 1), 0.2, multipliers="P0")
