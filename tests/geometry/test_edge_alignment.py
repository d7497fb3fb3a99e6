"""The P1 multiplier nodes aligned with the contact edges (`pairs.edge_aligned_ends`,
`PairGeometry.contact_zones`, `multiplier_nodes` with zones): pure numerics on one straight
chain, no mesh."""

import numpy as np
import pytest

from dolfinx_forms.geometry.pairs import PairGeometry, edge_aligned_ends, multiplier_nodes

OFFSET = 0.27


@pytest.mark.parametrize("sL,sR", [(2.13, 5.71), (0.9, 7.05), (3.0, 3.9)])
def test_the_first_node_outside_each_edge_lies_offset_elements_past_it(sL, sR):
    L, length = 8.0, 0.3
    E = edge_aligned_ends(L, length, [(sL, sR)], OFFSET)
    assert E[0] == 0.0 and E[-1] == L and np.all(np.diff(E) > 0.25 * length - 1e-12)
    inside = E[(E >= sL) & (E <= sR)]
    el = np.diff(inside)
    assert np.allclose(el, el[0], rtol=1e-12, atol=0)  # equal elements over the zone
    assert abs(el[0] - length) <= 0.5 * length  # about the requested spacing
    below, above = E[E < sL].max(), E[E > sR].min()
    assert sL - below == pytest.approx(OFFSET * el[0], rel=1e-12)
    assert above - sR == pytest.approx(OFFSET * el[0], rel=1e-12)
    # elsewhere elements of about `length`
    assert np.all(np.diff(E) <= 1.5 * length + 1e-12)


def test_zones_reaching_the_chain_ends_and_two_zones():
    L, length = 10.0, 0.4
    E = edge_aligned_ends(L, length, [(None, 2.02), (6.31, None)], OFFSET)
    assert E[0] == 0.0 and E[-1] == L and np.all(np.diff(E) > 0)
    el0 = np.diff(E[E <= 2.02])
    assert np.allclose(el0, el0[0], rtol=1e-12, atol=0)
    assert E[E > 2.02].min() - 2.02 == pytest.approx(OFFSET * el0[0], rel=1e-12)
    el1 = np.diff(E[E >= 6.31])
    assert np.allclose(el1, el1[0], rtol=1e-12, atol=0)
    assert 6.31 - E[E < 6.31].max() == pytest.approx(OFFSET * el1[0], rel=1e-12)


def _chain(n=400, L=8.0):
    """Points along one straight chain of length L: (positions, arc lengths)."""
    s = (np.arange(n) + 0.5) * L / n
    return (np.zeros(n, np.int64), s, np.array([L])), s


def test_aligned_nodes_reproduce_p1_fields_and_keep_the_partition_of_unity():
    positions, s = _chain()
    length, zones = 0.3, {0: [(2.13, 5.71)]}
    nodes, w = multiplier_nodes(None, "P1", length, 0.0, positions, zones, OFFSET)
    assert np.allclose(w.sum(axis=1), 1.0, atol=1e-14)
    E = edge_aligned_ends(8.0, length, zones[0], OFFSET)
    # a P1 field on the aligned ends comes back exactly at the points
    f = np.sin(E)
    fp = np.sum(np.where(nodes >= 0, w * f[np.maximum(nodes, 0)], 0.0), axis=1)
    assert np.allclose(fp, np.interp(s, E, f), atol=1e-13)
    # without zones: the equal elements of before
    n0, w0 = multiplier_nodes(None, "P1", length, 0.0, positions)
    assert nodes.max() + 1 == len(E) and n0.max() + 1 == round(8.0 / length) + 1


def test_contact_zones_are_the_zero_crossings_of_the_gap():
    positions, s = _chain()
    g = PairGeometry.__new__(PairGeometry)
    g.layout = ("P1", 0.3, positions)
    gap = (s - 2.2) * (s - 5.6)  # closed (< 0) on (2.2, 5.6)
    zones = g.contact_zones(gap, 0.6)
    ((sL, sR),) = zones[0]
    # linear interpolation between the points (spacing 0.02) of a parabola: O(spacing^2)
    assert abs(sL - 2.2) < 1e-3 and abs(sR - 5.6) < 1e-3
    # zones shorter than min_length are left out; one running to the chain's end has None
    assert g.contact_zones(gap, 4.0) == {}
    (z,) = g.contact_zones(s - 6.0, 0.6)[0]
    assert z[0] is None and abs(z[1] - 6.0) < 1e-12
