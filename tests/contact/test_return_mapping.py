# Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
"""Python-side checks of the penalty Coulomb return mapping (Algorithm 1; eqs 8, 11, 12), its
consistent tangent, the friction history and the gap functions (eqs 26-31)."""

import numpy as np
import pytest

from dolfinx_forms import _cpp

OPEN, STICK, SLIP = 0, 1, 2


def reference(g_n, g_t, gtp_old, eps_n, eps_t, mu):
    """Straightforward numpy restatement of Algorithm 1 with the tangent of the C++ header.

    g_t and gtp_old have shape (n, tdim)."""
    n, tdim = g_t.shape
    active = g_n < 0
    tau_n = np.where(active, g_n / eps_n, 0.0)
    tau_tr = (g_t - gtp_old) / eps_t
    norm = np.linalg.norm(tau_tr, axis=1)
    phi_tr = norm - mu * np.abs(tau_n)
    slip = active & ((phi_tr > 0) | (mu == 0))
    stick = active & ~slip
    state = np.where(slip, SLIP, np.where(stick, STICK, OPEN)).astype(np.int8)

    m = tau_tr / np.where(norm > 0, norm, 1.0)[:, None]
    tau_t = np.where(stick[:, None], tau_tr, 0.0)
    tau_t = np.where(slip[:, None], mu * np.abs(tau_n)[:, None] * m, tau_t)
    gtp = np.where(stick[:, None], gtp_old, g_t)  # open and mu == 0: slip follows the gap
    if mu > 0:
        gtp = np.where(slip[:, None], gtp_old + eps_t * phi_tr[:, None] * m, gtp)

    D = np.zeros((n, 1 + tdim, 1 + tdim))
    D[active, 0, 0] = 1.0 / eps_n
    eye = np.eye(tdim)
    D[stick, 1:, 1:] = eye / eps_t
    if mu > 0:
        c = mu * np.abs(tau_n[slip]) / (eps_t * norm[slip])
        ms = m[slip]
        D[slip, 1:, 0] = -mu / eps_n * ms
        D[slip, 1:, 1:] = c[:, None, None] * (eye - ms[:, :, None] * ms[:, None, :])
    return dict(tau_n=tau_n, tau_t=tau_t, gtp_trial=gtp, state=state, tangent=D)


def random_states(rng, n, tdim, eps_n, eps_t, mu, gtp_scale=1.0):
    """Gaps giving |tau_n| = O(1) and |tau_tr| = O(mu), so that stick, slip and open are all
    frequent."""
    g_n = eps_n * rng.uniform(-2, 2, n)
    gtp = gtp_scale * 5.0 * rng.uniform(-1, 1, (n, tdim))
    g_t = gtp + eps_t * (mu if mu > 0 else 1.0) * rng.uniform(-2, 2, (n, tdim))
    return g_n, g_t, gtp


def call(g_n, g_t, gtp, eps_n, eps_t, mu, tdim):
    """Call the binding with the 2D convention (1-D tangential arrays) when tdim == 1."""
    if tdim == 1:
        r = _cpp.return_mapping(g_n, g_t[:, 0], gtp[:, 0], eps_n, eps_t, mu)
        assert r["tau_t"].shape == (len(g_n),)
        return dict(r, tau_t=r["tau_t"][:, None], gtp_trial=r["gtp_trial"][:, None])
    return _cpp.return_mapping(g_n, g_t, gtp, eps_n, eps_t, mu)


