"""The analytic references against independent numerical solutions.

Hertz's line contact keeps the parabola x^2/(2R) of a cylinder's gap; the demos' cylinders are
circles. `analytic.circle_pressure` keeps the next term, x^4/(8R^3). Both are checked here
against the half-plane's singular integral equation solved numerically for the exact circle,
(1/pi) PV int_{-a}^{a} p(s) / (x - s) ds = E*/2 g0'(x), g0'(x) = x / sqrt(R^2 - x^2), by
Gauss-Chebyshev quadrature (Erdogan & Gupta 1972): p(s) = sqrt(a^2 - s^2) phi(s), phi at the
nodes t_k = cos(k pi / (n + 1)), collocation at xi_j = cos((2j - 1) pi / (2n + 2)); exact for
polynomial phi, so its error is the circle's non-polynomial remainder only."""

import numpy as np
import pytest

from dolfinx_forms.analysis import analytic


def circle_numerical(a, R, E_star, n=40):
    """phi's nodes x_k = a t_k, the pressure there and the load, for a given half-width."""
    k = np.arange(1, n + 1)
    t = np.cos(k * np.pi / (n + 1))
    w = (1 - t**2) / (n + 1)  # (1/pi) int sqrt(1-t^2) f(t) dt ~ sum w f(t_k)
    xi = np.cos((2 * np.arange(1, n + 1) - 1) * np.pi / (2 * n + 2))
    # a (1/pi) PV int sqrt(1-t^2) phi(a t) / (xi - t) dt = E*/2 g0'(a xi)
    A = a * w[None, :] / (xi[:, None] - t[None, :])
    x = a * xi
    phi = np.linalg.solve(A, 0.5 * E_star * x / np.sqrt(R**2 - x**2))
    load = a**2 * np.pi * np.sum(w * phi)  # int sqrt(a^2 - s^2) phi ds
    return a * t, a * np.sqrt(1 - t**2) * phi, load


@pytest.mark.parametrize("R", [10.0, 3.0])
def test_circle_pressure_solves_the_half_plane_problem(R):
    """At a/R = 0.1 and 0.33: the circle's closed form agrees with the numerical solution to
    O((a/R)^4) (load and pressure), Hertz's parabola to O((a/R)^2) only."""
    E_star, a = 1e4 / (2 * (1 - 0.3**2)), 1.0
    x, p, load = circle_numerical(a, R, E_star)
    scale = p.max()
    order4, order2 = (a / R) ** 4, (a / R) ** 2
    # the closed form at the numerical load: its half-width and pressure
    assert abs(analytic.circle_line(load, R, E_star) / a - 1) <= 0.2 * order4
    assert np.abs(analytic.circle_pressure(x, a, R, E_star) - p).max() <= 0.5 * order4 * scale
    # Hertz: a half-width and a pressure off by O((a/R)^2)
    a_h, p0 = analytic.hertz_line(load, R, E_star)
    assert abs(a_h / a - 1) >= 0.1 * order2
    assert np.abs(analytic.hertz_pressure(x, a, p0) - p).max() >= 0.1 * order2 * scale


def test_circle_line_inverts_its_load():
    P, R, E_star = 430.0, 10.0, 5494.5
    a = analytic.circle_line(P, R, E_star)
    assert np.isclose(
        np.pi * a**2 * E_star / (4 * R) * (1 + 3 * a**2 / (8 * R**2)), P, rtol=1e-14
    )
    x = np.linspace(-a, a, 400001)
    assert np.isclose(np.trapz(analytic.circle_pressure(x, a, R, E_star), x), P, rtol=1e-6)


def test_circle_mindlin_carries_Q_and_tends_to_hertz():
    """Cattaneo-Mindlin on the circle: q = mu p_c(a) - mu p_c(c) carries Q; for a/R -> 0 the
    stick half-width is Hertz's c = a sqrt(1 - Q / (mu P)); at a/R = 0.1 it is O((c/R)^2)
    smaller (the circle's pressure of half-width c is the stick correction: its slip is
    uniform on |x| < c, `test_circle_pressure_solves_the_half_plane_problem`)."""
    E_star, mu = 5494.5, 0.3
    for R, P, close in ((10.0, 430.0, False), (1e4, 0.43, True)):
        Q = 0.5 * mu * P
        a, c = analytic.circle_mindlin(P, Q, mu, R, E_star)
        x = np.linspace(-a, a, 400001)
        q = analytic.circle_mindlin_shear(x, a, c, R, E_star, mu)
        assert np.isclose(np.trapz(q, x), Q, rtol=1e-6)
        assert np.all(q >= -1e-12 * q.max()) and np.all(
            q <= mu * analytic.circle_pressure(x, a, R, E_star) + 1e-12
        )
        a_h, _ = analytic.hertz_line(P, R, E_star)
        c_h = analytic.mindlin_stick_half_width(a_h, Q, mu, P)
        if close:
            assert abs(c / c_h - 1) < 1e-7
        else:
            assert 1e-4 < 1 - c / c_h < 3 * (c / R) ** 2
