"""Grain outlines and packing (meshes/grains.py; issue 13 item 2): Fourier grains are
reproducible, star-shaped about their centroid, with the area of the Fourier series and an
aspect ratio that grows with elongation; polygon helpers and the exact polygon distance against
hand values and against dolfinx_forms.Polygon's exact signed distance; a 25-grain packing keeps
the gap (all pairs, brute force) and the box; impossible packings raise ValueError."""

import numpy as np
import pytest
from dolfinx_forms import _cpp

from meshes import grains as g


def test_shapes_and_outlines():
    c = (0.3, -0.2)
    d = g.disc(c, 1.5)
    assert isinstance(d, _cpp.Circle)
    np.testing.assert_allclose(d(np.array([[0.3, -0.2], [2.3, -0.2]])), [-1.5, 0.5], atol=1e-15)
    e = g.ellipse(c, 2.0, 0.5, 0.4)
    # Outline vertices lie on the curves (the shapes are exact signed distances: |phi| ~ 1e-15).
    assert np.abs(e(g.ellipse_outline(c, 2.0, 0.5, 0.4, 50))).max() < 1e-12
    v = g.disc_outline(c, 1.5, 40)
    assert np.abs(d(v)).max() < 1e-12
    assert g.polygon_area(v) > 0  # counter-clockwise
    p = g.polygon(v)
    assert isinstance(p, _cpp.Polygon) and p(np.array([c]))[0] < 0
    with pytest.raises(ValueError, match="R"):
        g.disc(c, -1.0)


def test_polygon_helpers():
    sq = np.array([[0, 0], [2, 0], [2, 1], [0, 1]], float)
    assert g.polygon_area(sq) == 2.0 and g.polygon_area(sq[::-1]) == -2.0
    np.testing.assert_allclose(
        g.polygon_centroid(sq + 1e6), [1e6 + 1, 1e6 + 0.5], rtol=0, atol=1e-9
    )
    tri = np.array([[0, 0], [3, 0], [0, 3]], float)
    np.testing.assert_allclose(g.polygon_centroid(tri), [1, 1], atol=1e-15)
    np.testing.assert_array_equal(g.polygon_bbox(tri), [[0, 0], [3, 3]])
    np.testing.assert_allclose(g.rotate(sq, np.pi), sq[[2, 3, 0, 1]], atol=1e-15)


def test_distances():
    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    assert g.polygon_distance(sq, sq + [1.3, 0]) == pytest.approx(0.3, abs=1e-15)
    assert g.polygon_distance(sq, sq + [1.3, 1.4]) == pytest.approx(0.5, abs=1e-15)  # 3-4-5
    assert g.polygon_distance(sq, sq + [1.0, 0.5]) == 0.0  # touching edges
    assert g.polygon_distance(sq, 0.25 * sq + 0.3) == 0.0  # nested
    # A plus sign: crossing bars, no vertex of one inside the other.
    h = np.array([[-2, -0.1], [2, -0.1], [2, 0.1], [-2, 0.1]])
    assert g.polygon_distance(h, h[:, ::-1].copy()) == 0.0
    assert g.polygon_distance(sq, sq + [5.0, 0], cutoff=1.0) == np.inf  # beyond the cutoff
    # Segments: crossing, parallel, T-contact.
    d = g.segment_distance(
        [[0, 0], [0, 0], [0, 0]],
        [[1, 1], [1, 0], [1, 0]],
        [[0, 1], [0, 0.5], [0.5, 0]],
        [[1, 0], [1, 0.5], [0.5, 1]],
    )
    np.testing.assert_allclose(d, [0, 0.5, 0], atol=1e-15)
    # Random grains vs the exact signed distance of dolfinx_forms.Polygon: for disjoint
    # polygons the distance is attained at a vertex of one of them.
    rng = np.random.default_rng(4)
    for _ in range(20):
        P = g.fourier_grain(rng, 1.0, 0.3, 0.05, n_vertices=64)
        Q = g.rotate(g.fourier_grain(rng, 0.7, 0.1, 0.08, n_vertices=64), 1.0) + rng.uniform(
            1.5, 2.5, size=2
        )
        ref = min(_cpp.Polygon(Q)(P).min(), _cpp.Polygon(P)(Q).min())
        if ref > 0:
            assert g.polygon_distance(P, Q) == pytest.approx(ref, rel=1e-12)
        else:
            assert g.polygon_distance(P, Q) == 0.0
    # Point in polygon agrees with the sign of the exact distance.
    P = g.fourier_grain(9, 1.0, 0.4, 0.1)
    x = rng.uniform(-1.6, 1.6, size=(2000, 2))
    phi = _cpp.Polygon(P)(x)
    far = np.abs(phi) > 1e-9
    np.testing.assert_array_equal(g.point_in_polygon(x, P)[far], (phi < 0)[far])