@pytest.mark.parametrize("tdim", [1, 2])
@pytest.mark.parametrize(
    "eps_n, eps_t, mu", [(0.5, 0.25, 0.5), (1e-3, 2e2, 1.2), (3e2, 1e-2, 0.05), (1.0, 1.0, 0.0)]
)
def test_matches_numpy_reference(tdim, eps_n, eps_t, mu):
    rng = np.random.default_rng(1234 + tdim)
    n = 1000
    g_n, g_t, gtp = random_states(rng, n, tdim, eps_n, eps_t, mu)
    r = call(g_n, g_t, gtp, eps_n, eps_t, mu, tdim)
    ref = reference(g_n, g_t, gtp, eps_n, eps_t, mu)

    assert r["state"].dtype == np.int8 and r["state"].shape == (n,)
    assert r["tangent"].shape == (n, 1 + tdim, 1 + tdim)
    np.testing.assert_array_equal(r["state"], ref["state"])
    if mu > 0:
        for s in (OPEN, STICK, SLIP):
            assert np.count_nonzero(r["state"] == s) > 50
    # Same formulas evaluated in a different order (e.g. the norm): a few ulps of the
    # magnitudes involved, hence 1e-13 relative to each array's largest entry
    for key in ("tau_n", "tau_t", "gtp_trial", "tangent"):
        scale = max(np.abs(ref[key]).max(), 1e-300)
        np.testing.assert_allclose(r[key], ref[key], rtol=0, atol=1e-13 * scale, err_msg=key)

    # Cone (eq 11) and tau_t = (g_t - gtp_trial)/eps_t (eq 12) in every branch; cone up to
    # a few ulps of |m| = 1; eq 12 up to 8 ulps of the cancelling terms over eps_t
    bound = mu * np.abs(r["tau_n"])
    nt = np.linalg.norm(r["tau_t"], axis=1)
    assert np.all(nt <= bound * (1 + 1e-14))
    np.testing.assert_allclose(nt[r["state"] == SLIP], bound[r["state"] == SLIP], rtol=1e-14)
    tol = (
        8
        * np.finfo(float).eps
        * ((np.abs(g_t) + np.abs(gtp) + np.abs(r["gtp_trial"])) / eps_t + np.abs(r["tau_t"]))
    )
    assert np.all(np.abs(r["tau_t"] - (g_t - r["gtp_trial"]) / eps_t) <= tol)


@pytest.mark.parametrize("tdim", [1, 2])
@pytest.mark.parametrize("eps_n, eps_t, mu", [(0.5, 0.25, 0.5), (1e-3, 2e2, 1.2), (3e2, 1e-2, 0.3)])
def test_tangent_matches_finite_differences(tdim, eps_n, eps_t, mu):
    rng = np.random.default_rng(99 + tdim)
    n = 3000
    # Slip history O(eps_t) so that g_t +- h is not rounded away (FD conditioning only)
    g_n, g_t, gtp = random_states(rng, n, tdim, eps_n, eps_t, mu, gtp_scale=eps_t)
    r = call(g_n, g_t, gtp, eps_n, eps_t, mu, tdim)
    state = r["state"]

    # Margins from the kinks g_n = 0 and phi_tr = 0 (1e-3 in traction units, >= 30 times
    # what the FD steps below change)
    ntr = np.linalg.norm((g_t - gtp) / eps_t, axis=1)
    phi_tr = ntr - mu * np.abs(r["tau_n"])
    keep = (np.abs(g_n) > 1e-3 * eps_n) & ((state == OPEN) | (np.abs(phi_tr) > 1e-3))

    # Steps: tau is linear in g_n (h = 1e-6 eps_n, roundoff only); in g_t the scale is
    # |tau_tr| (truncation h^2/|tau_tr|^2, roundoff 1e-15/h balanced by h ~ 1e-5 |tau_tr|^(2/3))
    h_n = 1e-6 * eps_n
    h_t = 1e-5 * eps_t * np.maximum(ntr, 1e-3) ** (2.0 / 3.0)
    fd = np.zeros((n, 1 + tdim, 1 + tdim))
    for col in range(1 + tdim):
        gnp, gnm, gtp_, gtm = g_n.copy(), g_n.copy(), g_t.copy(), g_t.copy()
        if col == 0:
            gnp += h_n
            gnm -= h_n
            dx = gnp - gnm
        else:
            gtp_[:, col - 1] += h_t
            gtm[:, col - 1] -= h_t
            dx = gtp_[:, col - 1] - gtm[:, col - 1]
        rp = call(gnp, gtp_, gtp, eps_n, eps_t, mu, tdim)
        rm = call(gnm, gtm, gtp, eps_n, eps_t, mu, tdim)
        assert np.all(rp["state"][keep] == state[keep])
        assert np.all(rm["state"][keep] == state[keep])
        fd[:, 0, col] = (rp["tau_n"] - rm["tau_n"]) / dx
        fd[:, 1:, col] = (rp["tau_t"] - rm["tau_t"]) / dx[:, None]

    D = r["tangent"]
    for s in (OPEN, STICK, SLIP):
        assert np.count_nonzero(keep & (state == s)) >= 200
    # 1e-6 relative to the magnitude of the block (nn, nt, tn, tt) holding the entry
    for rows in (slice(0, 1), slice(1, None)):
        for cols in (slice(0, 1), slice(1, None)):
            a, b = D[keep][:, rows, cols], fd[keep][:, rows, cols]
            scale = np.maximum(np.abs(a).max(axis=(1, 2)), np.abs(b).max(axis=(1, 2)))
            assert np.all(np.abs(a - b).max(axis=(1, 2)) <= 1e-6 * scale)

    # Slip tangent is not symmetric: d tau_t/d g_n = -mu/eps_n m while d tau_n/d g_t = 0
    s = state == SLIP
    asym = np.linalg.norm(D[s, 1:, 0] - D[s, 0, 1:], axis=1)
    np.testing.assert_allclose(asym, mu / eps_n, rtol=1e-12)


