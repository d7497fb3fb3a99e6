"""Broad phase (_cpp.candidate_pairs, _cpp.candidate_pairs_between; issue 13 item 1): the
sort-and-sweep pairs equal an O(n^2) numpy reference exactly (same inflated doubles, closed
boxes), touching counts, empty and bad input, and a timing measurement on grain packings
(printed with -s; the only assertion there is on the pair count, never on time).

Run the timing table alone: /usr/bin/python3 tests/geometry/test_broad_phase.py
"""


import numpy as np
import pytest
from dolfinx_forms import _cpp
from meshes.grains import lattice_boxes


def brute_force(boxes, inflate=0.0):
    """All pairs i < j whose inflated closed boxes overlap; boxes (n, 2, d)."""
    lo, hi = boxes[:, 0] - inflate, boxes[:, 1] + inflate
    ov = np.all((lo[:, None] <= hi[None]) & (lo[None] <= hi[:, None]), axis=2)
    i, j = np.nonzero(np.triu(ov, 1))
    return np.column_stack([i, j]).astype(np.int32)


def brute_force_between(a, b, inflate=0.0):
    la, ha, lb, hb = a[:, 0] - inflate, a[:, 1] + inflate, b[:, 0] - inflate, b[:, 1] + inflate
    ov = np.all((la[:, None] <= hb[None]) & (lb[None] <= ha[:, None]), axis=2)
    i, j = np.nonzero(ov)
    return np.column_stack([i, j]).astype(np.int32)


def random_boxes(rng, n, d):
    """n boxes in [0, n^(1/d)]^d with sides in [0, 1.5): a few neighbours each."""
    lo = rng.uniform(0, max(n, 1) ** (1 / d), size=(n, d))
    side = rng.uniform(0, 1.5, size=(n, d))
    side[::13] = 0.0  # some point boxes
    return np.stack([lo, lo + side], axis=1)


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_matches_brute_force(d, seed):
    rng = np.random.default_rng(seed)
    total = 0
    for n in [0, 1, 2, 3, 10, 57, 200, 500]:
        b = random_boxes(rng, n, d)
        for inflate in [0.0, 0.05]:
            ref = brute_force(b, inflate)
            got = _cpp.candidate_pairs(b, inflate=inflate)
            assert got.dtype == np.int32 and got.shape == (len(ref), 2)
            np.testing.assert_array_equal(got, ref)  # ref is lexicographic by construction
            # The flat (n, 2 d) layout is the same boxes.
            np.testing.assert_array_equal(_cpp.candidate_pairs(b.reshape(n, 2 * d), inflate), ref)
            total += len(ref)
    assert total > 500  # the sets do produce pairs


def test_plates_among_grains():
    """Boxes much larger than the median (rigid plates around an assembly) span many cells of
    the sweep grid: every pair is still reported once."""
    rng = np.random.default_rng(3)
    grains = random_boxes(rng, 400, 2)
    L = 20.0
    plates = np.array(
        [
            [[-1, -1], [L + 1, 0.2]],
            [[-1, L - 0.2], [L + 1, L + 1]],
            [[-1, -1], [0.2, L + 1]],
            [[L - 0.2, -1], [L + 1, L + 1]],
        ]
    )
    b = np.concatenate([grains, plates])
    np.testing.assert_array_equal(_cpp.candidate_pairs(b, 0.01), brute_force(b, 0.01))
    np.testing.assert_array_equal(
        _cpp.candidate_pairs_between(grains, plates, 0.01),
        brute_force_between(grains, plates, 0.01),
    )


