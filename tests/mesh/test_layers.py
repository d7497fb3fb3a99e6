"""meshes/layers.py, the mesher-free body-fitted triangles: the zipper of two parallel rows and
the nested layers of a block and a half-disc are valid, conforming triangulations of exactly
the polygon they claim (areas to round-off), mirror-symmetric, with the boundary nodes on the
curve. Pure numpy: no gmsh, no DOLFINx."""

import numpy as np
import pytest

from meshes.hertz import _layers
from meshes.layers import layer_mesh, layer_nodes, zip_strips


def signed_areas(x, tri):
    p = x[tri]
    d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    return 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])


def edge_counts(tri):
    """(edges (k, 2) sorted, number of triangles on each)."""
    e = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    return np.unique(e, axis=0, return_counts=True)


def mirrored_same(x, tri):
    """The triangles' centroids are their own mirror image about x = 0 (as a set)."""
    c = x[tri].mean(axis=1)
    key = np.round(c, 9)
    m = key * np.array([-1.0, 1.0])
    m[m == 0] = 0.0  # -0.0
    key[key == 0] = 0.0
    return {tuple(r) for r in key} == {tuple(r) for r in m}


@pytest.mark.parametrize("seed", range(4))
def test_zip_two_parallel_rows(seed):
    """Any two sorted rows on parallel lines: (n_a - 1) + (n_b - 1) counter-clockwise triangles
    of positive area filling the trapezoid between them, each edge in at most two."""
    rng = np.random.default_rng(seed)
    na, nb = rng.integers(1, 12, size=2)
    ya = np.sort(rng.uniform(0, 1, na)) if na > 1 else np.array([0.4])
    yb = np.sort(rng.uniform(-0.2, 1.3, nb))
    x = np.concatenate([np.column_stack([np.zeros(na), ya]), np.column_stack([np.ones(nb), yb])])
    tri = zip_strips(x, [0], [na], [na], [nb], [[0.0, 1.0]], [True])
    assert len(tri) == na - 1 + nb - 1
    a = signed_areas(x, tri)
    assert np.all(a > 0)
    # the trapezoid (a degenerate side: a triangle) between the two rows
    assert np.isclose(a.sum(), 0.5 * ((ya[-1] - ya[0]) + (yb[-1] - yb[0])), rtol=1e-12)
    assert edge_counts(tri)[1].max() <= 2
    # every triangle has one edge along a row, its third node on the other row
    on_a = tri < na
    assert np.all((on_a.sum(axis=1) == 1) | (on_a.sum(axis=1) == 2))


def test_zip_ties_step_by_a_first():
    """Aligned rows (a square grid): the tie rule chooses the diagonal, a_first the one
    from a's next node back to b's current node."""
    x = np.array([[0, 0], [0, 1], [1, 0], [1, 1]], float)
    first = zip_strips(x, [0], [2], [2], [2], [[0.0, 1.0]], [True])
    second = zip_strips(x, [0], [2], [2], [2], [[0.0, 1.0]], [False])
    diag = {tuple(sorted(e)) for t in first for e in zip(t, np.roll(t, 1))} - {(0, 1), (2, 3)}
    assert (1, 2) in diag  # a_1 - b_0
    diag = {tuple(sorted(e)) for t in second for e in zip(t, np.roll(t, 1))} - {(0, 1), (2, 3)}
    assert (0, 3) in diag  # a_0 - b_1


def block_layers(W=3.0, D=2.0, n=6):
    """U layers of the block [-W, W] x [-D, 0] around the origin, the last its outline."""
    t = np.linspace(0, 1, n + 1)
    X, Y = W * t, D * t
    o = np.zeros_like(t)
    pts = [(-X, o), (-X, -Y), (o, -Y), (X, -Y), (X, o)]
    return np.stack([np.column_stack(p) for p in pts], axis=1), np.full(n + 1, 0.5)


def test_layer_nodes_sides_and_corners():
    """Layer k runs Q0 -> Q4; each side starts and ends at its points; the single-point layer
    0 is one node; no node is repeated."""
    P, sp = block_layers()
    x, starts = layer_nodes(P, sp)
    for k in range(len(P)):
        for j in range(5):
            assert np.allclose(x[starts[k, j]], P[k, j], atol=1e-14)
    assert np.all(starts[0] == 0)  # layer 0: the origin once
    assert len(np.unique(np.round(x, 12), axis=0)) == len(x)


