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


def segments(q, seg):
    """Piecewise-constant multipliers: point p on node seg[p] alone (labels made 0..m-1)."""
    seg = np.unique(seg, return_inverse=True)[1].ravel()
    n = len(seg)
    q.set_multiplier_nodes(np.c_[seg, np.full(n, -1)], np.c_[np.ones(n), np.zeros(n)])


def hats(q, rng, elements):
    """Piecewise-linear multipliers: point p between nodes e and e + 1 (every element holds a
    point). Returns (nodes, weights)."""
    e = np.r_[np.arange(elements), rng.integers(0, elements, len(q) - elements)]
    theta = rng.uniform(0.05, 0.95, len(q))
    nodes, weights = np.c_[e, e + 1], np.c_[1 - theta, theta]
    q.set_multiplier_nodes(nodes, weights)
    return nodes, weights


@pytest.mark.parametrize("multipliers", ["points", "segments", "hats"])
@pytest.mark.parametrize("mu", [0.0, 0.4])
def test_tangent_equals_finite_differences(mu, multipliers):
    """Point-wise, with the points grouped into segments (one traction per segment from its
    mean gaps), and with hat functions (two nodes per point): the tangent couples all dofs of
    a node's points."""
    rng = np.random.default_rng(3)
    q = make_quadrature(rng, nq=40 if multipliers == "points" else 120)
    if multipliers == "segments":
        segments(q, rng.integers(0, 40, len(q)))
    elif multipliers == "hats":
        hats(q, rng, 30)
    law = (1e-2, 2e-2, mu)
    u = rng.uniform(-0.02, 0.02, 2 * NNODES)
    gtp = rng.uniform(-0.01, 0.01, q.num_law_points) if mu > 0 else np.zeros(0)
    K, b, s = dense_tangent(q, law, u, gtp)
    states = np.bincount(s["law_state"], minlength=3)
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
    theta = np.random.default_rng(5).uniform(0, 2 * np.pi, len(q))  # make_quadrature's normals
    n = np.c_[np.cos(theta), np.sin(theta)]
    t = np.c_[-n[:, 1], n[:, 0]]
    w = q.weights[:, None]
    traction = np.sum(w * (s["tau_n"][:, None] * n + s["tau_t"][:, None] * t), axis=0)
    np.testing.assert_allclose(fj, traction, rtol=1e-12, atol=1e-12 * np.abs(traction).max())
    assert np.abs(fj).max() > 0


def test_mu_zero_touches_no_history():
    rng = np.random.default_rng(7)
    q = make_quadrature(rng)
    u = rng.uniform(-0.02, 0.02, 2 * NNODES)
    s = _cpp.assemble_contact(q, 1e-2, 1e-2, 0.0, u, np.zeros(0))
    assert s["gtp_trial"] is None
    assert np.all(s["tau_t"] == 0)


def test_node_traction_is_the_law_of_its_mean_gap():
    """A node's traction is Algorithm 1 on the psi-weighted mean of its points' gaps (plus
    the augmented Lagrangian's shift); a point's traction is sum psi tau of its nodes; the
    residual is sum_p w_p B_p^T tau_p; single-point nodes reproduce the point-wise kernel."""
    rng = np.random.default_rng(11)
    q = make_quadrature(rng, nq=30)
    u = rng.uniform(-0.02, 0.02, 2 * NNODES)
    eps_n, eps_t, mu = 1e-2, 2e-2, 0.3
    point = _cpp.assemble_contact(q, eps_n, eps_t, mu, u, np.zeros(30))
    b_point = residual(q, (eps_n, eps_t, mu), u, np.zeros(30))
    segments(q, np.arange(30))
    single = _cpp.assemble_contact(q, eps_n, eps_t, mu, u, np.zeros(30))
    np.testing.assert_array_equal(single["tau_n"], point["tau_n"])
    np.testing.assert_array_equal(residual(q, (eps_n, eps_t, mu), u, np.zeros(30)), b_point)

    nodes, w = hats(q, rng, 7)
    shift = rng.uniform(-0.01, 0, 8)
    s = _cpp.assemble_contact(q, eps_n, eps_t, mu, u, np.zeros(8), g_n_shift=shift)
    W = q.weights[:, None] * w
    for a in range(8):
        m = W * (nodes == a)
        gn = np.sum(m.sum(1) * point["g_n"]) / m.sum() + shift[a]
        gt = np.sum(m.sum(1) * point["g_t"]) / m.sum()
        tn = min(gn, 0.0) / eps_n
        np.testing.assert_allclose(s["law_tau_n"][a], tn, rtol=1e-12, atol=1e-300)
        tt = gt / eps_t if tn < 0 else 0.0
        tt = tt if abs(tt) <= mu * abs(tn) else mu * abs(tn) * np.sign(tt)
        np.testing.assert_allclose(s["law_tau_t"][a], tt, rtol=1e-12, atol=1e-300)
    tau_p = np.sum(w * s["law_tau_n"][nodes], axis=1)
    np.testing.assert_allclose(s["tau_n"], tau_p, rtol=1e-12, atol=1e-300)
    np.testing.assert_array_equal(s["g_n"], point["g_n"])  # the points' own gaps
    assert np.any(s["law_tau_n"] < 0) and np.any(s["law_tau_n"] == 0)
    blocks = q.coupling_dofs()
    assert len(blocks) == 8 and all(len(np.unique(b)) == len(b) for b in blocks)
    with pytest.raises(ValueError, match="sum to 1"):
        q.set_multiplier_nodes(np.zeros((30, 2), np.int32), np.full((30, 2), 0.7))
