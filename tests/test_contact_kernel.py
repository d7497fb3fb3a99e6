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


@pytest.mark.parametrize("mu", [0.0, 0.4])
def test_tangent_equals_finite_differences(mu):
    rng = np.random.default_rng(3)
    q = make_quadrature(rng)
    law = (1e-2, 2e-2, mu)
    u = rng.uniform(-0.02, 0.02, 2 * NNODES)
    gtp = rng.uniform(-0.01, 0.01, len(q)) if mu > 0 else np.zeros(0)
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
