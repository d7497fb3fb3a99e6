"""Finite strain on the material-point path: an updated Lagrangian step on Omega_n.

A body whose law has `finite_strain` (`fem.laws`) carries at each material point its deformation
gradient F_n (plane strain: the in-plane block, F_33 = 1) and its law's history h_n. A step
solves for the displacement increment du on the configuration at the step's start, Omega_n (the
cut cells of the current level sets), with the relative gradient f = I + grad du and F = f F_n:

    R(du; v) = int_{Omega_n} (1 / det F_n) tau(F, f, h_n) f^-T : grad v  dv

(the reference virtual work int_{Omega_0} P : Grad v dV pulled to Omega_n: dV = dv / det F_n,
Grad v = grad v F_n, P = tau F^-T). F_n and h_n reach the integration points of the new cells by
the MLS projection of the points' values (eqs 38-45, linear basis: a homogeneous F is carried
exactly); the tangent is `ufl.derivative` of R, the consistent tangent of whatever tau the law
computes, its return mapping included. After the step each point updates F <- f F_n with f from
the converged increment at the point: multiplicative, so a rigid rotation rotates F and leaves
every invariant of the stress unchanged, exactly (objective by construction: tau depends on F
through the law alone, never on a rate). Its history follows the law's `history_update` and its
volume is vol = vol0 det F, vol0 = mass / density, so mass is constant.

The points' Cauchy stress and new history are the law's own UFL expressions evaluated at the
points (`PointLaw`: one DG0 cell per point on a helper mesh), so each equation is written once.
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem, mesh as dmesh
from mpi4py import MPI

from dolfinx_forms.fem.laws import Law, as_tensor


def voigt(S, d):
    """[S_xx, S_yy, S_xy] (d = 2) or [S_xx, S_yy, S_zz, S_yz, S_xz, S_xy] (d = 3)."""
    pairs = [(0, 0), (1, 1), (0, 1)] if d == 2 else [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)]
    return [S[i, j] for i, j in pairs]


class UpdatedLaw(Law):
    """The residual of a finite-strain law on Omega_n (module docstring), for `BulkForms`:
    law: the body's `Law` (finite_strain); Fn: a `Quadrature` Function of d*d components (F_n at
    the integration points, degree `quadrature_degree`); history: one of law.history_size
    components, or None. Bodies of one law share one UpdatedLaw: one kernel for all."""

    linear = False

    def __init__(self, law, Fn, history, degree):
        self.law, self.Fn, self.history = law, Fn, history
        self.quadrature_degree = int(degree)
        self.modulus, self.p_modulus = law.modulus, law.p_modulus

    def kinematics(self, u):
        d = len(u)
        f = ufl.Identity(d) + ufl.grad(u)
        Fn = as_tensor(self.Fn, d)
        return f * Fn, f, Fn

    def residual(self, u, v, dx):
        F, f, Fn = self.kinematics(u)
        tau = self.law.kirchhoff(F, f, self.history)
        return ufl.inner(tau * ufl.inv(f).T / ufl.det(Fn), ufl.grad(v)) * dx

    def cauchy(self, u):
        F, f, _ = self.kinematics(u)
        return self.law.kirchhoff(F, f, self.history) / ufl.det(F)

    def describe(self):
        return self.law.describe()


class PointLaw:
    """A finite-strain law at n points: Cauchy stress (Voigt) and new history from F_n, f and
    h_n per point, by the law's UFL on a helper mesh (one DG0 cell per point, grown on demand).
    The expression is compiled once per law."""

    def __init__(self, law, dim=2):
        self.law, self.d, self.n = law, int(dim), 0

    def _build(self, n):
        d, k = self.d, self.law.history_size
        m = int(np.ceil(np.sqrt(n)))
        mesh = dmesh.create_rectangle(
            MPI.COMM_SELF, [np.zeros(2), np.full(2, float(m))], [m, m], dmesh.CellType.quadrilateral
        )
        T = fem.VectorFunctionSpace(mesh, ("DG", 0), dim=d * d)
        self.f, self.Fn = fem.Function(T), fem.Function(T)
        self.h = fem.Function(fem.VectorFunctionSpace(mesh, ("DG", 0), dim=k)) if k else None
        self.dofs = T.dofmap.list.array  # cell -> its DG0 block
        f, Fn = as_tensor(self.f, d), as_tensor(self.Fn, d)
        F = f * Fn
        law = self.law.on(mesh)
        out = voigt(law.kirchhoff(F, f, self.h) / ufl.det(F), d)
        if k:
            new = law.history_update(F, f, self.h)
            out += [new[i] for i in range(k)]
        centre = np.full((1, d), 0.5)
        self.expr = fem.Expression(ufl.as_vector(out), centre)
        self.n = m * m

    def __call__(self, Fn, f, history):
        """Fn, f (n, d, d); history (n, k) -> (Cauchy stress (n, 3 or 6), history (n, k))."""
        n, d, k = len(Fn), self.d, self.law.history_size
        if n > self.n:
            self._build(n)
        cells = np.arange(n, dtype=np.int32)
        dofs = self.dofs[:n]
        self.Fn.x.array.reshape(-1, d * d)[dofs] = Fn.reshape(n, d * d)
        self.f.x.array.reshape(-1, d * d)[dofs] = f.reshape(n, d * d)
        if k:
            self.h.x.array.reshape(-1, k)[dofs] = history
        out = self.expr.eval(cells).reshape(n, -1)
        ns = 3 if d == 2 else 6
        return out[:, :ns].copy(), out[:, ns:].copy()
