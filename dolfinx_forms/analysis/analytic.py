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


# ---------------------------------------------------------------- homogeneous plane-strain block
# A block between frictionless platens: F = diag(l_x, l_y, 1), l_y prescribed, l_x from a free
# lateral face (sigma_xx = 0). Each returns the compressive force per unit thickness on the
# platen, |sigma_yy| times the current width (= |P_yy| times the initial one), and l_x.


def _free_stretch(tau_xx, lx0):
    """l_x with tau_xx(l_x) = 0 by the secant method from l_x0 (to round-off)."""
    a, b = lx0, lx0 * (1 + 1e-3)
    fa, fb = tau_xx(a), tau_xx(b)
    for _ in range(100):
        if fb == fa:
            break
        a, b, fa = b, b - fb * (b - a) / (fb - fa), fb
        fb = tau_xx(b)
        if abs(b - a) <= 1e-15 * abs(b):
            break
    return b


def block_neo_hookean(ly, width, mu, lmbda):
    """Compressible neo-Hookean (laws.NeoHookean): P = mu (F - F^-T) + lambda ln J F^-T.
    ly: an array of stretches; returns (force, l_x) arrays."""
    out = []
    for y in np.atleast_1d(ly):
        lx = _free_stretch(lambda x: mu * (x - 1 / x) + lmbda * np.log(x * y) / x, 1.0)
        out.append((abs(mu * (y - 1 / y) + lmbda * np.log(lx * y) / y) * width, lx))
    return tuple(np.array(v) for v in zip(*out))


def block_hypoelastic(ly, width, E, nu):
    """The small-strain MPM update (sigma += C : d_eps per step, d_eps on the step's
    configuration; no spin in pure stretch) integrated along the steps l_y[0], l_y[1], ...
    (from 1): sigma_xx = 0 gives d_eps_x = -C12 / C11 d_eps_y."""
    mu, lmbda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    C11, C12 = 2 * mu + lmbda, lmbda
    syy, lx, y0, out = 0.0, 1.0, 1.0, []
    for y in np.atleast_1d(ly):
        dy = (y - y0) / y0
        dx = -C12 / C11 * dy
        syy += C12 * dx + C11 * dy
        lx, y0 = lx * (1 + dx), y
        out.append((abs(syy) * width * lx, lx))
    return tuple(np.array(v) for v in zip(*out))


def _block_path(ly, width, E, nu, ret):
    """The homogeneous block of a log-strain plasticity law with the return mapping
    ret(eps (3,), alpha) -> (elastic strain (3,), dalpha) in principal axes x, y, z (the
    block's never rotate), integrated along the steps l_y[0], l_y[1], ... from the virgin
    state; each step's l_x from tau_xx = 0. Returns (force, l_x, alpha)."""
    G, lmbda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    K = lmbda + 2 * G / 3
    be, alpha, lx0, y0, out = np.ones(3), 0.0, 1.0, 1.0, []

    def update(f):
        e, da = ret(0.5 * np.log(f**2 * be), alpha)
        return K * e.sum() + 2 * G * (e - e.sum() / 3), e, da

    for y in np.atleast_1d(ly):
        lx = _free_stretch(lambda x: update(np.array([x / lx0, y / y0, 1.0]))[0][0], lx0)
        tau, e, da = update(np.array([lx / lx0, y / y0, 1.0]))
        be, alpha, lx0, y0 = np.exp(2 * e), alpha + da, lx, y
        out.append((abs(tau[1]) / y * width, lx, alpha))
    return tuple(np.array(v) for v in zip(*out))


def block_j2(ly, width, E, nu, yield_stress, hardening):
    """Finite-strain J2 (plasticity.J2Plasticity: logarithmic elastic strain, Kirchhoff
    stress, radial return) along the block path (_block_path): an independent principal-space
    implementation. Returns (force, l_x, alpha)."""
    G = E / (2 * (1 + nu))

    def ret(eps, alpha):
        dev = eps - eps.sum() / 3
        q = np.sqrt(1.5) * 2 * G * np.linalg.norm(dev)
        phi = q - (yield_stress + hardening * alpha)
        dg = max(phi, 0.0) / (3 * G + hardening)
        return eps.sum() / 3 + (1 - 3 * G * dg / q if phi > 0 else 1.0) * dev, dg

    return _block_path(ly, width, E, nu, ret)


def drucker_prager_return(eps, alpha, E, nu, cohesion, friction_angle, dilatancy_angle,
                          hardening):  # fmt: skip
    """The Drucker-Prager return mapping (plasticity.DruckerPrager: the cone's smooth part,
    else its apex) of principal trial logarithmic strains eps (3,) in numpy, an independent
    implementation: (elastic strains (3,), dalpha)."""
    from dolfinx_forms.fem.plasticity import drucker_prager_coefficients

    G, lmbda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    K, H = lmbda + 2 * G / 3, hardening
    eta, xi, eb = drucker_prager_coefficients(friction_angle, dilatancy_angle)
    p, s = K * eps.sum(), 2 * G * (eps - eps.sum() / 3)
    sq, c = np.sqrt(0.5 * s @ s), cohesion + H * alpha
    f = sq + eta * p - xi * c
    if f <= 0:
        return eps, 0.0
    dg = f / (G + K * eta * eb + xi**2 * H)
    if sq - G * dg >= 0:  # the cone's smooth part
        s, p, da = (1 - G * dg / sq) * s, p - K * eb * dg, xi * dg
    else:  # the apex
        dv = (p - xi / eta * c) / (K + H * xi**2 / (eta * eb))
        s, p, da = 0 * s, p - K * dv, xi / eb * dv
    return s / (2 * G) + p / (3 * K), da


def block_drucker_prager(ly, width, E, nu, cohesion, friction_angle, dilatancy_angle,
                         hardening):  # fmt: skip
    """Finite-strain Drucker-Prager along the block path (_block_path, drucker_prager_return).
    Returns (force, l_x, alpha)."""
    law = (E, nu, cohesion, friction_angle, dilatancy_angle, hardening)
    return _block_path(ly, width, E, nu, lambda eps, a: drucker_prager_return(eps, a, *law))


# ---------------------------------------------------------------- flat punch (Johnson 1985, 2.8)
def flat_punch(x, a, P, nu, adhesive=False):
    """Pressure p(x) and shear q(x) (on the half-space, along +x) under a rigid flat punch of
    half-width a pressed with P per unit thickness into an elastic half-space (plane strain),
    |x| < a. Frictionless: p = P / (pi sqrt(a^2 - x^2)), q = 0. Adhesive (no slip anywhere):
    p, q = c P / (pi sqrt(a^2 - x^2)) (cos, sin)(eta ln((a + x) / (a - x))), c = 2 (1 - nu) /
    sqrt(3 - 4 nu), eta = ln(3 - 4 nu) / (2 pi)."""
    x = np.asarray(x, float)
    base = P / (np.pi * np.sqrt(a**2 - x**2))
    if not adhesive:
        return base, np.zeros_like(base)
    eta, c = np.log(3 - 4 * nu) / (2 * np.pi), 2 * (1 - nu) / np.sqrt(3 - 4 * nu)
    L = eta * np.log((a + x) / (a - x))
    return c * base * np.cos(L), c * base * np.sin(L)
