"""A finite-strain law with history on a fixed mesh: total Lagrangian, the history at the
quadrature points (the single-step paths' counterpart of mpm/finite_strain.py).

The displacement u is measured from the reference configuration; F = I + grad u. The law
(`laws.Law` with `finite_strain`) is evaluated with the relative gradient of the load step,
f = F F_n^-1, and the history h_n of the last committed step, both `Quadrature` Functions at
the Gauss points of `degree`:

    R(u; v) = int_{Omega_0} tau(F, f, h_n) F^-T : Grad v dV   (P = tau F^-T).

`commit(u)` after each converged load step stores F_n <- F and h_n <- the law's
`history_update` at every quadrature point (the law's own UFL, evaluated there). The tangent is
`ufl.derivative` of R: for J2 the consistent tangent of its return mapping. A load history is
a sequence of `problem.solve(1, lam_k)` calls, each followed by `commit(problem.u)`.
"""

from __future__ import annotations

import basix
import numpy as np
import ufl
from dolfinx import fem

from dolfinx_forms.fem.laws import Law, as_tensor

CELLS = {"triangle": basix.CellType.triangle, "quadrilateral": basix.CellType.quadrilateral}


class HistoryLaw(Law):
    """`law` (finite_strain, with or without history) on `mesh` in total Lagrangian form
    (module docstring); degree: the quadrature degree of the history (and of the residual)."""

    linear = False

    def __init__(self, law, mesh, degree=4):
        if not law.finite_strain:
            raise ValueError(f"{type(law).__name__}: HistoryLaw needs a finite-strain law")
        self.law, self.mesh, self.quadrature_degree = law, mesh, int(degree)
        self.modulus, self.p_modulus = law.modulus, law.p_modulus
        self.d = d = mesh.geometry.dim
        cell = mesh.ufl_cell()

        def space(dim):
            e = ufl.VectorElement("Quadrature", cell, self.quadrature_degree, dim=dim,
                                  quad_scheme="default")  # fmt: skip
            return fem.FunctionSpace(mesh, e)

        self.Fn = fem.Function(space(d * d), name="F_n")
        self.Fn.x.array.reshape(-1, d * d)[:] = np.eye(d).ravel()
        k = law.history_size
        self.history = fem.Function(space(k), name="history") if k else None
        if k:
            self.history.x.array.reshape(-1, k)[:] = np.asarray(law.initial_history, float)
        self.points = basix.make_quadrature(CELLS[cell.cellname()], self.quadrature_degree)[0]
        self._update = None

    def kinematics(self, u):
        F = ufl.Identity(self.d) + ufl.grad(u)
        return F, F * ufl.inv(as_tensor(self.Fn, self.d))

    def stress(self, u):
        F, f = self.kinematics(u)
        return self.law.kirchhoff(F, f, self.history) * ufl.inv(F).T

    def cauchy(self, u):
        F, f = self.kinematics(u)
        return self.law.kirchhoff(F, f, self.history) / ufl.det(F)

    def describe(self):
        return self.law.describe()

    def commit(self, u):
        """F_n <- F(u) and the history <- history_update at every quadrature point of the
        mesh (owned and ghost cells: each rank evaluates its own)."""
        if self._update is None or self._update[0] is not u:
            F, f = self.kinematics(u)
            parts = [F[i, j] for i in range(self.d) for j in range(self.d)]
            if self.history is not None:
                new = self.law.on(self.mesh).history_update(F, f, self.history)
                parts += [new[i] for i in range(self.law.history_size)]
            self._update = (u, fem.Expression(ufl.as_vector(parts), self.points))
        imap = self.mesh.topology.index_map(self.mesh.topology.dim)
        cells = np.arange(imap.size_local + imap.num_ghosts, dtype=np.int32)
        values = self._update[1].eval(cells).reshape(len(cells), len(self.points), -1)
        dd = self.d * self.d
        dofs = self.Fn.function_space.dofmap.list.array.reshape(len(cells), -1)
        self.Fn.x.array.reshape(-1, dd)[dofs.ravel()] = values[:, :, :dd].reshape(-1, dd)
        if self.history is not None:
            k = self.law.history_size
            hd = self.history.function_space.dofmap.list.array.reshape(len(cells), -1)
            self.history.x.array.reshape(-1, k)[hd.ravel()] = values[:, :, dd:].reshape(-1, k)