def test_fourier_grain_reproducible():
    a = g.fourier_grain(7, 1.0, 0.2, 0.05)
    np.testing.assert_array_equal(a, g.fourier_grain(7, 1.0, 0.2, 0.05))
    np.testing.assert_array_equal(a, g.fourier_grain(np.random.default_rng(7), 1.0, 0.2, 0.05))
    assert not np.array_equal(a, g.fourier_grain(8, 1.0, 0.2, 0.05))
    assert a.shape == (128, 2)
    np.testing.assert_allclose(g.polygon_centroid(a), [0, 0], atol=1e-14)


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("elongation, roughness", [(0.0, 0.02), (0.25, 0.06), (0.5, 0.15)])
def test_fourier_grain_star_shaped_and_area(seed, elongation, roughness):
    R, n = 1.3, 128
    v, a, phi = g.fourier_grain(seed, R, elongation, roughness, n_vertices=n, return_modes=True)
    # r >= 0.3 R about the polar origin (the sum of |a_k| is capped at 0.7).
    assert a[2] == elongation and np.abs(a).sum() <= 0.7 + 1e-12
    # Every ray from the centroid crosses once: angles about it strictly increase, by 2 pi.
    d = v - g.polygon_centroid(v)
    dn = np.roll(d, -1, axis=0)
    step = np.arctan2(d[:, 0] * dn[:, 1] - d[:, 1] * dn[:, 0], np.sum(d * dn, axis=1))
    assert np.all(np.hypot(d[:, 0], d[:, 1]) > 0) and np.all(step > 0)
    assert step.sum() == pytest.approx(2 * np.pi, rel=1e-12)  # winds once
    # Area: the n-gon of samples has exactly (n/2) sin(D) R^2 (1 + sum a_k^2 cos(k D) / 2),
    # D = 2 pi / n (no aliasing for 2 K < n) ...
    A = g.polygon_area(v)
    D, k = 2 * np.pi / n, np.arange(a.size)
    assert A == pytest.approx(
        n / 2 * np.sin(D) * R**2 * (1 + np.sum(a**2 * np.cos(k * D)) / 2), rel=1e-12
    )
    # ... hence within D^2/6 + sum k^2 a_k^2 D^2 / 4 (1 - sin D / D, 1 - cos kD) of the curve's
    # pi R^2 (1 + sum a_k^2 / 2).
    exact = np.pi * R**2 * (1 + np.sum(a**2) / 2)
    assert abs(A / exact - 1) <= D**2 / 6 + np.sum(k**2 * a**2) * D**2 / 4
    # The roughness is the RMS of the k >= 3 part of r / R - 1 (unless capped).
    if abs(a).sum() < 0.7 - 1e-9:
        assert np.sqrt(np.sum(a[3:] ** 2) / 2) == pytest.approx(roughness, rel=1e-12)


def test_elongation_aspect_ratio():
    aspect = []
    for e in [0.0, 0.1, 0.2, 0.3, 0.4, 0.5]:
        lo, hi = g.polygon_bbox(g.fourier_grain(3, 1.0, e, 0.03))
        aspect.append((hi - lo)[0] / (hi - lo)[1])  # long axis along x
    assert np.all(np.diff(aspect) > 0), aspect
    assert aspect[-1] > 2.0  # (1 + 0.5) / (1 - 0.5) = 3 for the bare k = 2 outline


def test_bad_fourier_input():
    for kw, name in [
        ({"elongation": 0.7}, "elongation"),
        ({"roughness": -1}, "roughness"),
        ({"n_modes": 1}, "n_modes"),
        ({"n_vertices": 30}, "n_vertices"),
    ]:
        with pytest.raises(ValueError, match=name):
            g.fourier_grain(1, 1.0, **kw)


