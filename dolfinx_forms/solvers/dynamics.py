"""Implicit Newmark time stepping of a `ContactProblem` on a fixed mesh (the single-step paths).

Each body of density rho gets the inertia of the Newmark rule (beta, gamma; the trapezoidal
rule beta = 1/4, gamma = 1/2 conserves energy in the linear case, gamma > 1/2 with
beta = (gamma + 1/2)^2 / 4 damps the high frequencies):

    a_{n+1} = c0 (u - u_n - dt v_n) - c1 a_n,   c0 = 1 / (beta dt^2),  c1 = 1 / (2 beta) - 1,
    R(u) = F_int(u) + int rho a_{n+1} . w - f_ext = 0,
    v_{n+1} = v_n + dt ((1 - gamma) a_n + gamma a_{n+1}),

so the residual gains the linear mass term c0 int rho u . w (in each body's law, `Inertia`:
assembled with a linear law's stiffness, differentiated with a nonlinear one) and a load
int rho (c0 (u_n + dt v_n) + c1 a_n) . w re-assembled every step (`BulkForms.update_loads`).
Each time step ramps the load level lam from 0 to 1 (cut-back halves it): loads and Dirichlet
values that hold at t_{n+1} take scale / value 1 at any lam (gravity suddenly applied:
`BodyForce(..., scale=lambda lam: 1.0)`); the inertia load has scale 1.
"""

from __future__ import annotations

import ufl
from dolfinx import fem

from dolfinx_forms.fem.boundary import Load
from dolfinx_forms.fem.laws import Law, as_law

INTEGRATORS = {  # name -> (beta, gamma)
    "trapezoidal": (0.25, 0.5),
    "dissipative": (0.3025, 0.6),  # gamma = 0.6, beta = (gamma + 1/2)^2 / 4
}


def coefficients(beta, dt):
    """(c0, c1) = (1 / (beta dt^2), 1 / (2 beta) - 1) of the Newmark rule (module docstring)."""
    return 1.0 / (beta * dt**2), 1.0 / (2.0 * beta) - 1.0


def kinematics(du, v, a, dt, beta, gamma):
    """(v_{n+1}, a_{n+1}) of the Newmark rule from the step's increment du = u_{n+1} - u_n,
    v_n and a_n (arrays, any layout; module docstring)."""
    c0, c1 = coefficients(beta, dt)
    a_new = c0 * (du - dt * v) - c1 * a
    return v + dt * ((1.0 - gamma) * a + gamma * a_new), a_new


def _scalar(x):
    return x if isinstance(x, ufl.core.expr.Expr) else float(x)


class Inertia(Law):
    """A body's law plus the Newmark mass term c0 rho int u . w (module docstring) and, with
    viscous > 0, the damping term viscous int 2 sym grad u : grad w (the material point path's
    Kelvin-Voigt damping on the step's increment, mpm/dynamics.py: zero for a rigid
    translation, second order in a rigid rotation's angle)."""

    def __init__(self, law, rho, c0, degree=None, viscous=0.0):
        # rho, c0, viscous: numbers or UFL expressions (a fem.Constant keeps the compiled form
        # when the time step changes)
        self.law, self.rho, self.c0 = law, rho, _scalar(c0)
        self.viscous = _scalar(viscous)
        self.linear, self.modulus, self.p_modulus = law.linear, law.modulus, law.p_modulus
        self.quadrature_degree = degree or getattr(law, "quadrature_degree", None)

    def residual(self, u, v, dx):
        r = self.law.residual(u, v, dx) + self.c0 * self.rho * ufl.inner(u, v) * dx
        if not (isinstance(self.viscous, float) and self.viscous == 0):
            r += self.viscous * 2 * ufl.inner(ufl.sym(ufl.grad(u)), ufl.grad(v)) * dx
        return r

    def stress(self, u):
        return self.law.stress(u)

    def cauchy(self, u):
        return self.law.cauchy(u)

    def describe(self):
        rho = self.rho if isinstance(self.rho, (int, float)) else "projected"
        return dict(self.law.describe(), rho=rho)


