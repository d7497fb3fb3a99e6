"""Small-strain frictional contact between elastic bodies: assembly and Newton.

Bulk: plane-strain linear elasticity per body, a UFL form compiled by FFCx and assembled once
(it is linear). Contact: the C++ kernel of eq 48 adds, at every Newton iteration, the penalty
residual and its consistent tangent (Algorithm 1) into the same PETSc matrix, whose sparsity
pattern holds the mesh couplings *and* the contact coupling blocks (built once per scene).

Newton on  R(u) = K u - f(lam) + r_c(u) = 0  with Dirichlet values imposed on u and homogeneous
ones on the increment. Load steps lam in (0, 1]; a step that fails (no convergence in
`max_iterations`, a repeated active set without residual decrease, a solver failure, a
non-finite residual) is cut back: u and the friction history return exactly to the last
committed state and the step is halved, at most `max_cutbacks` times.
"""

import time
from dataclasses import dataclass, field

import numpy as np
import ufl
from dolfinx import cpp as _dcpp
from dolfinx import fem, la
from mpi4py import MPI
from petsc4py import PETSc

from . import _cpp
from .contact import pair_geometry

STATE_NAMES = {0: "open", 1: "stick", 2: "slip"}


class ContactSolverError(RuntimeError):
    """Newton/linear-solver failure, with the load step and iteration where it happened."""


@dataclass
class Dirichlet:
    """u[component] = value(lam) on a tagged boundary (component None: both components).

    boundary: a facet-tag name of the scene, or a callable marker x (3, n) -> bool selecting
    dofs geometrically (e.g. a single point)."""

    boundary: object
    component: object
    value: object = 0.0  # float or callable(lam) -> float

    def at(self, lam):
        return self.value(lam) if callable(self.value) else float(self.value)


@dataclass
class Traction:
    """Surface traction t(x) (a UFL vector) on a tagged boundary, scaled by scale(lam)."""

    boundary: str
    traction: object
    scale: object = None  # callable(lam) -> float; default lam

    def at(self, lam):
        return lam if self.scale is None else self.scale(lam)


@dataclass
class NewtonOptions:
    rtol: float = 1e-10          # residual relative to the first residual of the step
    atol: float = 1e-12          # absolute residual floor (force units)
    stol: float = 1e-12          # increment relative to |u|
    max_iterations: int = 25
    max_cutbacks: int = 6
    fd_tangent: bool = False     # verification only: central differences of the contact residual
    fd_step: float = 1e-9


@dataclass
class StepLog:
    lam: float
    iterations: int
    residuals: list = field(default_factory=list)
    cutback: bool = False


def plane_strain(E, nu):
    """Lame parameters (mu, lambda) of plane strain."""
    return E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))