def grains25(seed=11):
    rng = np.random.default_rng(seed)
    return [
        g.fourier_grain(
            rng, rng.uniform(0.8, 1.2), rng.uniform(0, 0.35), rng.uniform(0, 0.06), n_vertices=96
        )
        for _ in range(25)
    ]


def test_pack_25_grains():
    outl = grains25()
    box, gap = np.array([[0.0, 0.0], [16.0, 13.0]]), 0.05  # area fraction 0.36
    packed = g.pack_grains(outl, box, gap=gap, rng=2)
    again = g.pack_grains(outl, box, gap=gap, rng=2)
    assert all(np.array_equal(p, q) for p, q in zip(packed, again))  # reproducible
    # Congruent to the inputs (rotation + translation): same area and edge lengths.
    for p, q in zip(packed, outl):
        assert g.polygon_area(p) == pytest.approx(g.polygon_area(q), rel=1e-12)
        np.testing.assert_allclose(
            np.linalg.norm(np.diff(p, axis=0), axis=1),
            np.linalg.norm(np.diff(q, axis=0), axis=1),
            rtol=1e-12,
        )
    # Inside the box with the wall gap (= gap).
    allv = np.concatenate(packed)
    assert np.all(allv >= box[0] + gap) and np.all(allv <= box[1] - gap)
    # Every pair (brute force, 300 pairs) at least gap apart ...
    n = len(packed)
    dmin = min(g.polygon_distance(packed[i], packed[j]) for i in range(n) for j in range(i + 1, n))
    assert dmin >= gap
    # ... and, independently, boundary samples (8 per edge) of each grain against the exact
    # signed distance of every other: >= gap (an overlap would give samples < 0).
    t = np.linspace(0, 1, 8, endpoint=False)[:, None, None]
    dense = [(p + t * (np.roll(p, -1, axis=0) - p)).reshape(-1, 2) for p in packed]
    sd = min(_cpp.Polygon(packed[j])(dense[i]).min() for i in range(n) for j in range(n) if i != j)
    assert sd >= gap
    # The broad-phase minimum agrees with the brute force one where it is below the cutoff.
    assert g.min_separation(packed, 1.0) == (dmin if dmin < 1.0 else np.inf)


def test_pack_errors():
    outl = grains25()[:6]
    with pytest.raises(ValueError, match=r"box \[\[0.0, 0.0\], \[3.0, 3.0\]\].*smaller"):
        g.pack_grains(outl, [[0, 0], [3, 3]], gap=0.05, rng=0)  # total area exceeds the box
    with pytest.raises(ValueError, match=r"box .*does not fit"):
        g.pack_grains(outl, [[0, 0], [40, 1.2]], gap=0.05, rng=0, max_tries=50)  # too thin
    with pytest.raises(ValueError, match="gap"):
        g.pack_grains(outl, [[0, 0], [10, 10]], gap=-1)
    with pytest.raises(ValueError, match="box"):
        g.pack_grains(outl, [[0, 0], [-1, 10]])


def _covered(n, cols):
    """Every grain of the last full row has a grain of the row above at +-1/2 a spacing (rows
    of `cols`, odd rows shifted by 1/2, the last row partial): the lattice itself, counted."""
    k = np.arange(n)
    i, j = k % cols, k // cols
    x = i + 0.5 * (j % 2)
    top = n // cols - 1  # the last full row
    above = set(x[j == top + 1].tolist())
    return j.max() == top or all({v - 0.5, v + 0.5} & above for v in x[j == top])


def test_assembly_rows_hold_every_grain():
    """meshes.assembly.held_rows is the lattice's own count (every n <= 120, every row length),
    the layouts that ran keep their rows (9, 12, 15, 100, 400 grains), and the counts whose
    last row left a grain without a neighbour above (7, 700, 1000: they failed at the first
    step) get a row length that holds every grain."""
    from meshes.assembly import held_rows, lattice_columns

    for n in range(2, 121):
        for cols in range(1, n + 1):
            assert held_rows(n, cols) == _covered(n, cols), (n, cols)
    assert [lattice_columns(n) for n in (9, 12, 15, 100, 400)] == [3, 4, 4, 10, 20]
    for n in (7, 700, 1000):
        assert not held_rows(n, int(np.ceil(np.sqrt(n))))
        assert _covered(n, lattice_columns(n))
    assert [lattice_columns(n) for n in (7, 700, 1000)] == [2, 25, 25]