def test_hand_values_2d():
    # tau_n = -2, mu|tau_n| = 1; point 0: tau_tr = 2 -> slip; point 1: tau_tr = 0.8 -> stick;
    # point 2: open. Binary-exact up to one rounding: 1e-14 absolute on O(1) values.
    r = _cpp.return_mapping(
        np.array([-1.0, -1.0, 0.0]),
        np.array([0.6, 0.3, 0.2]),
        np.array([0.1, 0.1, 0.4]),
        0.5,
        0.25,
        0.5,
    )
    np.testing.assert_array_equal(r["state"], [SLIP, STICK, OPEN])
    np.testing.assert_allclose(r["tau_n"], [-2, -2, 0], atol=1e-14)
    np.testing.assert_allclose(r["tau_t"], [1, 0.8, 0], atol=1e-14)
    np.testing.assert_allclose(r["gtp_trial"], [0.35, 0.1, 0.2], atol=1e-14)
    np.testing.assert_allclose(
        r["tangent"], [[[2, 0], [-1, 0]], [[2, 0], [0, 4]], [[0, 0], [0, 0]]], atol=1e-14
    )
    assert int(_cpp.ContactState.slip) == SLIP
    assert int(_cpp.ContactState.stick) == STICK
    assert int(_cpp.ContactState.open) == OPEN


def test_friction_history():
    rng = np.random.default_rng(5)
    n = 50
    h = _cpp.FrictionHistory(n, 2)
    assert h.n == n and len(h) == n and h.tdim == 2
    np.testing.assert_array_equal(h.committed, np.zeros((n, 2)))
    g_n, g_t, gtp = random_states(rng, n, 2, 0.5, 0.25, 0.4)
    h.trial = gtp
    h.commit()
    np.testing.assert_array_equal(h.committed, gtp)

    r = _cpp.return_mapping(g_n, g_t, h.committed, 0.5, 0.25, 0.4)
    h.trial = r["gtp_trial"]
    np.testing.assert_array_equal(h.trial, r["gtp_trial"])
    np.testing.assert_array_equal(h.committed, gtp)  # untouched until commit
    h.restore()
    np.testing.assert_array_equal(h.trial, gtp)  # bitwise
    h.trial = r["gtp_trial"]
    h.commit()
    np.testing.assert_array_equal(h.committed, r["gtp_trial"])

    h1 = _cpp.FrictionHistory(n, 1)
    assert h1.committed.shape == (n,)
    h1.trial = np.arange(n, dtype=float)
    np.testing.assert_array_equal(h1.trial, np.arange(n))
    with pytest.raises(ValueError):
        h1.trial = np.zeros((n, 2))
    with pytest.raises(ValueError):
        h.trial = np.zeros(n)
    with pytest.raises(ValueError):
        _cpp.FrictionHistory(n, 3)


