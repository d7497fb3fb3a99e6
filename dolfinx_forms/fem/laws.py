"""Bulk constitutive laws in UFL, one per body (plane strain, written for any dimension).

A law gives the stress that enters the weak form, `stress(u)`: the first Piola-Kirchhoff
stress P(u) (for small-strain laws it is the Cauchy stress sigma(eps(u)), and the two forms
coincide because sigma is symmetric). The solver builds the body's residual
inner(P(u), grad v) dx on the body's cells (body-fitted) or on the inside part of its cut
cells, and the Jacobian with `ufl.derivative`; a `linear` law is assembled once, a
nonlinear one at every Newton iteration. `cauchy(u)` is the output stress (the same
expression, pushed forward for finite strain). Write your own law by subclassing `Law`:
set `linear`, `modulus` (a Young's modulus scale: penalty eq 51) and `p_modulus` (the
stiffness across a face, 2 mu + lambda for isotropy: ghost penalty) and return a UFL
tensor from `stress` (see docs/tutorial.md).

Finite strain on the material-point path (`dolfinx_forms.mpm.finite_strain`): a law with
`finite_strain = True` gives its Kirchhoff stress from the deformation gradient,
`kirchhoff(F, f, history)` (F = f F_n the total gradient, f = I + grad du the step's relative
one, `history` the law's state at the step's start: a UFL vector of `history_size`), and, if it
has a history, its value at the step's end, `history_update(F, f, history)`. A hyperelastic law
only writes `piola(F)` (then tau = P F^T); `plasticity.J2Plasticity` carries its history.

Run-time parameters: the numbers a shipped law's UFL reads (`Law.runtime`: Lame's mu and
lambda, a yield stress, ...) enter the forms as a `fem.Constant` of the mesh (`Law.on(mesh)`,
called where the forms are built), not as literals: the compiled kernels then do not depend on
their values, and a run at another E, nu or yield stress finds them in FFCx's cache instead of
compiling (block_compression, neo-Hookean: 5.8 s -> 2.0 s for a first run at a new E, of which
4 s were FFCx and the C compiler). A user's law without `runtime` keeps its numbers as literals
(one compile per value).
"""

from __future__ import annotations

import copy

import numpy as np
import ufl
from dolfinx import fem
from petsc4py import PETSc


def lame(E, nu):
    """Lame parameters (mu, lambda) of plane strain (= 3D) from E, nu."""
    return E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))


def as_tensor(q, d):
    """The d x d matrix of a UFL vector q of d*d components, row-major: the layout of F_n and
    the relative gradient at quadrature points and material points (fem/history.py,
    mpm/finite_strain.py)."""
    return ufl.as_matrix([[q[i * d + j] for j in range(d)] for i in range(d)])


def strain(u):
    """Small strain eps(u) = sym grad u."""
    return ufl.sym(ufl.grad(u))


class Law:
    """A bulk law (see the module docstring). Subclasses override `stress`."""

    linear = True
    finite_strain = False  # kirchhoff(F, f, history) defined (the MPM's finite-strain path)
    history_size = 0  # entries of the history a point carries (finite-strain path)
    initial_history = ()  # its value in the undeformed state
    modulus = 1.0  # Young's modulus scale (penalty of eq 51)
    p_modulus = 1.0  # stiffness normal to a face (ghost penalty)
    runtime = ()  # the float attributes the UFL reads that `on` makes fem.Constants

    def on(self, mesh):
        """This law for forms on `mesh`: a shallow copy whose `runtime` attributes are the
        entries of one `fem.Constant` of their values (module docstring), and whose inner `law`
        (a wrapper's: the MPM's UpdatedLaw, Inertia, ...) is bound too. The copy is for building
        UFL only; the law itself keeps its numbers (penalty scales, `describe`, `law_key`)."""
        inner = getattr(self, "law", None)
        if not self.runtime and not isinstance(inner, Law):
            return self
        bound = copy.copy(self)
        if self.runtime:
            # one vector Constant, its entries by index: UFL orders the operands of a sum or
            # product of two Constants by their repr, i.e. by their creation count, so separate
            # Constants would give the same law a count-dependent signature (a recompile)
            values = np.array([getattr(self, name) for name in self.runtime], PETSc.ScalarType)
            c = fem.Constant(mesh, values)
            for i, name in enumerate(self.runtime):
                setattr(bound, name, c[i])
        if isinstance(inner, Law):
            bound.law = inner.on(mesh)
        bound.describe = self.describe  # the numbers, not the Constants
        return bound

    def stress(self, u):
        raise NotImplementedError

    def piola(self, F):
        """First Piola-Kirchhoff stress of a hyperelastic law as a function of F."""
        raise NotImplementedError

    def kirchhoff(self, F, f, history):
        """Kirchhoff stress tau = P F^T (module docstring); history unused by default."""
        return self.piola(F) * F.T

    def history_update(self, F, f, history):
        """The history at the end of a step (module docstring); none by default."""
        raise NotImplementedError

    def cauchy(self, u):
        """Output (Cauchy) stress; small-strain laws: the stress itself."""
        return self.stress(u)

    def residual(self, u, v, dx):
        """Internal virtual work inner(P(u), grad v) dx (dx: a measure or a cut measure)."""
        return ufl.inner(self.stress(u), ufl.grad(v)) * dx

    def describe(self) -> dict:
        """Parameters for metrics.json."""
        return {
            "law": type(self).__name__,
            **{k: v for k, v in vars(self).items() if isinstance(v, (int, float, str))},
        }


