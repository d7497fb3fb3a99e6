"""Frictional contact between bodies with UFL laws: the problem that ties the parts together.

R(u) = F_bulk(u) - f(lam) + r_c(u) = 0, Dirichlet values imposed on u and homogeneous ones on the
increment, solved by Newton with load steps and cut-back (`newton.py`). The parts:

* `bulk.BulkForms`: each body's UFL law (`laws.py`) on its material (body-fitted cells, or the
  inside part of cut cells with moment-fitted weights, `cut.py`), loads and tractions; linear
  laws assembled once into K, nonlinear ones at every iteration;
* `contact_set.ContactSet`: the pairs' contact points (eqs 21-25, built once per scene in the
  reference configuration) and their friction history; the C++ kernel of eq 48 adds the
  penalty residual and its consistent tangent (Algorithm 1) into the same PETSc matrix, whose
  sparsity pattern holds the mesh couplings *and* the contact coupling blocks;
* `boundary.py`: Dirichlet conditions, tractions, body forces and any UFL load.
"""

from contextlib import nullcontext

import numpy as np
from dolfinx import cpp as _dcpp
from dolfinx import fem, la
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_forms import defaults
from dolfinx_forms.contact.contact_set import ContactSet
from dolfinx_forms.contact.penalty import contact_modulus, penalty_parameter
from dolfinx_forms.fem.boundary import dirichlet_dofs
from dolfinx_forms.fem.bulk import BulkForms
from dolfinx_forms.fem.laws import as_law
from dolfinx_forms.geometry.pairs import DEFAULT_MULTIPLIER_MASS, MULTIPLIER_MASSES, TRACTIONS
from dolfinx_forms.solvers import blas, linear
from dolfinx_forms.solvers.newton import NewtonOptions, load_steps

# the tuned factors of the augmented Lagrangian's regularisation and the BLAS threshold are
# read from dolfinx_forms.defaults.TUNING when a problem is made (their studies: STUDIES there)


