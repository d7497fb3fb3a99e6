"""J2 plasticity at finite strain with linear isotropic hardening, in UFL (plane strain).

Multiplicative split F = F_e F_p; the history is the elastic left Cauchy-Green tensor
b_e = F_e F_e^T at the step's start (its in-plane block and b_e,zz: plane strain keeps F_33 = 1
but b_e,zz evolves with plastic flow) and the equivalent plastic strain alpha. A step with the
relative gradient f (F = f F_n):

    trial:   b_e^tr = f b_e,n f^T,   eps^tr = 1/2 ln b_e^tr   (logarithmic elastic strain)
             tau^tr = K tr(eps^tr) I + 2 G dev(eps^tr),   q^tr = sqrt(3/2) |dev tau^tr|
    return:  phi = q^tr - (sigma_y + H alpha_n);  if phi > 0: dgamma = phi / (3 G + H),
             dev tau = (1 - 3 G dgamma / q^tr) dev tau^tr   (radial return)
    update:  eps_e = tr(eps^tr)/3 I + (1 - 3 G dgamma / q^tr) dev(eps^tr),
             b_e = exp(2 eps_e),  alpha = alpha_n + dgamma

(Simo's exponential-map algorithm: the small-strain radial return in logarithmic strain, so
any small-strain return mapping plugs in at `return_map`). The Kirchhoff stress is an explicit
UFL expression of f and the history, so `ufl.derivative` gives the consistent (algorithmic)
tangent. The tensors are 3 x 3 (the in-plane block and zz); the closed-form logarithm and
exponential of the in-plane block (`log_sym2`, `exp_sym2`) are the one 2D-specific part: 3D
needs their 3 x 3 spectral forms.
"""

from __future__ import annotations

import math

import ufl

from dolfinx_forms.fem.laws import IsotropicLaw


def log_sym2(B):
    """ln B of a symmetric positive definite 2 x 2 B: 1/2 ln det B I + c (B - tr B / 2 I),
    c = atanh(s) / (s m), s = sqrt(d2) / m (m = tr B / 2, d2 the squared half eigenvalue gap).
    atanh(s) / s is even in s: a series where s^2 < 1e-3 (error < 1e-16) keeps the tangent
    finite at equal eigenvalues."""
    m = 0.5 * ufl.tr(B)
    dev = B - m * ufl.Identity(2)
    s2 = (0.25 * (B[0, 0] - B[1, 1]) ** 2 + B[0, 1] ** 2) / m**2
    series = 1 + s2 / 3 + s2**2 / 5 + s2**3 / 7 + s2**4 / 9
    s = ufl.sqrt(ufl.max_value(s2, 1e-3))
    exact = 0.5 * ufl.ln((1 + s) / (1 - s)) / s
    c = ufl.conditional(ufl.lt(s2, 1e-3), series, exact) / m
    return 0.5 * ufl.ln(ufl.det(B)) * ufl.Identity(2) + c * dev


def exp_sym2(A):
    """exp A of a symmetric 2 x 2 A: e^m (cosh d I + sinh(d) / d (A - m I)), m = tr A / 2,
    d the half eigenvalue gap (sinh(d) / d by its series where d^2 < 1e-3)."""
    m = 0.5 * ufl.tr(A)
    dev = A - m * ufl.Identity(2)
    d2 = 0.25 * (A[0, 0] - A[1, 1]) ** 2 + A[0, 1] ** 2
    d = ufl.sqrt(ufl.max_value(d2, 1e-3))
    sinhc = ufl.conditional(
        ufl.lt(d2, 1e-3),
        1 + d2 / 6 + d2**2 / 120 + d2**3 / 5040 + d2**4 / 362880,
        ufl.sinh(d) / d,
    )
    cosh = ufl.conditional(
        ufl.lt(d2, 1e-3), 1 + d2 / 2 + d2**2 / 24 + d2**3 / 720 + d2**4 / 40320, ufl.cosh(d)
    )
    return ufl.exp(m) * (cosh * ufl.Identity(2) + sinhc * dev)


