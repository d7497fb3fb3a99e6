"""Implicit Newmark dynamics on the material-point path (solvers/dynamics.py on a fixed mesh).

The points carry velocity v and acceleration a. A step of length dt solves for the increment du
on Omega_n with a_{n+1} = c0 (du - dt v_n) - c1 a_n (c0 = 1 / (beta dt^2), c1 = 1 / (2 beta) - 1),
so the residual gains the mass term c0 int rho du . w (each body's law wrapped in
`solvers.dynamics.Inertia`) and the load int rho (c0 dt v_n + c1 a_n + g) . w. Optional
damping: a viscous stress 2 eta sym grad (du / dt), which a rigid translation does not feel,
and Rayleigh's mass-proportional drag alpha rho v (seed 004), which does (to settle deposits).
v, a and the current density rho = rho_0 vol0 / vol reach the Gauss points of the new cells by
the MLS projection (with the stress or F). `advance` controls the step size (a failed step is
undone and done again at half the step; the step grows back). After the step each point updates
a <- c0 (du - dt v) - c1 a and v <- v + dt ((1 - gamma) a_n + gamma a_{n+1}) with du the
converged increment at the point. Mass is rho_0 vol0 per point, constant.
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem
from petsc4py import PETSc

from dolfinx_forms.fem.boundary import Load
from dolfinx_forms.solvers.dynamics import INTEGRATORS, Inertia, coefficients, kinematics


class PointNewmark:
    """The Newmark rule of an ImplicitMPM (module docstring): rho {body tag: rho_0}, dt, the
    integrator (a name of solvers.dynamics.INTEGRATORS or (beta, gamma)), gravity (a vector
    per unit mass, any dimension)."""

    def __init__(self, rho, dt, integrator="trapezoidal", gravity=(0.0, 0.0), a0=None,
                 viscosity=0.0, mass_damping=0.0):  # fmt: skip
        self.rho = {int(t): float(r) for t, r in rho.items()}
        if not all(r > 0 for r in self.rho.values()) or not dt > 0:
            raise ValueError(f"dynamics: need rho > 0 and dt > 0, got {self.rho}, {dt}")
        beta, gamma = INTEGRATORS[integrator] if isinstance(integrator, str) else integrator
        self.beta, self.gamma = float(beta), float(gamma)
        self.set_dt(dt)
        self.gravity = np.asarray(gravity, float)
        # the points' acceleration when seeded: gravity's (exact for a body in free fall)
        self.a0 = self.gravity if a0 is None else np.asarray(a0, float)
        # Kelvin-Voigt damping: a viscous stress 2 viscosity sym grad (du / dt) on the step's
        # increment (no force for a rigid translation: rigid motions are not damped)
        if not viscosity >= 0:
            raise ValueError(f"dynamics: need viscosity >= 0, got {viscosity}")
        self.viscosity = float(viscosity)
        # Rayleigh's mass-proportional damping (seed 004's C = alpha M + beta K, the alpha
        # part): a drag alpha rho v_{n+1}, which does slow rigid motions; for settling a
        # deposit (terminal velocity g / alpha), off by default
        if not mass_damping >= 0:
            raise ValueError(f"dynamics: need mass_damping >= 0, got {mass_damping}")
        self.mass_damping = float(mass_damping)
        self.time = 0.0

    def set_dt(self, dt):
        """The time step of the next steps (c0, c1 with it)."""
        self.dt = float(dt)
        self.c0, self.c1 = coefficients(self.beta, self.dt)

    def advance(self, sim, t_end, dt_min=None, grow_after=4, log=print, prepare=None):
        """Steps of sim (an ImplicitMPM with this rule) to time t_end with step-size control:
        a step that fails (ContactSolverError, RuntimeError: the simulation is restored to the
        state before it, points, level sets, friction and multiplier records, time) is done
        again at half the time step, down to dt_min (default dt / 64); after grow_after
        accepted steps the step doubles again, up to the dt given at construction. Yields
        each accepted step's record, with its dt and `retries` (the failed tries before it);
        ContactSolverError when dt_min fails. prepare(t, dt), if given, is called before each
        try (e.g. to set the obstacles' motion over [t, t + dt])."""
        from dolfinx_forms.solvers.newton import ContactSolverError

        dt_max, good, retries = self.dt, 0, 0
        dt_min = dt_max / 64 if dt_min is None else float(dt_min)
        while self.time < t_end - 1e-12 * max(1.0, abs(t_end)):
            self.set_dt(min(self.dt, t_end - self.time))
            if prepare is not None:
                prepare(self.time, self.dt)
            try:
                record = sim.step()
            except (ContactSolverError, RuntimeError) as e:
                if self.dt / 2 < dt_min * (1 - 1e-12):
                    raise ContactSolverError(
                        f"t = {self.time:.6g}: the step failed down to dt = {self.dt:.3g} "
                        f"(dt_min {dt_min:.3g}): {e}"
                    ) from e
                self.set_dt(self.dt / 2)
                good, retries = 0, retries + 1
                log(f"t = {self.time:.6g}: step failed, dt halved to {self.dt:.4g} ({e})")
                continue
            record["dt"], record["retries"], retries = self.dt, retries, 0
            good += 1
            if good >= grow_after and self.dt < dt_max:
                self.set_dt(min(2 * self.dt, dt_max))
                good = 0
            yield record

    @staticmethod
    def point_values(points, rho0):
        """(n, 2 d + 1): [v, a, current density] of a body's points (the MLS columns)."""
        rho = rho0 * points.vol0 / points.vol
        return np.concatenate([points.v, points.a, rho[:, None]], axis=1)

    def laws(self, laws, q, degree):
        """Each body's law with the mass term c0 rho_q du . w (q: the projected columns at
        the Gauss points of `degree`)."""
        d = len(self.gravity)
        made, out = {}, {}
        # the drag's du part: alpha rho gamma dt a_{n+1} has c0 du in it
        c0 = self._constant(q, self.c0 * (1 + self.mass_damping * self.gamma * self.dt))
        viscous = self._constant(q, self.viscosity / self.dt) if self.viscosity > 0 else 0.0
        for t, law in laws.items():
            made.setdefault(id(law), Inertia(law, q[2 * d], c0, degree, viscous))
            out[t] = made[id(law)]
        return out

    @staticmethod
    def _constant(q, value):
        """value as a fem.Constant on q's mesh: the forms' code does not change with dt (one
        compilation for all the step sizes of a run)."""
        return fem.Constant(q.function_space.mesh, PETSc.ScalarType(value))

    def load(self, q, degree):
        """int rho_q (c0 dt v_q + c1 a_q + g) . w over all bodies (scale 1); with the drag
        alpha rho v_{n+1}, v_{n+1} = v + dt (1 - gamma) a + gamma dt a_{n+1}, its known part
        too: rho [(c0 dt v + c1 a)(1 + alpha gamma dt) - alpha (v + dt (1 - gamma) a)]."""
        d = len(self.gravity)
        v, a = ufl.as_vector([q[i] for i in range(d)]), ufl.as_vector([q[d + i] for i in range(d)])
        g = ufl.as_vector([float(c) for c in self.gravity])
        al, gdt = self.mass_damping, self.gamma * self.dt
        kv = self._constant(q, self.c0 * self.dt * (1 + al * gdt) - al)
        ka = self._constant(q, self.c1 * (1 + al * gdt) - al * (self.dt - gdt))
        f = q[2 * d] * (kv * v + ka * a + g)
        return Load(lambda w, measure: ufl.inner(f, w) * measure(None, degree=degree),
                    scale=lambda lam: 1.0)  # fmt: skip

    def update(self, points, du):
        """a and v of the points from the converged increment du (n, d); in place."""
        points.v, points.a = kinematics(du, points.v, points.a, self.dt, self.beta, self.gamma)

    def kinetic_energy(self, points, rho0):
        return 0.5 * float(np.sum(rho0 * points.vol0 * np.sum(points.v**2, axis=1)))