class ContactProblem:
    """Bodies of a `dolfinx_forms.mesh.scene.Scene` in frictional contact (penalty, eqs 8-12, 48).

    materials: {body tag: Law or (E, nu)} (`laws.py`; (E, nu) is `LinearElastic`); mu:
    friction coefficient (0: frictionless, no friction work); eps0: penalty factor of eq 51,
    eps_n = eps_t = eps0 h / E_c, E_c the most compliant contact's modulus
    (`contact.penalty.contact_modulus`: E on equal moduli, 2 E against a rigid obstacle); band:
    largest
    initial gap that Gamma_c covers (a length); degree: Lagrange degree (1 or 2; 1 on a cut
    scene); loads: `BodyForce`/`Load`s; quadrature_degree: see `BulkForms`. A scene with `cut`
    data (meshes.cut) integrates over the inside part of cut cells (`cut.CutIntegration`,
    degree `cut_degree`) with ghost penalty `ghost_penalty` (0: none). obstacles: rigid
    `obstacles.RigidObstacle`s (no dofs) whose step motion is ramped with lam.
    rigid_mode_stiffness: alpha of a spring alpha E / L^2 on every body's displacement, for
    bodies held by contact alone (free grains); it changes the answer by ~alpha (0: none).
    predictor_gap: in the first Newton iteration of a step, open contact points with a gap
    below it add a closed point's tangent (no force), so bodies whose contacts touch but are
    not closed yet are held (a length; 0: exact tangent throughout; the answer is unchanged).
    pair_grid_origin: None, or a point through which every pair's level-set grid passes
    (`contact.pair_geometry`'s lattice_origin: symmetric scenes stay symmetric).
    enforcement: "penalty" (the answer depends on eps0) or "augmented" (augmented Lagrangian,
    Uzawa loop, `contact_set`: eps0 sets only the loop's speed). multipliers: None (a traction
    per contact point), "P0" or "P1": one traction per multiplier node along Gamma_c, nodes
    multiplier_length apart (`contact.multiplier_nodes`: a stable pressure at any eps0);
    default "P1" with "augmented", None with "penalty". multiplier_length: default h body-fitted,
    1.5 h cut (Hertz at h = a/20, P1: 0.5 h and, on the cut path, 0.75 h give a checkerboard;
    p(x) 1.9 / 2.3 / 3.1 % body-fitted at 0.75 / 1 / 1.5 h, 3.9 / 3.4 % cut at 1 / 1.5 h, with
    traction "nodes"). traction: "nodes" (the law on each node's weighted mean gap) or "points"
    (the law at each point with the multipliers interpolated, `contact_set`; the kernel's eps_n
    and eps_t are then the tuned factors pointwise_eps0 and pointwise_eps0_t (defaults.TUNING)
    times h / E_c (eq 51), and
    eps0 relaxes the Uzawa step by min(1, eps_n / eps));
    default "points" with "augmented". multiplier_mass (augmented, P1, traction "points"):
    "hybrid" (default: zero weighted gap on the closed part of every node mostly in contact,
    the lumped projection at the contact edge), "consistent" (zero weighted mean gap at every
    node in contact, a coarser pressure) or "lumped" (weighted gaps ~1e-3 h); the first two
    with eps_n = consistent_eps0 h / E_c and nodes consistent_length h apart by default
    (defaults.TUNING)
    (`contact_set`).
    linear_solver: "auto", "condensed", "factorised" or "iterative" (`linear.py`: a linear bulk
    on one process is factorised once, with Newton on the Schur complement of the contact dofs;
    "iterative": CG + GAMG with the rigid-body modes, chosen by "auto" for large body-fitted
    problems).
    """

    def __init__(
        self,
        scene,
        materials,
        *,
        mu=0.0,
        eps0=1.0,
        band=None,
        degree=1,
        dirichlet=(),
        tractions=(),
        loads=(),
        newton=None,
        petsc_options=None,
        grid_refine=4,
        num_gauss=2,
        timer=None,
        contact_rank=0,
        ghost_penalty=0.01,
        quadrature_degree=None,
        cut_degree=4,
        obstacles=(),
        rigid_mode_stiffness=0.0,
        predictor_gap=0.0,
        pair_grid_origin=None,
        enforcement="penalty",
        multipliers="default",
        multiplier_length=None,
        traction="default",
        multiplier_mass=None,
        linear_solver="auto",
        log=print,
    ):
        self.scene, self.mesh = scene, scene.mesh
        self.comm = self.mesh.comm
        self.newton = newton or NewtonOptions()
        self.timer = timer
        self.log = log if self.comm.rank == 0 else (lambda *a, **k: None)
        self.predictor_gap = float(predictor_gap)
        self.rigid_mode_stiffness = float(rigid_mode_stiffness)  # checks.unheld_bodies
        self.laws = {int(t): as_law(m) for t, m in materials.items()}
        self.materials = self.laws

        with self.phase("assembly"):
            self.integration = None
            if getattr(scene, "cut", None) is not None:
                if degree != 1 or scene.cell_type != "quadrilateral":
                    raise ValueError(
                        "degree: the cut path supports Q1 (degree 1) on " "quadrilaterals only"
                    )
                from dolfinx_forms.fem.cut import CutIntegration

                self.integration = CutIntegration(scene, degree=cut_degree)
            self.V = fem.VectorFunctionSpace(self.mesh, ("Lagrange", degree))
            self.u = fem.Function(self.V, name="u")
            self.du = fem.Function(self.V)
            self._rc = fem.Function(self.V)  # contact residual, scattered in reverse
            self.bulk = BulkForms(
                self.u,
                scene,
                self.laws,
                tractions=tractions,
                loads=loads,
                integration=self.integration,
                ghost_penalty=ghost_penalty,
                quadrature_degree=quadrature_degree,
                rigid_mode_stiffness=rigid_mode_stiffness,
            )
            self.dirichlet = list(dirichlet)
            self.bc_dofs = [dirichlet_dofs(self.V, scene, d) for d in self.dirichlet]
            imap = self.V.dofmap.index_map
            self.bs = self.V.dofmap.index_map_bs
            self.n_owned = imap.size_local * self.bs
            self.num_dofs = imap.size_global * self.bs
            # small problems (and MPI ranks sharing the cores) run their dense kernels on one
            # BLAS thread: faster, and no spinning threads waiting for a busy core (`blas`)
            small = self.num_dofs < defaults.TUNING.blas_one_thread_dofs
            blas.threads_for(self.comm.size > 1 or small)
            all_bc = (
                np.unique(np.concatenate(self.bc_dofs)) if self.bc_dofs else np.zeros(0, np.int32)
            )
            self.bc_owned = all_bc[all_bc < self.n_owned].astype(np.int32)
            self.bc_global = (self.bc_owned + imap.local_range[0] * self.bs).astype(np.int32)

        h = scene.h_contact
        self.band = band if band is not None else 2 * h
        E_c = contact_modulus(scene, self.laws, obstacles)
        self.eps_n = self.eps_t = penalty_parameter(eps0, h, E_c)  # eq 51
        if multipliers == "default":
            multipliers = "P1" if enforcement == "augmented" else None
        if traction == "default":
            traction = "points" if enforcement == "augmented" else "nodes"
        if traction not in TRACTIONS:
            raise ValueError(f"traction must be one of {TRACTIONS}, got {traction!r}")
        projected = enforcement == "augmented" and multipliers == "P1" and traction == "points"
        if multiplier_mass is None:  # the default where Uzawa projects on P1 nodes
            multiplier_mass = DEFAULT_MULTIPLIER_MASS if projected else "lumped"
        if multiplier_mass not in MULTIPLIER_MASSES:
            raise ValueError(
                f"multiplier_mass must be one of {MULTIPLIER_MASSES}, got {multiplier_mass!r}"
            )
        consistent = multiplier_mass != "lumped"  # "consistent" or "hybrid"
        self.multiplier_mass = multiplier_mass
        if consistent and not projected:
            raise ValueError(
                f"multiplier_mass {multiplier_mass!r} needs enforcement 'augmented' with P1 "
                f"multipliers and traction 'points', got {enforcement!r}, {multipliers!r}, "
                f"{traction!r}"
            )
        relaxation, eps_t_start, tune = 1.0, None, defaults.TUNING
        if enforcement == "augmented" and multipliers is not None and traction == "points":
            # the point-wise regularisation is part of the discretisation; eps0 sets the step
            k_n = tune.consistent_eps0 if consistent else tune.pointwise_eps0
            fine = penalty_parameter(k_n, h, E_c)
            relaxation = min(1.0, fine / self.eps_n)
            self.eps_n, self.eps_t = fine, penalty_parameter(tune.pointwise_eps0_t, h, E_c)
            eps_t_start = self.eps_t
            if consistent:
                self.eps_t = penalty_parameter(tune.consistent_eps0_t, h, E_c)
        if multiplier_length is None:
            spacing = 1.5 if self.integration is not None else 1.0  # the lumped projection's
            multiplier_length = h * (tune.consistent_length if consistent else spacing)
        with self.phase("contact"):
            self.contact = ContactSet(
                self.V,
                scene,
                self.eps_n,
                self.eps_t,
                mu,
                self.band,
                grid_refine,
                num_gauss,
                contact_rank,
                obstacles,
                pair_grid_origin,
                multipliers=multipliers,
                multiplier_length=multiplier_length,
                enforcement=enforcement,
                traction=traction,
                relaxation=relaxation,
                multiplier_mass=multiplier_mass,
                eps_t_start=eps_t_start,
            )
        self.pairs = self.contact.pairs

        with self.phase("assembly"):
            # Sparsity: mesh couplings + contact coupling blocks (+ ghost-penalty cell pairs);
            # the pattern never changes.
            pattern = _dcpp.fem.create_sparsity_pattern(
                self.mesh.topology,
                [self.V.dofmap._cpp_object, self.V.dofmap._cpp_object],
                {_dcpp.fem.IntegralType.cell},
            )
            self.contact.insert_couplings(pattern)
            if self.integration is not None and ghost_penalty > 0:
                self.integration.insert_ghost_couplings(pattern, self.V)
            pattern.assemble()
            self.K = _dcpp.la.petsc.create_matrix(self.comm, pattern)
            self.K.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
            self.bulk.assemble_linear(self.K)
            self.K.assemblyBegin(PETSc.Mat.AssemblyType.FLUSH)  # assemble_matrix ends in INSERT
            self.K.assemblyEnd(PETSc.Mat.AssemblyType.FLUSH)
            self.contact.add_zeros(self.K)
            self.K.assemble()
            self.J = self.K.duplicate(copy=False)
            self.J_key = None  # newton._keep: the key of the tangent J holds (None: none)
            self.J.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
            # zeroRows must not shrink the pattern: MatCopy(SAME_NONZERO_PATTERN) each
            # iteration and the reuse of the symbolic LU factorisation depend on it
            self.J.setOption(PETSc.Mat.Option.KEEP_NONZERO_PATTERN, True)
            self.R = self.K.createVecLeft()
            self.Ku = self.K.createVecLeft()
            self.f = self.K.createVecLeft()

        with self.phase("solve"):  # the condensed bulk is factorised here, once
            self.linear = linear.choose(self, linear_solver, petsc_options)
        self.control = None  # force_control.ForceControl while a force-controlled stage runs
        self.u_committed = self.u.x.array.copy()
        self.lam = 0.0
        self.steps = []

    # ------------------------------------------------------------------ utilities
    @property
    def factorisations(self):
        """Sparse factorisations so far (the condensed bulk: one per scene)."""
        return self.linear.factorisations

    @property
    def mu(self):
        return self.contact.mu

    def phase(self, name):
        return nullcontext() if self.timer is None else self.timer.phase(name)

    _phase = phase

    def set_friction(self, mu):
        """Change mu between stages (friction switched on starts from zero tangential
        traction, see `ContactSet.set_friction`)."""
        self.contact.set_friction(mu, self.u.x.array)

    def set_bc_values(self, lam):
        x = self.u.x.array
        for d, dofs in zip(self.dirichlet, self.bc_dofs):
            x[dofs] = d.at(lam)

    def residual(self, lam, with_tangent=False, zero_bc=True, predictor=False, stick=False):
        """R = F_bulk(u) - f(lam) + r_c(u) (owned part); with_tangent also fills self.J (with
        `predictor`, the first iteration's tangent: see predictor_gap)."""
        if with_tangent:
            self.J_key = None  # newton._keep: what J is the tangent of
        with self.phase("assembly"):
            self.u.x.scatter_forward()
            self.K.mult(self.u.vector, self.Ku)
            self.Ku.copy(self.R)
            self.bulk.external(lam, self.f)
            self.R.axpy(-1.0, self.f)
            if with_tangent:
                self.K.copy(self.J, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
            self.bulk.add_nonlinear(self.R, self.J if with_tangent else None)
        with self.phase("contact"):
            self.contact.set_load(lam)
            self._rc.x.array[:] = 0.0
            self.contact.assemble(
                self.u.x.array,
                self._rc.x.array,
                self.J if with_tangent else None,
                self.newton.fd_tangent,
                self.newton.fd_step,
                self.predictor_gap if predictor else 0.0,
                stick,
            )
            self._rc.x.scatter_reverse(la.ScatterMode.add)
        with self.phase("assembly"):
            self.R.array[:] += self._rc.x.array[: self.n_owned]
            # force scale of the round-off floor: internal forces (R + f) and external ones
            self.R.copy(self.Ku)
            self.Ku.axpy(1.0, self.f)
            self.force_scale = max(self.Ku.norm(), self.f.norm())
            if with_tangent:
                self.J.assemble()
                if self.control is not None:
                    self.control.linearise(self.J)
                self.J.zeroRows(self.bc_global, diag=1.0)
            if self.control is None:
                return self._zero_bc(zero_bc)
            self.control.measure(self.R)  # the reaction, from the rows zeroed next
            return float(np.hypot(self._zero_bc(zero_bc), self.control.residual(lam)))

    def _zero_bc(self, zero_bc):
        if zero_bc:
            self.R.array[self.bc_owned] = 0.0
        return self.R.norm()

    def commit(self, lam):
        if self.control is not None:
            self.control.commit(lam)
        self.contact.commit()
        self.u_committed[:] = self.u.x.array
        self.lam = lam

    def restore(self):
        self.u.x.array[:] = self.u_committed
        self.u.x.scatter_forward()
        self.contact.restore()
        if self.control is not None:
            self.control.restore()

    def solve(self, num_steps=1, lam_end=1.0, label="step", initial_guess=None):
        """Ramp the load from the committed level to lam_end in num_steps equal steps, with
        cut-back (`newton.load_steps`). Raises ContactSolverError."""
        load_steps(self, num_steps, lam_end, label, initial_guess)

    # ------------------------------------------------------------------ outputs
    def reaction(self, boundary):
        """Force exerted by the supports on the body at a tagged boundary: the residual
        F_bulk(u) + r_c - f summed over the boundary's dofs (all components)."""
        self.residual(self.lam, zero_bc=False)
        facets = self.scene.facet_tags.find(self.scene.boundaries[boundary])
        gdim = self.mesh.geometry.dim
        F = np.zeros(gdim)
        for c in range(gdim):
            dofs = fem.locate_dofs_topological(self.V.sub(c), self.mesh.topology.dim - 1, facets)
            F[c] = np.sum(self.R.array[dofs[dofs < self.n_owned]])
        return self.comm.allreduce(F, MPI.SUM)

    def contact_points(self):
        """Per-point records of all pairs on this rank (reference configuration)."""
        return self.contact.points(self.u.x.array)

    def stress(self, space=("DG", 0)):
        """The bodies' output stress (their laws' `cauchy`) as a Function of a tensor space."""
        return self.bulk.stress(space)


def solver_metrics(problem, converged=True):
    """The `solver` block of metrics.json, with the failed checks of the final state
    (`checks.contact_warnings`) in `warnings`."""
    from dolfinx_forms.solvers.checks import contact_warnings, penetration

    return {
        "warnings": contact_warnings(problem),
        "penetration_h": penetration(problem),
        "load_steps": len(problem.steps),
        "newton_iterations": [s.iterations for s in problem.steps],
        "converged": bool(converged),
        "residual_history": [[float(r) for r in s.residuals] for s in problem.steps],
        "penalty": {"eps_n": problem.eps_n, "eps_t": problem.eps_t},
        "enforcement": problem.contact.enforcement,
        # Uzawa's projection on the multipliers (`ContactProblem`): augmented only
        "multiplier_mass": problem.multiplier_mass if problem.contact.augmented else None,
        "augmentations": [int(s.augmentations) for s in problem.steps],
        "uzawa_halvings": int(problem.contact.halvings),  # `NewtonOptions.al_stall`
        "cutbacks": int(sum(s.cutback for s in problem.steps)),
        "factorisations": int(problem.factorisations),
        "linear_solver": problem.linear.name,
        "schur_factorisations": int(getattr(problem.linear, "schur_factorisations", 0)),
        "condensed_dofs": int(getattr(problem.linear, "num_dofs", 0)),
        # Krylov iterations per linear solve (the iterative solver only)
        **(
            {"linear_iterations": list(problem.linear.iterations)}
            if hasattr(problem.linear, "iterations")
            else {}
        ),
    }


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