@pytest.mark.parametrize("W,D,n", [(3.0, 2.0, 6), (1.0, 4.0, 3), (2.0, 2.0, 10)])
def test_block_layers_tile_the_block(W, D, n):
    P, sp = block_layers(W, D, n)
    x, tri = layer_mesh(P, sp)
    a = signed_areas(x, tri)
    assert np.all(a > 0)
    assert np.isclose(a.sum(), 2 * W * D, rtol=1e-12)
    edges, count = edge_counts(tri)
    assert count.max() == 2
    # the edges of one triangle are the outline: its length is the block's perimeter
    b = edges[count == 1]
    assert np.isclose(np.linalg.norm(x[b[:, 0]] - x[b[:, 1]], axis=1).sum(), 2 * (2 * W + D))
    q = x[b].reshape(-1, 2)
    assert np.all(np.isclose(abs(q[:, 0]), W) | np.isclose(q[:, 1], 0) | np.isclose(q[:, 1], -D))
    assert mirrored_same(x, tri)
    used = np.zeros(len(x), bool)
    used[tri.ravel()] = True
    assert used.all()


@pytest.mark.parametrize(
    "R,Ry,h,growth", [(10.0, 10.0, 0.2, 0.25), (10.0, 6.0, 0.1, 0.5), (5.0, 9.0, 0.25, 1.0)]
)
def test_hertz_layers(R, Ry, h, growth):
    """Both Hertz bodies: valid, conforming, mirror-symmetric; the block exactly its
    rectangle; the indenter's boundary nodes exactly on the ellipse or its flat top, its
    area that of the inscribed polygon (below the half-ellipse's by the chords' segments,
    O(h_far^2)); the zone's edges between 0.6 h and 1.1 h, the block's a square grid."""
    W, D, z = 20.0, 20.0, 1.2
    x, tri = _layers(R, Ry, W, D, z, h, 5.0, growth)
    a = signed_areas(x, tri)
    assert np.all(a > 0)
    edges, count = edge_counts(tri)
    assert count.max() == 2
    assert mirrored_same(x, tri)
    block = x[tri].mean(axis=1)[:, 1] < 0
    assert np.isclose(a[block].sum(), 2 * W * D, rtol=1e-12)
    b = np.unique(edges[count == 1])
    xb = x[b][x[b][:, 1] > 0]  # the indenter's outline but its lowest point
    on_arc = np.isclose(np.hypot(xb[:, 0] / R, (xb[:, 1] - Ry) / Ry), 1, atol=1e-12)
    assert np.all(on_arc | np.isclose(xb[:, 1], Ry, atol=1e-12))
    half = np.pi * R * Ry / 2
    assert 0.9 * half < a[~block].sum() < half
    # the zone |x|, |y| < z - h: the block's cells halves of squares of side h / sqrt(2) (edges
    # h / sqrt(2) and h); the indenter's arms span r - sag(r), in parts near h / sqrt(2)
    p = x[tri]
    inner = np.all(np.abs(p).max(axis=2) < z - h, axis=1)
    e = np.linalg.norm(p[inner] - np.roll(p[inner], 1, axis=1), axis=2)
    in_block = p[inner][..., 1].mean(axis=1) < 0
    eb = e[in_block]
    assert np.all(np.isclose(eb, h / np.sqrt(2), rtol=1e-9) | np.isclose(eb, h, rtol=1e-9))
    assert 0.6 * h < e.min() and e.max() <= 1.1 * h


def test_touching_layers_refused():
    """Two layers that coincide over a side make triangles of no area: refused by name."""
    P, sp = block_layers()
    P[2, 1:4, 1] = P[1, 1:4, 1]  # layer 2's bottom on layer 1's
    with pytest.raises(ValueError, match="no area"):
        layer_mesh(P, sp)


def test_zone_outside_the_indenter_refused():
    """A zone whose corner (zone, zone) lies outside a slender indenter (R = 0.5, Ry = 10:
    its arc is at y = 0.84 at x = 0.2) would fold the layers over: refused before meshing."""
    from mpi4py import MPI

    from meshes.hertz import hertz_scene

    for mesher in ("layers", "gmsh"):
        with pytest.raises(ValueError, match="zone 0.2 must lie inside both bodies"):
            hertz_scene(MPI.COMM_SELF, R=0.5, Ry=10.0, h=0.01, zone=0.2, mesher=mesher)
