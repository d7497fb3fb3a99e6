"""Intermediate contact surface (eqs 21-24) against exact equidistant curves.

On Gamma_int the two exact signed distances are equal, so |phi_A - phi_B|/2 at the
quadrature points measures the position error directly. The surface is a straight
segment per grid cell (chord of a curve of curvature k): position O(k h^2), normal
O(h^2), length O(h^2). The asserted orders leave margin (1.6 for a theoretical 2)
for the pre-asymptotic range; absolute bounds are the finest-mesh figures with a
factor ~3 of slack.
"""

import numpy as np
import pytest
from scipy.optimize import brentq

import dolfinx_forms as df


def exact_curve_length(fA, fB, y0, y1, xbracket, n=4001):
    """Arc length of {phi_A = phi_B} between heights y0 < y1, the curve being a graph x(y)."""
    ys = np.linspace(y0, y1, n)
    xs = np.array(
        [
            brentq(
                lambda x: fA(np.array([[x, y]]))[0] - fB(np.array([[x, y]]))[0],
                *xbracket,
                xtol=1e-15,
            )
            for y in ys
        ]
    )
    return np.hypot(np.diff(xs), np.diff(ys)).sum()


def surface_on(grid_n, A, B, lo, hi, eps):
    nx, ny = grid_n
    g = df.StructuredGrid.uniform(lo, hi, [nx, ny])
    return g, df.contact_surface(
        df.levelset_from_shape(g, A), df.levelset_from_shape(g, B), eps=eps
    )


def check_surface(s, A, B, grad_exact, xbracket):
    """Return (position error, normal error, relative length error) of one surface."""
    x = s["points"]
    pos = np.abs(A(x) - B(x)).max() / 2
    ne = grad_exact(x)
    ne /= np.linalg.norm(ne, axis=1)[:, None]
    nerr = np.linalg.norm(s["normals"] - ne, axis=1).max()
    seg = s["segments"]
    length = np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1).sum()
    ends = seg.reshape(-1, 2)
    exact = exact_curve_length(A, B, ends[:, 1].min(), ends[:, 1].max(), xbracket)
    # Quadrature weights integrate the length exactly; tangents are unit and orthogonal
    assert s["weights"].sum() == pytest.approx(length, rel=1e-13)
    assert np.allclose(np.einsum("ij,ij->i", s["normals"], s["tangents"]), 0.0, atol=1e-14)
    assert np.allclose(np.linalg.norm(s["tangents"], axis=1), 1.0, atol=1e-14)
    return pos, nerr, abs(length - exact) / exact


def rates(errs):
    errs = np.asarray(errs)
    return np.log2(errs[:-1] / errs[1:])


