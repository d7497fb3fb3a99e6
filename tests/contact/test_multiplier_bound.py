"""benchmarks/multiplier_bound.py: the best-approximation floor of a multiplier space."""

import numpy as np
import pytest

from benchmarks.multiplier_bound import best_approximation


@pytest.mark.parametrize("degree", [1, 2])
def test_exact_in_the_space(degree):
    """A continuous piecewise linear function with kinks on element ends is in the space."""
    hat = lambda x: np.maximum(0.0, 1.0 - np.abs(x))  # noqa: E731
    # the error comes from |f|^2 - b.c: half the digits of round-off
    assert best_approximation(degree, 0.25, 0.0, f=hat, kinks=(-1.0, 0.0, 1.0)) < 1e-7
    # a kink inside an element is not: the error is that of the kink's element
    assert best_approximation(1, 0.25, 0.1, f=hat, kinks=(-1.0, 0.0, 1.0)) > 1e-3


def test_first_order_at_the_edge():
    """The square-root edge limits P1 to first order in L2: halving H halves the error (over
    offsets); the floor at h = a/20 is the figure quoted in issue 11's note (1.03-1.11 %)."""
    h = 1.0 / 20
    e = [[best_approximation(1, H, o) for o in np.linspace(0, H, 6)[:-1]] for H in (h, h / 2)]
    assert 1.02e-2 < min(e[0]) < max(e[0]) < 1.12e-2
    assert 0.4 < np.mean(e[1]) / np.mean(e[0]) < 0.6
