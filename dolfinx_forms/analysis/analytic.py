"""Analytic references (Johnson, Contact Mechanics, ch. 4 and 7; plane strain, line loads)."""

import numpy as np


def effective_modulus(E1, nu1, E2=None, nu2=None):
    """E* with 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2 (E2 = inf or None: rigid second body)."""
    inv = (1 - nu1**2) / E1
    if E2 is not None and np.isfinite(E2):
        inv += (1 - nu2**2) / E2
    return 1.0 / inv


def hertz_line(P, R, E_star):
    """Half-width a and peak pressure p0 of a cylinder (radius R) on a flat, line load P."""
    a = np.sqrt(4 * P * R / (np.pi * E_star))
    return a, 2 * P / (np.pi * a)


def hertz_pressure(x, a, p0):
    """p(x) = p0 sqrt(1 - x^2/a^2) inside |x| < a, 0 outside."""
    r = np.clip(1 - (np.asarray(x) / a) ** 2, 0.0, None)
    return p0 * np.sqrt(r)


def circle_line(P, R, E_star):
    """Half-width a and pressure scale of a cylinder on a flat whose gap is the circle's to
    order x^4, g0 = x^2/(2R) + x^4/(8R^3), where Hertz keeps x^2/(2R) only: the load is
    P = pi a^2 E* / (4R) (1 + 3 a^2 / (8 R^2)) (`circle_pressure`). Relative error O((a/R)^4)
    against the exact circle on a half-plane, where Hertz's is O((a/R)^2): at a/R = 0.1 Hertz's
    pressure is 0.4 % off the circle's in L2, most of it at the contact edge (a 0.19 % larger
    half-width). Returns a."""
    k, c = 4 * P * R / (np.pi * E_star), 3 / (8 * R**2)  # a^2 (1 + c a^2) = k
    return np.sqrt(2 * k / (1 + np.sqrt(1 + 4 * c * k)))


def circle_pressure(x, a, R, E_star):
    """p(x) = E*/(2R) sqrt(a^2 - x^2) (1 + (x^2 + a^2/2) / (2 R^2)) inside |x| < a, the
    half-plane solution for the gap x^2/(2R) + x^4/(8R^3) (`circle_line`): (1/pi) PV int p(s) /
    (x - s) ds = E*/2 g0'(x), with (1/pi) PV int s^2 sqrt(a^2-s^2)/(x-s) ds = x^3 - a^2 x/2."""
    x = np.asarray(x, float)
    r = np.sqrt(np.clip(a**2 - x**2, 0.0, None))
    return E_star / (2 * R) * r * (1 + (x**2 + 0.5 * a**2) / (2 * R**2))


def circle_mindlin(P, Q, mu, R, E_star):
    """Cattaneo-Mindlin on the circle to O((a/R)^4) (`circle_line`): the stick half-width c
    where the circle's load of half-width c is P - |Q| / mu (the tangential traction is mu p
    minus mu times the circle's pressure of half-width c, whose slip is uniform on |x| < c:
    the same integral equation, identical bodies). Returns (a, c)."""
    return circle_line(P, R, E_star), circle_line(P - abs(Q) / mu, R, E_star)


def circle_mindlin_shear(x, a, c, R, E_star, mu):
    """|q(x)| = mu circle_pressure(x, a) - mu circle_pressure(x, c) (`circle_mindlin`)."""
    q = mu * circle_pressure(x, a, R, E_star)
    return q - mu * circle_pressure(x, c, R, E_star) if c > 0 else q


def load_for_half_width(a, R, E_star):
    """Line load that gives half-width a (inverse of hertz_line)."""
    return np.pi * E_star * a**2 / (4 * R)


def mindlin_stick_half_width(a, Q, mu, P):
    """Cattaneo-Mindlin c = a sqrt(1 - |Q|/(mu P)) (monotonic Q after P)."""
    return a * np.sqrt(1 - abs(Q) / (mu * P))


def mindlin_shear(x, a, c, p0, mu):
    """|q(x)|: mu p0 sqrt(1-x^2/a^2) minus mu p0 (c/a) sqrt(1-x^2/c^2) inside the stick zone."""
    x = np.asarray(x)
    q = mu * hertz_pressure(x, a, p0)
    return q - mu * (c / a) * hertz_pressure(x, c, p0) if c > 0 else q


def patch_pressure(E, nu, strain):
    """Uniform contact pressure of the plane-strain patch test with free sides: E/(1-nu^2) e."""
    return E / (1 - nu**2) * strain


def inclined_uniaxial_state(E, nu, d, height, slope, eps_n=0.0, eps_t=0.0):
    """The uniform uniaxial state (sigma_yy = -s, sigma_xx = tau_xy = 0, plane strain) of a
    column of height `height` shortened by d and crossed by the interface of slope tan theta,
    bonded by penalty springs eps_n, eps_t (eqs 8, 51: the jump g = eps_n tau_n n + eps_t tau_t
    t = s g1), so the top moves by -d = -s (1 - nu^2) height / E + s g1_y. n: unit normal of
    the interface pointing up (lower -> upper), t = (-n_y, n_x); the traction on it is
    (0, -s cos theta). Returns s, the lateral strain exx = nu (1 + nu) s / E, the horizontal
    jump gx = s g1_x, the pressure p_n = s cos^2 theta and the shear tau_t along t."""
    n = np.array([-slope, 1.0]) / np.hypot(1.0, slope)
    t = np.array([-n[1], n[0]])
    tv = np.array([0.0, -1.0]) * n[1]  # (tau_n n + tau_t t) per unit s: (0, -cos theta)
    tau_n, tau_t = tv @ n, tv @ t
    g1 = eps_n * tau_n * n + eps_t * tau_t * t
    s = d / ((1 - nu**2) * height / E - g1[1])
    return dict(s=s, exx=nu * (1 + nu) * s / E, gx=s * g1[0], p_n=-s * tau_n, tau_t=s * tau_t)