def test_bad_inputs_raise_value_error():
    g_n, g_t, gtp = np.array([-1.0, 0.5]), np.array([0.1, 0.2]), np.zeros(2)
    rm = _cpp.return_mapping
    rm(g_n, g_t, gtp, 1.0, 1.0, 0.5)
    for eps_n, eps_t, mu in [
        (0, 1, 0.5),
        (-1, 1, 0.5),
        (np.nan, 1, 0.5),
        (1, 0, 0.5),
        (1, np.inf, 0.5),
        (1, 1, -0.1),
        (1, 1, np.nan),
    ]:
        with pytest.raises(ValueError):
            rm(g_n, g_t, gtp, eps_n, eps_t, mu)
    with pytest.raises(ValueError):
        rm(np.array([np.nan, 0.5]), g_t, gtp, 1.0, 1.0, 0.5)
    with pytest.raises(ValueError):
        rm(g_n, np.array([0.1, np.nan]), gtp, 1.0, 1.0, 0.5)
    with pytest.raises(ValueError):
        rm(g_n, g_t[:1], gtp, 1.0, 1.0, 0.5)  # n mismatch
    with pytest.raises(ValueError):
        rm(g_n, g_t, np.zeros(3), 1.0, 1.0, 0.5)
    with pytest.raises(ValueError):
        rm(g_n, np.zeros((2, 2)), np.zeros(2), 1.0, 1.0, 0.5)  # gtp_old shape != g_t shape
    with pytest.raises(ValueError):
        rm(g_n, np.zeros((2, 3)), np.zeros((2, 3)), 1.0, 1.0, 0.5)  # tdim 3
    with pytest.raises(ValueError):
        rm(g_n[:, None], g_t, gtp, 1.0, 1.0, 0.5)
    z = np.zeros((3, 2))
    with pytest.raises(ValueError):
        _cpp.compute_gaps(z, z, z, np.zeros((2, 2)), z, z)
    with pytest.raises(ValueError):
        _cpp.compute_gaps(z, z, z, z, np.zeros((3, 3)), z)


def test_compute_gaps_rotated_frames():
    # P_j - P_i = a n + b t, u_j - u_i = c n + d t in frames rotated by theta: g_n0 = a,
    # j_int = c, g_t = d. Inputs O(10): 1e-13 absolute is a few ulps.
    rng = np.random.default_rng(3)
    n = 500
    th = rng.uniform(0, 2 * np.pi, n)
    nrm = np.column_stack([np.cos(th), np.sin(th)])
    tng = np.column_stack([-np.sin(th), np.cos(th)])
    a, b, c, d = rng.uniform(-1, 1, (4, n))
    p_i = rng.uniform(-10, 10, (n, 2))
    u_i = rng.uniform(-1, 1, (n, 2))
    p_j = p_i + a[:, None] * nrm + b[:, None] * tng
    u_j = u_i + c[:, None] * nrm + d[:, None] * tng
    r = _cpp.compute_gaps(p_i, p_j, u_i, u_j, nrm, tng)
    np.testing.assert_allclose(r["g_n0"], a, rtol=0, atol=1e-13)
    np.testing.assert_allclose(r["j_int"], c, rtol=0, atol=1e-13)
    np.testing.assert_allclose(r["g_n"], a + c, rtol=0, atol=1e-13)
    np.testing.assert_allclose(r["g_t"], d, rtol=0, atol=1e-13)
    np.testing.assert_array_equal(r["g_n"], r["g_n0"] + r["j_int"])
