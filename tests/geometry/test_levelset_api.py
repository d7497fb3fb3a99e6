"""Python-facing level-set API: layouts, vectorised projection, graded grids."""

import numpy as np

import dolfinx_forms as df


def test_layout_and_locate():
    x = np.array([0.0, 0.1, 0.3, 0.6, 1.0])
    y = np.array([0.0, 0.5, 1.0, 2.0])
    g = df.StructuredGrid(x, y)
    assert g.shape == (4, 5) and g.num_nodes == 20 and g.num_cells == 12
    nodes = g.nodes()
    assert np.array_equal(nodes[:5, 0], x) and np.all(nodes[:5, 1] == 0)  # x-fastest
    cells = g.locate(np.array([[0.05, 0.2], [0.7, 1.5], [1.0, 2.0], [1.1, 0.0]]))
    assert list(cells) == [0, 4 * 2 + 3, 4 * 2 + 3, -1]
    phi = df.LevelSet(g, nodes[:, 0] + 2 * nodes[:, 1])
    assert phi.values.shape == (4, 5)
    v, gr = phi.evaluate(np.array([[0.45, 0.75]]))
    assert np.allclose(v, 0.45 + 1.5, atol=1e-14) and np.allclose(gr, [[1.0, 2.0]], atol=1e-13)


def test_projection_vectorised_graded_grid():
    """A graded grid concentrating nodes at the boundary of a disc: projections exact to
    the interpolation error there (O(h_fine^2), h_fine = 0.4/40 * ~0.3)."""
    t = np.tanh(2.0 * np.linspace(-1, 1, 121)) / np.tanh(2.0)
    g = df.StructuredGrid(1.0 + 0.6 * t, 0.6 * t)  # clustered at x = 1, y = 0
    phi = df.levelset_from_shape(g, df.Circle([0.0, 0.0], 1.0))
    th = np.linspace(-0.2, 0.2, 41)
    pts = np.c_[1.1 * np.cos(th), 1.1 * np.sin(th)]
    r = df.closest_point_projection(phi, pts)
    assert r["converged"].all() and r["status"].dtype == np.int8
    assert np.abs(r["points"] - np.c_[np.cos(th), np.sin(th)]).max() < 1e-5
    assert r["iterations"].max() <= 6


def test_polyline_levelset_matches_polygon():
    th = np.linspace(0, 2 * np.pi, 60, endpoint=False)
    v = np.c_[0.5 + 0.3 * np.cos(th), 0.5 + 0.2 * np.sin(th)]
    g = df.StructuredGrid.uniform([0, 0], [1, 1], [60, 60])
    a = df.levelset_from_polyline(g, v, band=3)
    b = df.levelset_from_shape(g, df.Polygon(v))
    exact = df.Polygon(v)(g.nodes()).reshape(g.shape)
    near = np.abs(exact) < 2.5 / 60
    assert np.abs(a.values - b.values)[near].max() < 1e-12  # exact in the band
    assert np.array_equal(np.sign(a.values), np.sign(exact))