def _embed(A2, zz):
    """The 3 x 3 block-diagonal tensor of an in-plane block and a zz entry."""
    return ufl.as_matrix([[A2[0, 0], A2[0, 1], 0], [A2[1, 0], A2[1, 1], 0], [0, 0, zz]])


class LogStrainPlasticity(IsotropicLaw):
    """Finite-strain plasticity by the exponential map (module docstring): a Hencky elastic law
    (E, nu) in the logarithmic elastic strain and a small-strain return mapping
    `return_map(eps_trial, alpha) -> (eps_e, dalpha)` of a subclass. History [b_xx, b_yy, b_xy,
    b_zz, alpha] (5 entries), initially [1, 1, 0, 1, 0]; alpha the hardening variable."""

    linear = False
    finite_strain = True
    history_size = 5
    initial_history = (1.0, 1.0, 0.0, 1.0, 0.0)
    runtime = IsotropicLaw.runtime + ("K",)

    def __init__(self, E, nu):
        super().__init__(E, nu)
        self.K = self.lmbda + 2 * self.mu / 3

    def trial(self, f, h):
        """Trial logarithmic elastic strain (3 x 3) of the step."""
        be = ufl.as_matrix([[h[0], h[2]], [h[2], h[1]]])
        return _embed(0.5 * log_sym2(f * be * f.T), 0.5 * ufl.ln(h[3]))

    def tau3(self, f, h):
        eps_e, dalpha = self.return_map(self.trial(f, h), h[4])
        tau = self.K * ufl.tr(eps_e) * ufl.Identity(3) + 2 * self.mu * ufl.dev(eps_e)
        return tau, eps_e, dalpha

    def kirchhoff(self, F, f, history):
        tau, _, _ = self.tau3(f, history)
        return ufl.as_matrix([[tau[0, 0], tau[0, 1]], [tau[1, 0], tau[1, 1]]])

    def history_update(self, F, f, history):
        _, eps_e, dalpha = self.tau3(f, history)
        be = exp_sym2(2 * ufl.as_matrix([[eps_e[0, 0], eps_e[0, 1]], [eps_e[1, 0], eps_e[1, 1]]]))
        return ufl.as_vector(
            [be[0, 0], be[1, 1], be[0, 1], ufl.exp(2 * eps_e[2, 2]), history[4] + dalpha]
        )


class J2Plasticity(LogStrainPlasticity):
    """Finite-strain J2 plasticity with linear isotropic hardening (module docstring):
    E, nu (the Hencky elastic law), yield_stress sigma_y > 0, hardening H >= 0; alpha the
    equivalent plastic strain."""

    runtime = LogStrainPlasticity.runtime + ("yield_stress", "hardening")

    def __init__(self, E, nu, yield_stress, hardening=0.0):
        super().__init__(E, nu)
        if not (yield_stress > 0 and hardening >= 0):
            raise ValueError(
                "J2Plasticity: need yield_stress > 0 and hardening >= 0, got "
                f"yield_stress={yield_stress}, hardening={hardening}"
            )
        self.yield_stress, self.hardening = float(yield_stress), float(hardening)

    def return_map(self, eps, alpha):
        """Radial return in logarithmic strain: (elastic strain, dgamma)."""
        G, H = self.mu, self.hardening
        e = ufl.dev(eps)
        q = ufl.sqrt(1.5 * ufl.inner(2 * G * e, 2 * G * e))
        phi = q - (self.yield_stress + H * alpha)
        dgamma = ufl.max_value(phi, 0.0) / (3 * G + H)
        shrink = 1 - 3 * G * dgamma / ufl.max_value(q, 1e-300)
        scale = ufl.conditional(ufl.gt(phi, 0.0), shrink, 1.0)
        return ufl.tr(eps) / 3 * ufl.Identity(3) + scale * e, dgamma


def drucker_prager_coefficients(friction_angle, dilatancy_angle):
    """(eta, xi, eta_bar) of the Drucker-Prager cone matched to Mohr-Coulomb in plane strain
    (de Souza Neto, Peric & Owen 2008, section 8.2): eta = 3 tan phi / sqrt(9 + 12 tan^2 phi),
    xi = 3 / sqrt(9 + 12 tan^2 phi), eta_bar as eta of the dilatancy angle psi (degrees)."""

    def match(angle):
        t = math.tan(math.radians(angle))
        return 3 * t / math.sqrt(9 + 12 * t * t), 3 / math.sqrt(9 + 12 * t * t)

    (eta, xi), (eta_bar, _) = match(friction_angle), match(dilatancy_angle)
    return eta, xi, eta_bar


