"""meshes/column.py, the granular column's sample, wall protocol and statistics shared by
demos/granular_column.py and benchmarks/dem_peer.py (numpy only): the sample is reproducible,
without contact and inside its walls; the walls follow the three phases with the area constant
through the shear; the stresses and contact statistics of hand-made states."""

from types import SimpleNamespace

import numpy as np
import pytest

from meshes import column
from meshes import grains as gr


@pytest.mark.parametrize("shape", [(0.0, 0.0), (0.15, 0.03)], ids=["discs", "fourier"])
def test_sample_is_reproducible_without_contact_inside_its_walls(shape):
    a = column.random_sample(30, 1.0, 0.2, *shape, seed=4)
    b = column.random_sample(30, 1.0, 0.2, *shape, seed=4)
    assert a.discs == (shape == (0.0, 0.0))
    assert all(np.array_equal(p, q) for p, q in zip(a.outlines, b.outlines))
    assert gr.min_separation(a.outlines, 0.5) >= 0.1 - 1e-12  # the default gap, 0.1 radius
    (x0, y0), (x1, y1) = a.box
    assert x1 - x0 == pytest.approx(y1 - y0)  # MELODY's square domain
    for v in a.outlines:
        assert v.min() >= x0 + 0.1 - 1e-12 and v[:, 0].max() <= x1 - 0.1 + 1e-12
        assert v[:, 1].max() <= y1 - 0.1 + 1e-12
    if a.discs:
        assert np.all((a.radius >= 0.8) & (a.radius <= 1.2))
    area = sum(abs(gr.polygon_area(v)) for v in a.outlines)
    assert area / np.prod(a.box[1] - a.box[0]) == pytest.approx(0.35, rel=1e-12)


def test_walls_follow_the_three_phases():
    """Deposition: the box; compression: the top wall from the settled height H_s down to
    (1 - c) H_s, linearly; shear: W = W_c exp(gamma / 2), H = H_c exp(-gamma / 2), the area
    constant, gamma linear in time; phases with a round-off margin at their ends."""
    box = np.array([[0.0, 0.0], [10.0, 10.0]])
    p = column.Protocol(box, 5.0, 2.0, 4.0, 0.1, 0.2)
    hs = 6.0
    assert p.walls(2.0, None) == dict(left=0.0, right=10.0, bottom=0.0, top=10.0)
    assert p.phase(5.0 + 1e-12) == "deposition" and p.phase(5.1) == "compression"
    assert p.walls(5.0 + 1e-13, hs)["top"] == 10.0  # still deposition: no settled height yet
    assert p.walls(5.0 + 1e-6, hs)["top"] == pytest.approx(6.0, abs=1e-6)
    assert p.walls(6.0, hs)["top"] == pytest.approx(5.7)
    assert p.walls(7.0, hs)["top"] == pytest.approx(5.4)
    areas = []
    for t in np.linspace(7.05, 11.0, 9):
        w = p.walls(t, hs)
        gamma = 0.2 * (t - 7.0) / 4.0
        assert p.phase(t) == "shear" and p.shear(t) == pytest.approx(gamma)
        assert w["right"] - w["left"] == pytest.approx(10.0 * np.exp(gamma / 2))
        assert w["left"] + w["right"] == pytest.approx(10.0)  # symmetric about the centre
        areas.append((w["right"] - w["left"]) * (w["top"] - w["bottom"]))
    assert np.ptp(areas) < 1e-12 * areas[0] and areas[0] == pytest.approx(10.0 * 5.4)
    assert p.shear(20.0) == 0.2 and p.t_end == 11.0


def test_stresses_and_contact_statistics():
    walls = dict(left=0.0, right=4.0, bottom=0.0, top=2.0)
    sxx, syy, ratio = column.stresses(walls, dict(left=2.0, right=6.0, bottom=10.0, top=6.0))
    assert (sxx, syy, ratio) == (2.0, 2.0, 1.0)  # (2 + 6) / (2 * 2), (10 + 6) / (2 * 4)
    assert column.stresses(walls, dict(left=0.0, right=0.0, bottom=1.0, top=0.0))[2] is None
    s = column.contact_statistics([1.0, 3.0, 0.0, -1e-9], 4)
    assert s == dict(contacts=2, coordination=1.0, force_mean=2.0, force_cv=0.5)
    assert column.contact_statistics([], 3)["force_cv"] == 0.0
    p = column.Protocol(np.array([[0.0, 0.0], [4.0, 2.0]]), 1.0, 1.0, 1.0, 0.0, 0.1)
    sample = SimpleNamespace(radius=np.array([0.4, 0.6, 0.5, 0.5]))  # mean diameter 1
    row = column.row(p, 0.5, walls, dict(left=2.0, right=6.0, bottom=10.0, top=6.0), [1.0, 3.0],
                     sample, 0.25)  # fmt: skip
    assert set(row) == set(column.COLUMNS)  # write_table orders them
    # force mean 2 over p d = ((2 + 2) / 2) * 1
    assert row["force_mean_pd"] == pytest.approx(1.0, rel=1e-15)
    assert column.scaled_force_mean(2.0, 0.0, 0.0, 1.0) is None  # no wall loaded yet
    assert row["phase"] == "deposition" and row["stress_ratio"] == 1.0 and row["contacts"] == 2
