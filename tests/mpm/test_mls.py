"""MLS projection (eqs 38-45) through the binding: linear reproduction, second order, widening."""

import numpy as np
import pytest

from dolfinx_forms._cpp import MLSProjector, quadratic_spline_weight

G = np.sqrt(0.6) / 2
GAUSS = np.array([0.5 - G, 0.5, 0.5 + G])


def gauss_cloud(dim, n, jitter, rng):
    """3^dim Gauss points per cell of [0, 1]^dim (n cells per direction), each coordinate moved
    by up to +-jitter h: material points after a small deformation (~3 points per h)."""
    idx = np.meshgrid(*([np.arange(n)] * dim + [GAUSS] * dim), indexing="ij")
    x = np.stack([(idx[a] + idx[dim + a]).ravel() for a in range(dim)], axis=1)
    return (x + rng.uniform(-jitter, jitter, x.shape)) / n


def test_spline_weight():
    r = np.array([0.0, 0.25, 0.5, 1.0, 1.5, 2.0, -1.0])
    expected = [0.75, 0.6875, 0.5, 0.125, 0.0, 0.0, 0.125]
    np.testing.assert_allclose(quadratic_spline_weight(r), expected, rtol=0, atol=1e-15)
    assert quadratic_spline_weight(r.reshape(7, 1)).shape == (7, 1)


@pytest.mark.parametrize("dim", [2, 3])
def test_linear_fields_reproduced(dim):
    # Linear fields lie in the basis: exact up to round-off (measured ~1e-15 relative).
    rng = np.random.default_rng(dim)
    n = 10 if dim == 2 else 5
    src = gauss_cloud(dim, n, 0.15, rng)
    tgt = np.vstack([rng.uniform(0, 1, (200, dim)), src[:50]])
    grad = np.array([[1.0, -2.0, 0.5], [3.0, 1e3, -7.0]])[:, :dim]
    field = lambda x: np.c_[1 + x @ grad[0], -4 + x @ grad[1]]  # noqa: E731
    mls = MLSProjector(src, h=1.0 / n)
    assert mls.num_points == len(src)
    r = mls.project(field(src), tgt)
    exact = field(tgt)
    assert r["values"].shape == exact.shape
    assert np.max(np.abs(r["values"] - exact) / np.maximum(1, np.abs(exact))) < 1e-12
    assert r["neighbours"].dtype == np.int32 and np.all(r["neighbours"] >= dim + 1)
    assert np.all(r["rcond"] >= 1e-8) and np.all(r["widening"] >= 1)
    # A single field (n,) gives (k,) values, the same as column 0.
    r1 = mls.project(np.ascontiguousarray(field(src)[:, 0]), tgt)
    assert r1["values"].shape == (len(tgt),)
    np.testing.assert_array_equal(r1["values"], r["values"][:, 0])


def test_quadratic_field_second_order():
    # RMS error of the linear fit of a quadratic field ~ h^2 (2.0-2.1 measured; 1.8 leaves
    # room for the random jitter changing the error constant between levels).
    rng = np.random.default_rng(0)
    tgt = rng.uniform(0, 1, (500, 2))
    f = lambda x: x[:, 0] ** 2 + 0.7 * x[:, 0] * x[:, 1] - 0.5 * x[:, 1] ** 2 + x[:, 0]  # noqa
    errs = []
    for n in [8, 16, 32, 64]:
        src = gauss_cloud(2, n, 0.15, rng)
        r = MLSProjector(src, 1.0 / n).project(f(src), tgt)
        errs.append(np.sqrt(np.mean((r["values"] - f(tgt)) ** 2)))
    rates = np.log2(np.array(errs[:-1]) / errs[1:])
    assert np.all(rates > 1.8), rates


def test_collinear_neighbours_widened_then_error():
    # Within 1.5 h of the targets the sources are collinear; two sources 2 h off the line are
    # reached by one widening (2.25 h).
    h = 0.1
    line = np.c_[np.arange(-9, 10) * h / 3, np.zeros(19)]
    src = np.vstack([line, [[0.0, 2 * h], [0.05, -2 * h]]])
    tgt = np.array([[0.01, 0.0], [0.02, 0.03]])
    f = lambda x: 2 - x[:, 0] + 3 * x[:, 1]  # noqa: E731
    r = MLSProjector(src, h).project(f(src), tgt)
    np.testing.assert_array_equal(r["widening"], [1.5, 1.5])
    np.testing.assert_allclose(r["values"], f(tgt), atol=1e-12)
    with pytest.raises(RuntimeError, match=r"target 0 at \(0, 0\)"):
        MLSProjector(line, h).project(f(line), np.array([[0.0, 0.0], [0.3, 5.0]]))


def test_far_target_raises_with_index():
    src = gauss_cloud(2, 4, 0.1, np.random.default_rng(1))
    mls = MLSProjector(src, 0.25)
    with pytest.raises(RuntimeError, match=r"target 2 at \(10, -4\)"):
        mls.project(np.ones(len(src)), np.array([[0.5, 0.5], [0.2, 0.3], [10.0, -4.0]]))


def test_bad_input_value_error():
    src = gauss_cloud(2, 2, 0.0, np.random.default_rng(0))
    with pytest.raises(ValueError, match="sources"):
        MLSProjector(np.zeros((10, 4)), 0.5)
    with pytest.raises(ValueError, match="sources"):
        MLSProjector(src.ravel(), 0.5)
    with pytest.raises(ValueError, match="h must"):
        MLSProjector(src, 0.0)
    with pytest.raises(ValueError, match="h must"):
        MLSProjector(src, np.inf)
    bad = src.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match="sources"):
        MLSProjector(bad, 0.5)
    mls = MLSProjector(src, 0.5)
    with pytest.raises(ValueError, match="values"):
        mls.project(np.ones(len(src) + 1), np.zeros((1, 2)))
    with pytest.raises(ValueError, match="values"):
        mls.project(np.ones((len(src), 2, 2)), np.zeros((1, 2)))
    with pytest.raises(ValueError, match="targets"):
        mls.project(np.ones(len(src)), np.zeros((1, 3)))
    with pytest.raises(ValueError, match="targets"):
        mls.project(np.ones(len(src)), np.array([[0.5, np.nan]]))