class IsotropicLaw(Law):
    """A law with Young's modulus E and Poisson ratio nu (Lame mu, lmbda)."""

    runtime = ("mu", "lmbda")

    def __init__(self, E, nu):
        if not (E > 0 and -1 < nu < 0.5):
            raise ValueError(
                f"{type(self).__name__}: need E > 0 and -1 < nu < 0.5, got " f"E={E}, nu={nu}"
            )
        self.E, self.nu = float(E), float(nu)
        self.mu, self.lmbda = lame(self.E, self.nu)
        self.modulus, self.p_modulus = self.E, 2 * self.mu + self.lmbda


class LinearElastic(IsotropicLaw):
    """Isotropic linear elasticity, plane strain: sigma = 2 mu eps + lambda tr(eps) I."""

    def stress(self, u):
        e = strain(u)
        return 2 * self.mu * e + self.lmbda * ufl.tr(e) * ufl.Identity(len(u))


class OrthotropicElastic(Law):
    """Orthotropic linear elasticity in plane strain (eps_33 = 0).

    Material axes 1, 2 in the plane, rotated by `angle` (degrees, counter-clockwise: the unit
    of every angle a user gives, here and in scene descriptions) from x, y;
    axis 3 out of plane. Engineering constants E1, E2, E3, Poisson ratios nu12, nu13, nu23
    (nu_ij = -eps_j / eps_i under uniaxial stress i) and in-plane shear modulus G12. The
    in-plane stiffness is the 2x2 block of the inverse of the 3x3 normal compliance (plane
    strain keeps eps_33 = 0), plus 2 G12 on the shear strain.
    """

    def __init__(self, E1, E2, E3, nu12, nu13, nu23, G12, angle=0.0):
        S = np.array(
            [
                [1 / E1, -nu12 / E1, -nu13 / E1],
                [-nu12 / E1, 1 / E2, -nu23 / E2],
                [-nu13 / E1, -nu23 / E2, 1 / E3],
            ]
        )
        if min(E1, E2, E3, G12) <= 0 or np.any(np.linalg.eigvalsh(S) <= 0):
            raise ValueError(
                "OrthotropicElastic: the constants do not give a positive definite "
                "stiffness (need E_i > 0, G12 > 0 and a positive compliance)"
            )
        C = np.linalg.inv(S)
        self.E1, self.E2, self.E3 = float(E1), float(E2), float(E3)
        self.nu12, self.nu13, self.nu23 = float(nu12), float(nu13), float(nu23)
        self.G12, self.angle = float(G12), float(angle)  # degrees
        self.C11, self.C12, self.C22 = float(C[0, 0]), float(C[0, 1]), float(C[1, 1])
        self.modulus, self.p_modulus = max(E1, E2), max(self.C11, self.C22)

    runtime = ("C11", "C12", "C22", "G12")  # the angle enters through numpy: a literal

    def stress(self, u):
        c, s = np.cos(np.radians(self.angle)), np.sin(np.radians(self.angle))
        R = ufl.as_matrix([[c, -s], [s, c]])  # columns: material axes in x, y
        e = R.T * strain(u) * R
        sm = ufl.as_matrix(
            [
                [self.C11 * e[0, 0] + self.C12 * e[1, 1], 2 * self.G12 * e[0, 1]],
                [2 * self.G12 * e[0, 1], self.C12 * e[0, 0] + self.C22 * e[1, 1]],
            ]
        )
        return R * sm * R.T


class NeoHookean(IsotropicLaw):
    """Compressible neo-Hookean, plane strain (F_33 = 1), finite strain:

    psi = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2,  P = mu (F - F^-T) + lambda ln J F^-T,
    with I1 = tr(F^T F) + 1. Linearised at F = I it is `LinearElastic(E, nu)`.
    """

    linear = False
    finite_strain = True

    def piola(self, F):
        Finv_T = ufl.inv(F).T
        return self.mu * (F - Finv_T) + self.lmbda * ufl.ln(ufl.det(F)) * Finv_T

    def stress(self, u):
        return self.piola(ufl.Identity(len(u)) + ufl.grad(u))

    def cauchy(self, u):
        F = ufl.Identity(len(u)) + ufl.grad(u)
        return self.stress(u) * F.T / ufl.det(F)


def as_law(material) -> Law:
    """A Law, or (E, nu) for `LinearElastic` (the default law)."""
    if isinstance(material, Law):
        return material
    E, nu = material
    return LinearElastic(E, nu)


LAWS = {"linear": LinearElastic, "orthotropic": OrthotropicElastic, "neo-hookean": NeoHookean}


def law_key(law):
    """Laws that are the same: one object, or a shipped law class with equal parameters (a
    user's law is compared by identity: its UFL may hold more than its numbers). Bodies of
    one key share one bulk integral (`bulk.BulkForms`) and one MPM tangent (`mpm`)."""
    if type(law) in LAWS.values():
        return (type(law), tuple(sorted((k, v) for k, v in law.describe().items())))
    return id(law)