class Newmark:
    """Newmark time stepping (module docstring). rho: {body tag: density}; dt: the time step;
    integrator: a name of INTEGRATORS or (beta, gamma).

        nm = Newmark({1: rho}, dt)
        problem = ContactProblem(scene, nm.laws(laws), loads=[*loads, *nm.loads()], ...)
        nm.start(problem)      # a_0 = M^-1 f_ext: at rest, undeformed, loaded at t = 0
        for n in range(steps):
            nm.step(problem)   # u, nm.v, nm.a at t_{n+1}
    """

    def __init__(self, rho, dt, integrator="trapezoidal"):
        self.rho = {int(t): float(r) for t, r in rho.items()}
        if not all(r > 0 for r in self.rho.values()) or not dt > 0:
            raise ValueError(f"Newmark: need rho > 0 and dt > 0, got {self.rho}, {dt}")
        beta, gamma = INTEGRATORS[integrator] if isinstance(integrator, str) else integrator
        self.dt, self.beta, self.gamma = float(dt), float(beta), float(gamma)
        self.c0, self.c1 = coefficients(beta, dt)
        self.u_n = self.v = self.a = None  # Functions on the problem's space (`loads`)
        self.time, self.steps = 0.0, 0

    def laws(self, laws):
        """The bodies' laws with their inertia (one Inertia per distinct law and density)."""
        made = {}
        out = {}
        for t, law in laws.items():
            law = as_law(law)
            key = (id(law), self.rho[int(t)])
            made.setdefault(key, Inertia(law, self.rho[int(t)], self.c0))
            out[t] = made[key]
        return out

    def loads(self):
        """The inertia loads int rho (c0 (u_n + dt v_n) + c1 a_n) . w of each body (scale 1)."""

        def form(tag, rho):
            def f(w, measure):
                if self.u_n is None:  # the problem's space, from its test function
                    V = w.ufl_function_space()
                    self.u_n, self.v, self.a = (fem.Function(V, name=n) for n in "uva")
                g = self.c0 * (self.u_n + self.dt * self.v) + self.c1 * self.a
                return rho * ufl.inner(g, w) * measure(tag)

            return f

        return [Load(form(t, r), scale=lambda lam: 1.0) for t, r in self.rho.items()]

    def start(self, problem):
        """The initial acceleration of a start at rest in the undeformed state:
        M a_0 = f_ext (at lam = 1; a_0 = 0 on Dirichlet dofs), so that the first step starts
        from equilibrium of the load applied at t = 0 (a_0 = 0 instead breaks the trapezoidal
        rule's energy conservation by O(dt^2))."""
        from petsc4py import PETSc

        V = problem.V
        w, z = ufl.TestFunction(V), ufl.TrialFunction(V)
        m = sum(rho * ufl.inner(z, w) * problem.bulk.measure(t) for t, rho in self.rho.items())
        M = fem.petsc.assemble_matrix(fem.form(m))
        M.assemble()
        M.zeroRowsColumns(problem.bc_global, 1.0)
        problem.bulk.update_loads()
        f = M.createVecLeft()
        problem.bulk.external(1.0, f)
        f.array[problem.bc_owned] = 0.0
        x = M.createVecRight()
        ksp = PETSc.KSP().create(problem.comm)
        ksp.setOperators(M)
        ksp.setType("preonly")
        ksp.getPC().setType("lu")
        ksp.solve(f, x)
        self.a.x.array[: len(x.array)] = x.array
        self.a.x.scatter_forward()

    def step(self, problem, label=None):
        """One time step: the inertia load of (u_n, v_n, a_n), the solve (lam from 0 to 1,
        module docstring), then a and v at t_{n+1} and u_n <- u. Raises ContactSolverError
        (u, v, a unchanged)."""
        problem.bulk.update_loads()
        problem.lam = 0.0  # the step's own ramp (the committed u is the step's start)
        problem.solve(1, 1.0, label=label or f"t = {self.time + self.dt:.6g}")
        u, un, v, a = (f.x.array for f in (problem.u, self.u_n, self.v, self.a))
        v[:], a[:] = kinematics(u - un, v, a, self.dt, self.beta, self.gamma)
        un[:] = u
        self.time += self.dt
        self.steps += 1

    def kinetic_energy(self, problem):
        """1/2 int rho v . v over the bodies (every rank's sum)."""
        mesh, total = problem.mesh, 0.0
        for t, rho in self.rho.items():
            e = 0.5 * rho * ufl.inner(self.v, self.v)
            total += fem.assemble_scalar(fem.form(e * problem.bulk.measure(t)))
        return mesh.comm.allreduce(total)