def test_two_circles_unequal_radii():
    R1, R2, gap = 1.0, 0.6, 0.05
    c1, c2 = np.array([-R1 - gap / 2, 0.0]), np.array([R2 + gap / 2, 0.0])
    A, B = df.Circle(c1, R1), df.Circle(c2, R2)

    def grad(x):
        return (x - c1) / np.linalg.norm(x - c1, axis=1)[:, None] - (x - c2) / np.linalg.norm(
            x - c2, axis=1
        )[:, None]

    res = []
    for n in (100, 200, 400):
        _, s = surface_on((n, 3 * n // 4), A, B, [-2.5, -1.5], [1.5, 1.5], eps=0.1)
        assert np.all(s["normals"][:, 0] > 0.9)  # body i = A (left) -> body j = B (right)
        res.append(check_surface(s, A, B, grad, (-0.5, 0.5)))
    pos, nerr, lerr = np.array(res).T
    assert rates(pos)[-1] > 1.6 and pos[-1] < 1e-5
    # normals: observed rates 1.41, 1.55 on these meshes (approaching 2 from below)
    assert rates(nerr)[-1] > 1.4 and nerr[-1] < 3e-5
    assert lerr.max() < 1e-3


def test_circle_above_box_parabola():
    """Equidistant curve between a disc (radius R, gap g) and a flat face: a parabola."""
    R, g = 1.0, 0.04
    A = df.Box([-3.0, -1.0], [3.0, 0.0])
    B = df.Circle([0.0, R + g], R)

    def grad(x):
        c = np.array([0.0, R + g])
        gb = (x - c) / np.linalg.norm(x - c, axis=1)[:, None]
        return np.c_[np.zeros(len(x)), np.ones(len(x))] - gb

    res = []
    for n in (64, 128, 256):
        _, s = surface_on((2 * n, n), A, B, [-1.0, -0.5], [1.0, 0.5], eps=0.08)
        x = s["points"]
        parabola = (x[:, 0] ** 2 + 2 * R * g + g**2) / (2 * (2 * R + g))
        assert np.abs(x[:, 1] - parabola).max() < 2 * np.abs(A(x) - B(x)).max() + 1e-12
        # the curve is a graph y(x): measure length with x and y swapped
        seg = s["segments"]
        length = np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1).sum()
        xs = np.linspace(seg[..., 0].min(), seg[..., 0].max(), 20001)
        ys = (xs**2 + 2 * R * g + g**2) / (2 * (2 * R + g))
        exact = np.hypot(np.diff(xs), np.diff(ys)).sum()
        ne = grad(x)
        ne /= np.linalg.norm(ne, axis=1)[:, None]
        res.append(
            (
                np.abs(A(x) - B(x)).max() / 2,
                np.linalg.norm(s["normals"] - ne, axis=1).max(),
                abs(length - exact) / exact,
            )
        )
    pos, nerr, lerr = np.array(res).T
    assert rates(pos)[-1] > 1.6 and pos[-1] < 1e-5
    assert rates(nerr)[-1] > 1.6
    assert lerr.max() < 1e-3


def test_overlap_is_kept():
    """Penetrated bodies: the chord through the overlap lens must be on Gamma_c."""
    d = 0.98  # centres at +-d, radius 1: overlap depth 0.04
    A, B = df.Circle([-d, 0.0], 1.0), df.Circle([d, 0.0], 1.0)
    _, s = surface_on((200, 120), A, B, [-2.5, -1.5], [2.5, 1.5], eps=0.1)
    y = s["points"][:, 1]
    half_chord = np.sqrt(1 - d**2)
    assert y.min() < -half_chord and y.max() > half_chord
    assert np.abs(s["points"][:, 0]).max() < 1e-12  # symmetric: exactly on x = 0
    inside = np.abs(y) < half_chord
    assert inside.sum() >= 2 * half_chord / (5.0 / 200) - 2  # ~1 segment per cell crossed
    assert np.all(A(s["points"][inside]) < 0)


def test_far_apart_and_region_flags():
    A, B = df.Circle([-1.0, 0.0], 0.5), df.Circle([1.0, 0.0], 0.5)
    g = df.StructuredGrid.uniform([-2, -1], [2, 1], [80, 40])
    pa, pb = df.levelset_from_shape(g, A), df.levelset_from_shape(g, B)
    s = df.contact_surface(pa, pb, eps=0.1)  # gap 1.0 >> 2 eps: nothing to search
    assert len(s["weights"]) == 0 and s["segments"].shape == (0, 2, 2)
    # Close pair: the bridge nodes between them are in the region, far nodes are not
    B2 = df.Circle([0.2, 0.0], 0.5)  # gap 0.2 in [-0.5, -0.3]
    region = df.contact_region(pa, df.levelset_from_shape(g, B2), eps=0.15)
    X = g.nodes().reshape(g.shape + (2,))
    mid = np.argmin(np.abs(g.x - (-0.4)))
    j0 = np.argmin(np.abs(g.y))
    assert region[j0, mid] == 1
    assert region[0, 0] == 0 and region[-1, -1] == 0
    assert not region[np.hypot(X[..., 0] + 1, X[..., 1]) < 0.4].any()  # interior of A alone


def test_bad_inputs():
    g = df.StructuredGrid.uniform([0, 0], [1, 1], [10, 10])
    g2 = df.StructuredGrid.uniform([0, 0], [1, 2], [10, 10])
    a = df.levelset_from_shape(g, df.Circle([0.3, 0.5], 0.2))
    b = df.levelset_from_shape(g, df.Circle([0.7, 0.5], 0.19))
    with pytest.raises(ValueError, match="eps"):
        df.contact_surface(a, b, eps=0.0)
    with pytest.raises(ValueError, match="num_gauss"):
        df.contact_surface(a, b, eps=0.1, num_gauss=0)
    with pytest.raises(ValueError, match="grid"):
        df.contact_surface(a, df.levelset_from_shape(g2, df.Circle([0.7, 0.5], 0.2)), eps=0.1)
    with pytest.raises(ValueError, match="not finite"):
        df.LevelSet(g, np.full(121, np.nan))
    with pytest.raises(ValueError, match="at least 3 nodes"):
        df.StructuredGrid(np.array([]), np.array([0.0, 1.0, 2.0]))
    with pytest.raises(IndexError, match="outside the grid"):
        df.closest_point_projection(a, np.array([[0.5, 1.5]]))
    with pytest.raises(ValueError, match=r"\(n, 2\)"):
        df.closest_point_projection(a, np.zeros((3, 3)))


def test_segment_quadrature_reproduces_and_refines_contact_surface():
    """`segment_quadrature` on contact_surface's own segments gives its points, weights and
    normals bitwise; on the segments split in two it integrates a cubic along Gamma_c as
    exactly (2 Gauss points per piece) and the length is unchanged."""
    A = df.Box([-3.0, -1.0], [3.0, 0.0])
    B = df.Circle([0.0, 1.04], 1.0)
    g = df.StructuredGrid.uniform([-1.0, -0.5], [1.0, 0.5], [64, 32])
    pa, pb = df.levelset_from_shape(g, A), df.levelset_from_shape(g, B)
    s = df.contact_surface(pa, pb, eps=0.08)
    phi = df.intermediate_levelset(pa, pb)
    q = df._cpp.segment_quadrature(phi, s["segments"], s["cells"], 2)
    for k in ("points", "weights", "normals", "tangents", "segment"):
        assert np.array_equal(q[k], s[k]), k
    mid = 0.5 * (s["segments"][:, 0] + s["segments"][:, 1])
    halves = np.concatenate(
        [np.stack([s["segments"][:, 0], mid], 1), np.stack([mid, s["segments"][:, 1]], 1)]
    )
    r = df._cpp.segment_quadrature(phi, halves, np.r_[s["cells"], s["cells"]], 2)
    f = lambda x: x[:, 0] ** 3 - 2 * x[:, 0] * x[:, 1]  # cubic in the arc parameter of a piece
    assert abs(r["weights"].sum() - s["weights"].sum()) < 1e-13
    assert abs(np.dot(r["weights"], f(r["points"])) - np.dot(s["weights"], f(s["points"]))) < 1e-13
    with pytest.raises(ValueError, match="num_gauss"):
        df._cpp.segment_quadrature(phi, s["segments"], s["cells"], 0)