class ContactProblem:
    """Elastic bodies of a `meshes.scene.Scene` in frictional contact (penalty, eqs 8-12, 48).

    materials: {body tag: (E, nu)}; mu: friction coefficient (0: frictionless, no friction
    work); eps0: penalty factor of eq 51, eps_n = eps_t = eps0 h / E_mean; band: largest
    initial gap that Gamma_c covers (a length); degree: Lagrange degree (1 or 2; 1 on a cut
    scene). A scene with `cut` data (meshes.cut) gets the cut-cell forms of `cut.CutForms`
    with ghost penalty `ghost_penalty` (0: none).
    """

    def __init__(self, scene, materials, *, mu=0.0, eps0=1.0, band=None, degree=1,
                 dirichlet=(), tractions=(), newton=None, petsc_options=None, grid_refine=4,
                 num_gauss=2, timer=None, contact_rank=0, ghost_penalty=0.01, log=print):
        self.scene, self.mesh = scene, scene.mesh
        self.comm = self.mesh.comm
        self.mu = float(mu)
        self.newton = newton or NewtonOptions()
        self.timer = timer
        self.log = log if self.comm.rank == 0 else (lambda *a, **k: None)
        tdim = self.mesh.topology.dim

        with self._phase("assembly"):
            self.V = fem.VectorFunctionSpace(self.mesh, ("Lagrange", degree))
            self.u = fem.Function(self.V, name="u")
            self._rc = fem.Function(self.V)  # contact residual, scattered in reverse
            du, v = ufl.TrialFunction(self.V), ufl.TestFunction(self.V)
            dx = ufl.Measure("dx", domain=self.mesh, subdomain_data=scene.cell_tags)
            ds = ufl.Measure("ds", domain=self.mesh, subdomain_data=scene.facet_tags)
            eps = lambda w: ufl.sym(ufl.grad(w))  # noqa: E731
            self.E = {tag: E for tag, (E, _) in materials.items()}
            self.materials = dict(materials)
            self.cut = None
            if getattr(scene, "cut", None) is not None:  # cut cells: C++ kernels in the Form
                from .cut import CutForms

                self.cut = CutForms(self.V, scene, materials, ghost_penalty=ghost_penalty)
                self.a_form = self.cut.a
            else:
                a = 0
                for tag, (E, nu) in materials.items():
                    m, lmb = plane_strain(E, nu)
                    sig = 2 * m * eps(du) + lmb * ufl.tr(eps(du)) * ufl.Identity(2)
                    a += ufl.inner(sig, eps(v)) * dx(tag)
                self.a_form = fem.form(a)
            self.tractions = list(tractions)
            self.f_vectors = []
            for t in self.tractions:
                tag = scene.boundaries[t.boundary]
                L = (self.cut.traction_form(t.traction, tag) if self.cut is not None
                     else fem.form(ufl.inner(t.traction, v) * ds(tag)))
                self.f_vectors.append(fem.petsc.assemble_vector(L))
                self.f_vectors[-1].ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)

            self.dirichlet = list(dirichlet)
            fdim = tdim - 1
            self.bc_dofs = []  # per condition: local unrolled dof indices (owned + ghost)
            for d in self.dirichlet:
                comps = [0, 1] if d.component is None else [d.component]
                if callable(d.boundary):
                    dofs = [fem.locate_dofs_geometrical((self.V.sub(c), self.V.sub(c).collapse()[0]),
                                                        d.boundary)[0] for c in comps]
                else:
                    facets = scene.facet_tags.find(scene.boundaries[d.boundary])
                    dofs = [fem.locate_dofs_topological(self.V.sub(c), fdim, facets) for c in comps]
                self.bc_dofs.append(np.concatenate(dofs).astype(np.int32))
            imap = self.V.dofmap.index_map
            self.bs = self.V.dofmap.index_map_bs
            self.n_owned = imap.size_local * self.bs
            all_bc = np.unique(np.concatenate(self.bc_dofs)) if self.bc_dofs else np.zeros(0, np.int32)
            self.bc_owned = all_bc[all_bc < self.n_owned].astype(np.int32)
            self.bc_global = (self.bc_owned + imap.local_range[0] * self.bs).astype(np.int32)

        # Contact geometry, once per scene (reference configuration)
        h = scene.h_contact
        E_mean = np.mean(list(self.E.values()))
        self.eps_n = self.eps_t = eps0 * h / E_mean  # eq 51
        self.pairs = []
        with self._phase("contact"):
            if self.comm.rank == contact_rank:
                for pair in scene.pairs:
                    g = pair_geometry(self.V, scene, pair, band if band is not None else 2 * h,
                                      grid_refine=grid_refine, num_gauss=num_gauss)
                    if g is not None:
                        self.pairs.append(g)
        # Friction history per pair: committed and trial plastic slip (absent when mu == 0)
        self.gtp = [None] * len(self.pairs)
        self.gtp_trial = [None] * len(self.pairs)
        self.gtp_start = [np.zeros(len(g.weights)) for g in self.pairs]
        if self.mu > 0:  # friction from the start: zero plastic slip in the reference state
            self.gtp = [np.zeros(len(g.weights)) for g in self.pairs]
        self.last = [None] * len(self.pairs)
        self.committed = [None] * len(self.pairs)  # point states of the last accepted step

        with self._phase("assembly"):
            # Sparsity: mesh couplings + contact coupling blocks; the pattern never changes.
            pattern = _dcpp.fem.create_sparsity_pattern(
                self.mesh.topology, [self.V.dofmap._cpp_object, self.V.dofmap._cpp_object],
                {_dcpp.fem.IntegralType.cell})
            for g in self.pairs:
                _cpp.insert_coupling(pattern, g.quadrature)
            if self.cut is not None:
                self.cut.insert_ghost_couplings(pattern)
            pattern.assemble()
            self.K = _dcpp.la.petsc.create_matrix(self.comm, pattern)
            self.K.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
            fem.petsc.assemble_matrix(self.K, self.a_form)
            self.K.assemblyBegin(PETSc.Mat.AssemblyType.FLUSH)  # assemble_matrix ends in INSERT
            self.K.assemblyEnd(PETSc.Mat.AssemblyType.FLUSH)
            for g in self.pairs:
                _cpp.add_coupling_zeros(self.K, g.quadrature)
            self.K.assemble()
            self.J = self.K.duplicate(copy=False)
            self.J.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
            # zeroRows must not shrink the pattern: MatCopy(SAME_NONZERO_PATTERN) each
            # iteration and the reuse of the symbolic LU factorisation depend on it
            self.J.setOption(PETSc.Mat.Option.KEEP_NONZERO_PATTERN, True)
            self.R = self.K.createVecLeft()
            self.Ku = self.K.createVecLeft()
            self.du = fem.Function(self.V)
            self.num_dofs = imap.size_global * self.bs

        self.ksp = PETSc.KSP().create(self.comm)
        self.ksp.setOptionsPrefix("ils_")
        opts = PETSc.Options()
        defaults = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
        for k, v in {**defaults, **(petsc_options or {})}.items():
            opts["ils_" + k] = v
        self.ksp.setFromOptions()
        self.u_committed = self.u.x.array.copy()
        self.lam = 0.0
        self.steps = []

    # ------------------------------------------------------------------ utilities
    def _phase(self, name):
        if self.timer is None:
            from contextlib import nullcontext
            return nullcontext()
        return self.timer.phase(name)

    def set_friction(self, mu):
        """Change mu between stages. Switching friction on starts from zero tangential
        traction: the committed plastic slip is the current tangential gap."""
        mu = float(mu)
        if mu > 0 and self.mu == 0:
            for k, g in enumerate(self.pairs):
                s = _cpp.assemble_contact(g.quadrature, self.eps_n, self.eps_t, 0.0,
                                          self.u.x.array, np.zeros(0))
                self.gtp[k] = s["g_t"].copy()
            self.gtp_start = [g.copy() for g in self.gtp]
        if mu == 0:
            self.gtp = [None] * len(self.pairs)
        self.mu = mu

    def _set_bc_values(self, lam):
        x = self.u.x.array
        for d, dofs in zip(self.dirichlet, self.bc_dofs):
            x[dofs] = d.at(lam)

    def _external_force(self, lam):
        f = self.R.duplicate()
        f.set(0.0)
        for t, F in zip(self.tractions, self.f_vectors):
            f.axpy(t.at(lam), F)
        return f

    def residual(self, lam, with_tangent=False, zero_bc=True):
        """R = K u - f(lam) + r_c(u) (owned part); with_tangent also fills self.J."""
        with self._phase("assembly"):
            self.u.x.scatter_forward()
            self.K.mult(self.u.vector, self.Ku)
            self.Ku.copy(self.R)
            self.R.axpy(-1.0, self._external_force(lam))
            if with_tangent:
                self.K.copy(self.J, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        with self._phase("contact"):
            self._rc.x.array[:] = 0.0
            for k, g in enumerate(self.pairs):
                gtp = self.gtp[k] if self.mu > 0 else np.zeros(0)
                s = _cpp.assemble_contact(g.quadrature, self.eps_n, self.eps_t, self.mu,
                                          self.u.x.array, gtp, self._rc.x.array,
                                          self.J if with_tangent else None,
                                          self.newton.fd_tangent, self.newton.fd_step)
                self.last[k] = s
                self.gtp_trial[k] = s["gtp_trial"]
            self._rc.x.scatter_reverse(la.ScatterMode.add)
        with self._phase("assembly"):
            self.R.array[:] += self._rc.x.array[: self.n_owned]
            if with_tangent:
                self.J.assemble()
                self.J.zeroRows(self.bc_global, diag=1.0)
            if zero_bc:
                self.R.array[self.bc_owned] = 0.0
        return self.R.norm()

    def _active_signature(self):
        return tuple(s["state"].tobytes() for s in self.last if s is not None)

    # ------------------------------------------------------------------ Newton
    def _newton(self, lam):
        """Newton at load level lam from the committed state. Returns (ok, residuals, why)."""
        opts = self.newton
        self._set_bc_values(lam)
        residuals, seen = [], {}
        r0 = None
        for it in range(opts.max_iterations + 1):
            r = self.residual(lam, with_tangent=True)
            residuals.append(r)
            if not np.isfinite(r):
                return False, residuals, f"non-finite residual at iteration {it}"
            if r0 is None:
                r0 = max(r, opts.atol)
            if r <= max(opts.rtol * r0, opts.atol):
                return True, residuals, ""
            if it > 0:
                dnorm, unorm = self.du.vector.norm(), self.u.vector.norm()
                if dnorm <= opts.stol * max(unorm, 1e-300) and r <= np.sqrt(opts.rtol) * r0:
                    return True, residuals, ""
            # An active set seen before without a lower residual: Newton is cycling. The
            # states live on the contact rank only: the decision must be collective.
            sig = self._active_signature()
            cycling = self.comm.allreduce(bool(sig) and sig in seen and r >= 0.999 * seen[sig],
                                          op=MPI.LOR)
            if cycling:
                return False, residuals, f"active set cycles (iteration {it})"
            seen[sig] = min(r, seen.get(sig, np.inf))
            if it == opts.max_iterations:
                break
            with self._phase("solve"):
                self.R.scale(-1.0)
                try:
                    self.ksp.setOperators(self.J)
                    self.ksp.solve(self.R, self.du.vector)
                except PETSc.Error as e:
                    return False, residuals, f"linear solver error {e.ierr} at iteration {it}"
                reason = self.ksp.getConvergedReason()
                if reason < 0:
                    return False, residuals, f"linear solver diverged (reason {reason}) at iteration {it}"
            self.du.x.scatter_forward()
            self.u.x.array[:] += self.du.x.array
        return False, residuals, f"no convergence in {opts.max_iterations} iterations"

    def _commit(self, lam):
        # Keep the accepted step's point states: re-evaluating them with the committed slip
        # would put the slipped points exactly on the cone, where stick/slip is a coin toss.
        self.committed = [dict(s) for s in self.last]
        self.u_committed[:] = self.u.x.array
        if self.mu > 0:
            self.gtp = [g.copy() for g in self.gtp_trial]
        self.lam = lam

    def _restore(self):
        self.u.x.array[:] = self.u_committed
        self.u.x.scatter_forward()

    def solve(self, num_steps=1, lam_end=1.0, label="step", initial_guess=None):
        """Ramp the load from the committed level to lam_end in num_steps equal steps, with
        cut-back. initial_guess(problem, lam) may set u before the first Newton iteration of a
        step (e.g. to establish contact under force control). Raises ContactSolverError."""
        lam0 = self.lam
        dlam = (lam_end - lam0) / num_steps
        target = lam0
        cuts = 0
        while self.lam < lam_end - 1e-14 * max(1.0, abs(lam_end)):
            target = min(self.lam + dlam, lam_end)
            if initial_guess is not None:
                initial_guess(self, target)
            t0 = time.perf_counter()
            ok, residuals, why = self._newton(target)
            if ok:
                self._commit(target)
                self.steps.append(StepLog(target, len(residuals) - 1, residuals, cuts > 0))
                states = np.concatenate([s["state"] for s in self.last]) if self.last else np.zeros(0)
                nst = self.comm.allreduce(np.bincount(states.astype(int), minlength=3), MPI.SUM)
                self.log(f"{label} lam={target:.4f}: {len(residuals) - 1} Newton iterations, "
                         f"|R| {residuals[0]:.2e} -> {residuals[-1]:.2e}, "
                         f"open/stick/slip {nst[0]}/{nst[1]}/{nst[2]} "
                         f"({time.perf_counter() - t0:.2f} s)")
                continue
            self._restore()
            cuts += 1
            if cuts > self.newton.max_cutbacks:
                raise ContactSolverError(
                    f"{label}: Newton failed at load level {target:.6g} ({why}); residuals "
                    + ", ".join(f"{r:.3e}" for r in residuals[-5:])
                    + f"; gave up after {self.newton.max_cutbacks} step cut-backs")
            dlam /= 2
            self.log(f"{label} lam={target:.4f}: {why}; cutting the step to {dlam:.4g}")

    # ------------------------------------------------------------------ outputs
    def reaction(self, boundary):
        """Force [Fx, Fy] exerted by the supports on the body at a tagged boundary: the
        residual K u + r_c - f summed over the boundary's dofs (all components)."""
        self.residual(self.lam, zero_bc=False)
        facets = self.scene.facet_tags.find(self.scene.boundaries[boundary])
        F = np.zeros(2)
        for c in range(2):
            dofs = fem.locate_dofs_topological(self.V.sub(c), self.mesh.topology.dim - 1, facets)
            F[c] = np.sum(self.R.array[dofs[dofs < self.n_owned]])
        return self.comm.allreduce(F, MPI.SUM)

    def contact_points(self):
        """Per-point records of all pairs on this rank (reference configuration)."""
        out = []
        for k, g in enumerate(self.pairs):
            s = self.committed[k]
            if s is None:  # nothing solved yet
                s = _cpp.assemble_contact(g.quadrature, self.eps_n, self.eps_t, self.mu,
                                          self.u.x.array,
                                          self.gtp[k] if self.mu > 0 else np.zeros(0))
            # plastic slip accumulated since friction was switched on (mu = 0: all of g_t)
            slip = self.gtp[k] - self.gtp_start[k] if self.mu > 0 else s["g_t"]
            out.append(dict(x=g.points[:, 0], y=g.points[:, 1], w=g.weights, normals=g.normals,
                            p_n=-s["tau_n"], p_t=s["tau_t"], gap_n=s["g_n"], slip=slip,
                            state=s["state"]))
        return out


def solver_metrics(problem, converged=True):
    """The `solver` block of metrics.json."""
    return {"load_steps": len(problem.steps),
            "newton_iterations": [s.iterations for s in problem.steps],
            "converged": bool(converged),
            "residual_history": [[float(r) for r in s.residuals] for s in problem.steps],
            "penalty": {"eps_n": problem.eps_n, "eps_t": problem.eps_t},
            "cutbacks": int(sum(s.cutback for s in problem.steps))}


def zone_ends(x, inside, gap=None):
    """Left and right ends of the zone where `inside` holds (x sorted). With `gap` the ends are
    interpolated to the zero of gap between the last inside and first outside point, else the
    midpoint between them is used. Returns (None, None) for an empty zone."""
    idx = np.flatnonzero(inside)
    if idx.size == 0:
        return None, None
    ends = []
    for k, nb in ((idx[0], idx[0] - 1), (idx[-1], idx[-1] + 1)):
        if nb < 0 or nb >= len(x):
            ends.append(x[k])
        elif gap is not None and gap[nb] > 0 > gap[k]:
            ends.append(x[nb] + (x[k] - x[nb]) * gap[nb] / (gap[nb] - gap[k]))
        else:
            ends.append(0.5 * (x[k] + x[nb]))
    return ends[0], ends[1]