@pytest.mark.parametrize("d", [2, 3])
def test_between_matches_brute_force(d):
    rng = np.random.default_rng(5)
    for na, nb in [(0, 3), (3, 0), (1, 1), (50, 4), (300, 40), (200, 200)]:
        a, b = random_boxes(rng, na, d), random_boxes(rng, nb, d)
        k = min(na, nb)
        b[:k:2, 0] = a[:k:2, 0]  # equal lower bounds: the tie rule of the merged sweep
        b[:k:2, 1] = np.maximum(b[:k:2, 1], b[:k:2, 0])
        for inflate in [0.0, 0.1]:
            np.testing.assert_array_equal(
                _cpp.candidate_pairs_between(a, b, inflate), brute_force_between(a, b, inflate)
            )


def test_touching_counts():
    # Unit squares sharing an edge, a corner, or one apart.
    b = np.array([[[0, 0], [1, 1]], [[1, 0], [2, 1]], [[2, 1], [3, 2]], [[5, 5], [6, 6]]], float)
    np.testing.assert_array_equal(_cpp.candidate_pairs(b), [[0, 1], [1, 2]])
    # 5 x 5 lattice of touching unit squares: 8-neighbourhood pairs = 2 * 5 * 4 + 2 * 4 * 4.
    ij = np.stack(np.meshgrid(np.arange(5.0), np.arange(5.0)), -1).reshape(-1, 2)
    lat = np.stack([ij, ij + 1], axis=1)
    assert len(_cpp.candidate_pairs(lat)) == 72
    # Gap 0.5 between two boxes: inflate 0.25 (exact in binary) closes it, 0.2499 does not.
    two = np.array([[0, 0, 1, 1], [1.5, 0, 2.5, 1]], float)
    assert len(_cpp.candidate_pairs(two, 0.2499)) == 0
    np.testing.assert_array_equal(_cpp.candidate_pairs(two, 0.25), [[0, 1]])
    np.testing.assert_array_equal(_cpp.candidate_pairs_between(two[:1], two[1:], 0.25), [[0, 0]])


def test_empty_and_layouts():
    for shape in [(0, 4), (0, 2, 2), (0, 2, 3), (1, 4)]:
        p = _cpp.candidate_pairs(np.zeros(shape))
        assert p.shape == (0, 2) and p.dtype == np.int32
    assert _cpp.candidate_pairs_between(np.zeros((0, 4)), np.zeros((3, 4))).shape == (0, 2)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: _cpp.candidate_pairs(np.array([[0, np.nan, 1, 1]])), "boxes"),
        (lambda: _cpp.candidate_pairs(np.array([[0, 0, np.inf, 1]])), "boxes"),
        (lambda: _cpp.candidate_pairs(np.array([[0, 2, 1, 1.0]])), "lo > hi"),
        (lambda: _cpp.candidate_pairs(np.zeros((3, 3))), "boxes"),
        (lambda: _cpp.candidate_pairs(np.zeros(4)), "boxes"),
        (lambda: _cpp.candidate_pairs(np.zeros((2, 4)), inflate=-1.0), "inflate"),
        (lambda: _cpp.candidate_pairs(np.zeros((2, 4)), inflate=np.nan), "inflate"),
        (lambda: _cpp.candidate_pairs_between(np.zeros((1, 4)), np.zeros((1, 6))), "boxes_b"),
        (
            lambda: _cpp.candidate_pairs_between(np.array([[1.0, 0, 0, 1]]), np.zeros((1, 4))),
            "boxes_a",
        ),
        (lambda: _cpp.candidate_pairs_between(np.zeros((1, 4)), np.zeros((1, 4)), -0.1), "inflate"),
    ],
)
def test_bad_input(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_grain_packing_matches_reference():
    """Jittered lattices of grain boxes (benchmarks/broad_phase.py times them): pairs equal the
    reference up to N = 1600, and pairs <= 4 N (each grain meets at most its 8 neighbours)."""
    rng = np.random.default_rng(0)
    for n in (25, 100, 400, 1600):
        b = lattice_boxes(n, rng)
        p = _cpp.candidate_pairs(b, 0.02)
        assert len(p) <= 4 * n
        np.testing.assert_array_equal(p, brute_force(b, 0.02))