class DruckerPrager(LogStrainPlasticity):
    """Finite-strain Drucker-Prager plasticity for geomaterials (de Souza Neto et al. 2008,
    section 8.3; the return mapping of their Box 8.9 in the logarithmic elastic strain):

        yield      sqrt(J2(tau)) + eta p - xi (c + H alpha) <= 0,   p = tr tau / 3 (tension > 0)
        potential  sqrt(J2(tau)) + eta_bar p   (non-associative for psi < phi)

    with the plane-strain Mohr-Coulomb match (drucker_prager_coefficients) of the friction angle
    phi and the dilatancy angle psi (0 < psi <= phi, degrees), cohesion c > 0 hardening
    linearly with alpha (H >= 0). Return to the cone's smooth part: dgamma = f_trial / (G +
    K eta eta_bar + xi^2 H), s = (1 - G dgamma / sqrt(J2_trial)) s_trial, p = p_trial -
    K eta_bar dgamma, alpha += xi dgamma; when that overshoots the axis (sqrt(J2_trial) <
    G dgamma), return to the apex: s = 0, p = p_trial - K dv with dv = (p_trial - (xi / eta)
    (c + H alpha_n)) / (K + H xi^2 / (eta eta_bar)), alpha += (xi / eta_bar) dv."""

    runtime = LogStrainPlasticity.runtime + ("cohesion", "hardening", "eta", "xi", "eta_bar")

    def __init__(self, E, nu, cohesion, friction_angle, dilatancy_angle=None, hardening=0.0):
        super().__init__(E, nu)
        psi = friction_angle if dilatancy_angle is None else dilatancy_angle
        if not (cohesion > 0 and 0 < friction_angle < 90 and 0 < psi <= friction_angle
                and hardening >= 0):  # fmt: skip
            raise ValueError(
                "DruckerPrager: need cohesion > 0, 0 < friction_angle < 90, 0 < dilatancy_angle"
                f" <= friction_angle and hardening >= 0, got {cohesion}, {friction_angle}, "
                f"{psi}, {hardening}"
            )
        self.cohesion, self.hardening = float(cohesion), float(hardening)
        self.friction_angle, self.dilatancy_angle = float(friction_angle), float(psi)
        self.eta, self.xi, self.eta_bar = drucker_prager_coefficients(friction_angle, psi)

    def return_map(self, eps, alpha):
        """(elastic strain, dalpha) of the trial logarithmic strain (class docstring). Scalar
        conditionals only: eps_e = A dev(eps) + B I in every branch."""
        G, K, H = self.mu, self.K, self.hardening
        eta, xi, eb = self.eta, self.xi, self.eta_bar
        e, ev = ufl.dev(eps), ufl.tr(eps)
        sq = G * ufl.sqrt(2 * ufl.inner(e, e))  # sqrt(J2) of s = 2 G e
        p = K * ev
        c = self.cohesion + H * alpha
        f = sq + eta * p - xi * c
        dg = ufl.max_value(f, 0.0) / (G + K * eta * eb + xi * xi * H)
        dv = (p - xi / eta * c) / (K + H * xi * xi / (eta * eb))  # the apex's volumetric strain
        cone = ufl.ge(sq - G * dg, 0.0)
        A_plastic = ufl.conditional(cone, 1 - G * dg / ufl.max_value(sq, 1e-300), 0.0)
        p_plastic = ufl.conditional(cone, p - K * eb * dg, p - K * dv)
        plastic = ufl.gt(f, 0.0)
        A = ufl.conditional(plastic, A_plastic, 1.0)
        B = ufl.conditional(plastic, p_plastic / (3 * K), ev / 3)
        dalpha = ufl.conditional(plastic, ufl.conditional(cone, xi * dg, xi / eb * dv), 0.0)
        return A * e + B * ufl.Identity(3), dalpha
