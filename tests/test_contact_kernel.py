"""The contact kernel of eq 48 against finite differences of its own residual.

Random point data (weights, normals, basis values, dofs) and displacements chosen so that
open, stick and slip points are all present; the exact consistent tangent (Algorithm 1 with
d tau/d g) must equal central differences of the assembled residual to 1e-6 relative, and
the kernel's own finite-difference mode must agree with it as well.
"""

import numpy as np
import pytest
from petsc4py import PETSc

from dolfinx_forms import _cpp

NNODES = 12  # nodes of the toy "mesh" (block size 2)


def make_quadrature(rng, nq=40, ni=3, nj=4):
    theta = rng.uniform(0, 2 * np.pi, nq)
    n = np.c_[np.cos(theta), np.sin(theta)]
    t = np.c_[-n[:, 1], n[:, 0]]
    dofs_i = np.array([rng.choice(NNODES // 2, ni, replace=False) for _ in range(nq)], np.int32)
    dofs_j = np.array(
        [NNODES // 2 + rng.choice(NNODES // 2, nj, replace=False) for _ in range(nq)], np.int32
    )
    bi = rng.uniform(0.1, 1, (nq, ni))
    bj = rng.uniform(0.1, 1, (nq, nj))
    bi /= bi.sum(1, keepdims=True)
    bj /= bj.sum(1, keepdims=True)
    g0 = rng.uniform(-0.02, 0.02, nq)
    q = _cpp.ContactQuadrature(rng.uniform(0.5, 1, nq), n, t, g0, dofs_i, dofs_j, bi, bj)
    return q


def dense_tangent(q, law, u, gtp, fd=False):
    A = PETSc.Mat().createAIJ(
        (2 * NNODES, 2 * NNODES), bsize=2, nnz=2 * NNODES, comm=PETSc.COMM_SELF
    )
    lg = PETSc.LGMap().create(np.arange(NNODES, dtype=np.int32), bsize=2, comm=PETSc.COMM_SELF)
    A.setLGMap(lg, lg)
    A.setUp()
    _cpp.add_coupling_zeros(A, q)
    A.assemble()
    b = np.zeros_like(u)
    s = _cpp.assemble_contact(q, *law, u, gtp, b, A, fd, 1e-9)
    A.assemble()
    return A.convert("dense").getDenseArray().copy(), b, s


def residual(q, law, u, gtp):
    b = np.zeros_like(u)
    _cpp.assemble_contact(q, *law, u, gtp, b)
    return b


@pytest.mark.parametrize("segmented", [False, True])
@pytest.mark.parametrize("mu", [0.0, 0.4])
def test_tangent_equals_finite_differences(mu, segmented):
    """Point-wise, and with the points grouped into segments of 1 to 4 points (one traction
    per segment from its mean gaps): the tangent couples all dofs of a segment."""
    rng = np.random.default_rng(3)
    q = make_quadrature(rng, nq=120 if segmented else 40)
    if segmented:
        q.segments = np.sort(rng.integers(0, 40, len(q))).astype(np.int32)
    law = (1e-2, 2e-2, mu)
    u = rng.uniform(-0.02, 0.02, 2 * NNODES)
    gtp = rng.uniform(-0.01, 0.01, len(q)) if mu > 0 else np.zeros(0)
    if segmented and mu > 0:  # one committed slip per segment, as the solver keeps it
        gtp = gtp[np.searchsorted(q.segments, q.segments)]
    K, b, s = dense_tangent(q, law, u, gtp)
    states = np.bincount(s["state"], minlength=3)
    if mu > 0:
        assert np.all(states > 0), f"open/stick/slip all needed, got {states}"
    else:
        assert states[0] > 0 and states[2] > 0
    # Central differences of the assembled residual, column by column
    h = 1e-7
    K_fd = np.zeros_like(K)
    for c in range(len(u)):
        e = np.zeros_like(u)
        e[c] = h
        K_fd[:, c] = (residual(q, law, u + e, gtp) - residual(q, law, u - e, gtp)) / (2 * h)
    scale = np.abs(K).max()
    assert np.abs(K - K_fd).max() <= 1e-6 * scale
    # The kernel's own FD mode (verification option of the solver) agrees too
    K_kfd, b2, _ = dense_tangent(q, law, u, gtp, fd=True)
    assert np.abs(K - K_kfd).max() <= 1e-6 * scale
    np.testing.assert_array_equal(b, b2)
    if mu > 0:  # the slip branch makes the tangent non-symmetric
        assert np.abs(K - K.T).max() > 1e-3 * scale


def test_residual_is_weighted_traction():
    """Sum of the contact residual over body j equals int tau_n n + tau_t t (action-reaction:
    body i gets the opposite), since the basis values of each side sum to one."""
    rng = np.random.default_rng(5)
    q = make_quadrature(rng)
    u = rng.uniform(-0.02, 0.02, 2 * NNODES)
    gtp = rng.uniform(-0.01, 0.01, len(q))
    b = np.zeros_like(u)
    s = _cpp.assemble_contact(q, 1e-2, 2e-2, 0.4, u, gtp, b)
    b = b.reshape(-1, 2)
    fi, fj = b[: NNODES // 2].sum(0), b[NNODES // 2 :].sum(0)
    np.testing.assert_allclose(fi, -fj, atol=1e-12)
    assert np.abs(fj).max() > 0


def test_mu_zero_touches_no_history():
    rng = np.random.default_rng(7)
    q = make_quadrature(rng)
    u = rng.uniform(-0.02, 0.02, 2 * NNODES)
    s = _cpp.assemble_contact(q, 1e-2, 1e-2, 0.0, u, np.zeros(0))
    assert s["gtp_trial"] is None
    assert np.all(s["tau_t"] == 0)


def test_segment_traction_is_the_law_of_its_mean_gap():
    """A segment's traction is Algorithm 1 on the weighted mean of its points' gaps (plus the
    augmented Lagrangian's shift), the same on all its points; its residual is the sum of the
    points' w B^T tau; single-point segments reproduce the point-wise kernel exactly."""
    rng = np.random.default_rng(11)
    q = make_quadrature(rng, nq=30)
    u = rng.uniform(-0.02, 0.02, 2 * NNODES)
    gtp = np.zeros(len(q))
    eps_n, eps_t, mu = 1e-2, 2e-2, 0.3
    point = _cpp.assemble_contact(q, eps_n, eps_t, mu, u, gtp)
    b_point = residual(q, (eps_n, eps_t, mu), u, gtp)
    q.segments = np.arange(len(q), dtype=np.int32)
    single = _cpp.assemble_contact(q, eps_n, eps_t, mu, u, gtp)
    np.testing.assert_array_equal(single["tau_n"], point["tau_n"])
    np.testing.assert_array_equal(residual(q, (eps_n, eps_t, mu), u, gtp), b_point)

    q.segments = np.repeat(np.arange(10), 3).astype(np.int32)
    shift = np.repeat(rng.uniform(-0.01, 0, 10), 3)
    s = _cpp.assemble_contact(q, eps_n, eps_t, mu, u, gtp, g_n_shift=shift)
    w = q.weights
    for k in range(10):
        sl = slice(3 * k, 3 * k + 3)
        gn = np.sum(w[sl] * point["g_n"][sl]) / w[sl].sum() + shift[3 * k]
        gt = np.sum(w[sl] * point["g_t"][sl]) / w[sl].sum()
        tn = min(gn, 0.0) / eps_n
        np.testing.assert_allclose(s["tau_n"][sl], tn, rtol=1e-12, atol=1e-300)
        if tn < 0:
            tt = gt / eps_t
            tt = tt if abs(tt) <= mu * abs(tn) else mu * abs(tn) * np.sign(tt)
            np.testing.assert_allclose(s["tau_t"][sl], tt, rtol=1e-12)
        np.testing.assert_array_equal(s["g_n"][sl], point["g_n"][sl])  # the points' own gaps
    assert np.any(s["tau_n"] < 0) and np.any(s["tau_n"] == 0)
    blocks = q.coupling_dofs()
    assert len(blocks) == 10 and all(len(np.unique(b)) == len(b) for b in blocks)
    with pytest.raises(ValueError, match="non-decreasing"):
        q.segments = np.arange(len(q), dtype=np.int32)[::-1].copy()
