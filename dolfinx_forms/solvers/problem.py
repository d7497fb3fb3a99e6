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
from dolfinx_forms.contact.band import carry_state, lattice_origins
from dolfinx_forms.contact.contact_set import ContactSet
from dolfinx_forms.contact.penalty import contact_modulus, penalty_parameter
from dolfinx_forms.fem.boundary import dirichlet_dofs
from dolfinx_forms.fem.bulk import BulkForms
from dolfinx_forms.fem.laws import as_law
from dolfinx_forms.geometry.pairs import DEFAULT_MULTIPLIER_MASS, MULTIPLIER_MASSES, TRACTIONS
from dolfinx_forms.solvers import blas, linear
from dolfinx_forms.solvers.newton import ContactSolverError, NewtonOptions, load_steps
from dolfinx_forms.solvers.options import ContactOptions, FemOptions, SolverOptions

# the tuned factors of the augmented Lagrangian's regularisation and the BLAS threshold are
# read from dolfinx_forms.defaults.TUNING when a problem is made (their studies: STUDIES there)

# active points with an initial gap above this fraction of the band reach its edge: the band
# doubles and the step is done again (`ContactProblem.grow_band`; `checks.pair_warnings`)
BAND_EDGE = 0.9
# growths of the contact sparsity by the closing points' reach before a step is accepted;
# the next one takes every law point of the band (`ContactProblem._grow_coupling`)
MAX_STEP_GROWTHS = 2


class ContactProblem:
    """Bodies of a `dolfinx_forms.mesh.scene.Scene` in frictional contact (eqs 8-12, 37, 48).

    materials: {body tag: Law or (E, nu)} (`fem.laws`; (E, nu) is `LinearElastic`).
    dirichlet: `Dirichlet` conditions; tractions: `Traction`s; loads: `BodyForce`/`Load`s.
    obstacles: rigid `geometry.obstacles.RigidObstacle`s (no dofs) whose step motion is
    ramped with lam. contact, fem, solver: the grouped options (`solvers.options`:
    ContactOptions, FemOptions, SolverOptions; `**options(mu=..., degree=...)` sorts flat
    keywords into them). A scene with `cut` data integrates over the inside part of cut
    cells (`fem.cut.CutIntegration`) with a ghost penalty. timer: a `io.results.PhaseTimer`
    (or None); log: where the Newton lines go (rank 0). predictor(problem) -> guess or None:
    guess(problem, lam) adds a predicted increment to u, which Newton starts from where it
    lowers the first residual (`solve`, `newton.newton`); the law points it closes join the
    contact tangent's sparsity with those near contact (`_coupling_points`).
    """

    def __init__(
        self,
        scene,
        materials,
        *,
        dirichlet=(),
        tractions=(),
        loads=(),
        obstacles=(),
        contact=None,
        fem=None,
        solver=None,
        timer=None,
        log=print,
        predictor=None,
    ):
        c = contact if contact is not None else ContactOptions()
        fo = fem if fem is not None else FemOptions()
        so = solver if solver is not None else SolverOptions()
        self.scene, self.mesh = scene, scene.mesh
        self.comm = self.mesh.comm
        self.newton = so.newton or NewtonOptions()
        self.timer = timer
        self.log = log if self.comm.rank == 0 else (lambda *a, **k: None)
        self.predictor_gap = float(c.predictor_gap)
        self.rigid_mode_stiffness = float(fo.rigid_mode_stiffness)  # checks.unheld_bodies
        self.laws = {int(t): as_law(m) for t, m in materials.items()}
        self.materials = self.laws
        with self.phase("assembly"):
            self._bulk(fo, dirichlet, tractions, loads)
        h = scene.h_contact
        self.band = self.band_start = float(c.band if c.band is not None else 2 * h)
        self.band_growth = int(c.band_growth)  # doublings allowed (`grow_band`)
        self.band_errors = []  # the growth bound reached: error-level warnings
        E_c = contact_modulus(scene, self.laws, obstacles)
        settings = enforcement(c, h, E_c, cut=self.integration is not None)
        self.eps_n, self.eps_t = settings["eps_n"], settings["eps_t"]
        self.multiplier_mass = settings["multiplier_mass"]
        # what a rebuild over a wider band needs (`grow_band`)
        self._rebuild = dict(settings=dict(settings, obstacles=obstacles), fem=fo, solver=so)
        with self.phase("contact"):
            self.contact = ContactSet(
                self.V, scene, band=self.band, obstacles=obstacles, **settings
            )
        self.pairs = self.contact.pairs
        # the law points whose tangent blocks the sparsity holds (`SolverOptions.coupling_gap`)
        if so.coupling_gap is not None and not so.coupling_gap >= 0:
            raise ValueError(
                f"coupling_gap: a number >= 0 (units of h) or None, not {so.coupling_gap}"
            )
        self.coupling_gap = None if so.coupling_gap is None else float(so.coupling_gap) * h
        self.coupling_rebuilds = 0  # matrices built again for a point outside the sparsity
        self.step_growths = 0  # of the sparsity since the last accepted step (`_grow_coupling`)
        self.short_lived = bool(so.short_lived)  # `linear.Factorised`'s ordering
        picked = linear.pick(self, so.linear_solver, so.petsc_options)
        self._coupled = picked[0] == "factorised"
        self.lam = 0.0
        self.guess = None if predictor is None else predictor(self)
        self.coupled = self._coupling_points()
        with self.phase("assembly"):
            self._matrices(fo.ghost_penalty)
        self.retired = [0, 0]  # factorisations of the linear solvers a band growth replaced
        with self.phase("solve"):  # the condensed bulk is factorised here, once
            self.linear = linear.choose(self, so.linear_solver, so.petsc_options, picked)
        self.control = None  # force_control.ForceControl while a force-controlled stage runs
        self.u_committed = self.u.x.array.copy()
        self.guess_taken = False  # newton: whether the last solve started from its guess
        self.steps = []

    def _bulk(self, fo, dirichlet, tractions, loads):
        """Function space, bulk forms (cut integration on a cut scene), Dirichlet dofs."""
        scene = self.scene
        self.integration = None
        if getattr(scene, "cut", None) is not None:
            if fo.degree != 1 or scene.cell_type != "quadrilateral":
                raise ValueError("degree: the cut path supports Q1 (degree 1) on quadrilaterals")
            from dolfinx_forms.fem.cut import CutIntegration

            self.integration = CutIntegration(scene, degree=fo.cut_degree)
        self.V = fem.VectorFunctionSpace(self.mesh, ("Lagrange", fo.degree))
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
            ghost_penalty=fo.ghost_penalty,
            quadrature_degree=fo.quadrature_degree,
            rigid_mode_stiffness=fo.rigid_mode_stiffness,
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
        all_bc = np.zeros(0, np.int32)
        if self.bc_dofs:
            all_bc = np.unique(np.concatenate(self.bc_dofs))
        self.bc_owned = all_bc[all_bc < self.n_owned].astype(np.int32)
        self.bc_global = (self.bc_owned + imap.local_range[0] * self.bs).astype(np.int32)

    def _coupling_points(self):
        """Per pair, a mask of the law points whose tangent blocks the sparsity holds: those
        with a gap below coupling_gap before the step's deformation (`ContactSet.law_gaps0`;
        below predictor_gap on a pair with no closed point) or at the end of the predicted
        increment (`guess`); None (every law point) without a coupling_gap or where the linear
        solver is not `Factorised`."""
        if self.coupling_gap is None or not self._coupled:
            return None
        gap = self.coupling_gap
        gaps0 = [self.contact.law_gaps0(k) for k in range(len(self.pairs))]
        coupled = [g < gap for g in gaps0]
        if self.predictor_gap > 0:  # a pair that touches, none of it closed: the predictor's
            # first tangent holds its bodies (a closed pair's touching points need not)
            coupled = [
                c | ((g < self.predictor_gap) & ~np.any(g < 0)) for c, g in zip(coupled, gaps0)
            ]
        if self.guess is not None:  # else the first iteration's tangent grows the sparsity
            with self.phase("contact"):
                self.guess(self, 1.0)
                self.contact.set_load(1.0)
                self.contact.assemble(self.u.x.array, self._rc.x.array)
                coupled = [c | (s["law_g_n"] < gap) for c, s in zip(coupled, self.contact.last)]
                self.u.x.array[:] = 0.0
                self._rc.x.array[:] = 0.0
                self.contact.last = [None] * len(self.pairs)
        return coupled

    def _outside_coupling(self):
        """After a contact assembly into J: per pair, the law points that put a tangent block
        into J but are not in its sparsity (J dropped those entries), or None if there are none
        on any rank."""
        if self.coupled is None:
            return None
        # closed points only: a touching point's predictor tangent (an open point's) outside
        # the sparsity is dropped, which leaves the first iterate's residual exact
        out = [
            (s["law_coupled"] != 0) & (s["law_state"] > 0) & ~c
            for s, c in zip(self.contact.last, self.coupled)
        ]
        return out if self.comm.allreduce(any(o.any() for o in out), op=MPI.LOR) else None

    def _grow_coupling(self, outside):
        """The sparsity grown by the points `outside` and by every law point whose current gap
        is below the largest of theirs (or coupling_gap); matrices and solver built again.
        Past MAX_STEP_GROWTHS growths before a step is accepted it takes every law point of
        the band: Newton's iterates in a failing step (before its cut-back) close points far
        apart one after the other, and each growth costs an assembly and a symbolic
        factorisation (30 grains, 10 + 5 steps: 178 growths for 472 Newton iterations)."""
        self.coupling_rebuilds += 1
        self.step_growths += 1
        if self.step_growths > MAX_STEP_GROWTHS:
            self.coupled = None
        else:
            gaps = [s["law_g_n"] for s in self.contact.last]
            grown = [float(np.max(g[o])) for g, o in zip(gaps, outside) if o.any()]
            reach = self.comm.allreduce(max([self.coupling_gap] + grown), op=MPI.MAX)
            self.coupled = [c | o | (g <= reach) for c, o, g in zip(self.coupled, outside, gaps)]
        self._rebuild_linear(renew=True)

    def _rebuild_linear(self, renew=False):
        """Matrices and linear solver built again (a wider band; a grown sparsity, renew: a
        solver like the one in use, `Factorised.renewed`); the factorisations so far are kept
        in the count."""
        self.retired[0] = self.factorisations
        self.retired[1] = self.schur_factorisations
        old = self.linear
        old.destroy()
        linear.destroy(self.K, self.J, self.R, self.Ku, self.f)
        with self.phase("assembly"):
            self._matrices(self._rebuild["fem"].ghost_penalty)
        so = self._rebuild["solver"]
        with self.phase("solve"):
            if renew:
                self.linear = old.renewed(self)
            else:
                self.linear = linear.choose(self, so.linear_solver, so.petsc_options)

    def _matrices(self, ghost_penalty):
        """Sparsity: mesh couplings + contact coupling blocks of the law points `coupled` (+
        ghost-penalty cell pairs). K (the linear bulk), J (the tangent), R, Ku, f."""
        pattern = _dcpp.fem.create_sparsity_pattern(
            self.mesh.topology,
            [self.V.dofmap._cpp_object, self.V.dofmap._cpp_object],
            {_dcpp.fem.IntegralType.cell},
        )
        points = None if self.coupled is None else [np.flatnonzero(c) for c in self.coupled]
        self.contact.insert_couplings(pattern, points)
        if self.integration is not None and ghost_penalty > 0:
            self.integration.insert_ghost_couplings(pattern, self.V)
        pattern.assemble()
        self.K = _dcpp.la.petsc.create_matrix(self.comm, pattern)
        self.K.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
        self.bulk.assemble_linear(self.K)
        self.K.assemblyBegin(PETSc.Mat.AssemblyType.FLUSH)  # assemble_matrix ends in INSERT
        self.K.assemblyEnd(PETSc.Mat.AssemblyType.FLUSH)
        self.contact.add_zeros(self.K, points)
        self.K.assemble()
        self.J = self.K.duplicate(copy=False)
        self.J_key = None  # newton._keep: the key of the tangent J holds (None: none)
        if self.coupled is None:
            self.J.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
        else:  # a block outside the sparsity is dropped, then found (`_outside_coupling`)
            self.J.setOption(PETSc.Mat.Option.NEW_NONZERO_LOCATIONS, False)
        # zeroRows must not shrink the pattern: MatCopy(SAME_NONZERO_PATTERN) each iteration
        # and the reuse of the symbolic LU factorisation depend on it
        self.J.setOption(PETSc.Mat.Option.KEEP_NONZERO_PATTERN, True)
        self.R = self.K.createVecLeft()
        self.Ku = self.K.createVecLeft()
        self.f = self.K.createVecLeft()

    def destroy(self):
        """Free this problem's PETSc objects: petsc4py frees none when garbage-collected, so a
        run that makes a problem per step (the material-point path) calls this for each one it
        drops. The problem is unusable afterwards."""
        self.linear.destroy()
        if self.control is not None:
            self.control.destroy()
            self.control = None
        self.bulk.destroy()
        linear.destroy(self.K, self.J, self.R, self.Ku, self.f)
        self.K = self.J = self.R = self.Ku = self.f = None

    def release_solver(self):
        """Free the linear solver's factorisations (`Factorised.release`): the problem stays
        usable (a later solve factorises again)."""
        self.linear.release()

    # ------------------------------------------------------------------ utilities
    @property
    def factorisations(self):
        """Sparse factorisations so far (the condensed bulk: one per scene and band)."""
        return self.retired[0] + self.linear.factorisations

    @property
    def schur_factorisations(self):
        return self.retired[1] + int(getattr(self.linear, "schur_factorisations", 0))

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
        outside = self._outside_coupling() if with_tangent else None
        if outside is not None:  # J dropped their blocks: a wider sparsity, then again
            self._grow_coupling(outside)
            return self.residual(lam, with_tangent, zero_bc, predictor, stick)
        with self.phase("contact"):
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

    def nonfinite(self):
        """Where the last residual is not finite (Newton's failure message; collective): the
        first of its parts (the iterate u, the loads f, the linear bulk K u, the nonlinear bulk,
        the contact) with a non-finite entry, the body whose dofs hold it and a dof's position;
        "" where every part is finite."""
        n = self.n_owned
        Ku = self.K.createVecLeft()
        self.K.mult(self.u.vector, Ku)
        parts = [
            ("the displacement iterate (from the last linear solve: a singular system? every "
             "body needs its rigid motions held by Dirichlet conditions or by contact)",
             self.u.x.array[:n]),
            ("the external loads (body forces, inertia)", self.f.array[:n]),
            ("the linear bulk forces K u", Ku.array[:n]),
            ("the nonlinear bulk forces (finite strain: det F <= 0 at an integration point?)",
             self.bulk.b_nl.array[:n] if self.bulk.nonlinear else np.zeros(0)),
            ("the contact forces", self._rc.x.array[:n]),
        ]  # fmt: skip
        first = None
        for k, (_, values) in enumerate(parts):
            bad = np.flatnonzero(~np.isfinite(values))
            if len(bad):
                first = (k, len(bad), bad[0])
                break
        linear.destroy(Ku)
        where = (np.inf, 0, "", (np.nan, np.nan))  # part, count, body, a dof's position
        if first is not None:
            k, count, dof = first
            bs = self.V.dofmap.index_map_bs
            cells = np.flatnonzero((self.V.dofmap.list.array == dof // bs).reshape(
                self.V.dofmap.list.num_nodes, -1).any(axis=1))  # fmt: skip
            tags = self.scene.cell_tags
            tag = tags.values[np.isin(tags.indices, cells)]
            names = {b.tag: b.name for b in self.scene.bodies}
            body = names.get(int(tag[0]), f"tag {int(tag[0])}") if len(tag) else "?"
            x = self.V.tabulate_dof_coordinates()[dof // bs, :2]
            where = (k, count, body, (float(x[0]), float(x[1])))
        k, count, body, x = min(self.comm.allgather(where), key=lambda w: w[0])
        if not np.isfinite(k):
            return ""
        total = self.comm.allreduce(count if where[0] == k else 0)
        return (f"{parts[int(k)][0]}: not finite at {total} dof(s), on body {body!r} "
                f"(one at x = ({x[0]:.6g}, {x[1]:.6g}))")  # fmt: skip

    def _zero_bc(self, zero_bc):
        if zero_bc:
            self.R.array[self.bc_owned] = 0.0
        return self.R.norm()

    def commit(self, lam):
        self.step_growths = 0
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
        cut-back (`newton.load_steps`; initial_guess: that of `predictor` unless given).
        Raises ContactSolverError."""
        load_steps(self, num_steps, lam_end, label, initial_guess or self.guess)

    # ------------------------------------------------------------------ the band
    def band_reached(self):
        """Whether an active contact point of the last evaluation has an initial gap above
        BAND_EDGE band: Gamma_c may cut the contact zone off there (the same on every rank)."""
        near = any(
            s is not None and bool(np.any((s["state"] > 0) & (g.g_n0 > BAND_EDGE * self.band)))
            for g, s in zip(self.contact.pairs, self.contact.last)
        )
        return bool(self.comm.allreduce(near, op=MPI.LOR))

    def grow_band(self, lam):
        """After a converged step to load level lam whose active points reached the band's edge
        (`band_reached`): back to the committed state, the band doubled, the pair geometry,
        matrices and linear solver rebuilt, the committed state carried over
        (`contact.band`); the caller then does the step again, as a band that wide from the
        start would have. Returns False, with an error-level warning in `band_errors` (once)
        and on the console, when band_growth doublings are spent."""
        if self.band >= self.band_start * 2.0**self.band_growth:
            if not self.band_errors:
                self.band_errors.append(
                    f"the contact zone is cut off at the band's edge (an error: the results are "
                    f"wrong): active points reach 0.9 of the band {self.band:.4g} at load level "
                    f"{lam:.4g}, after {self.band_growth} doublings of {self.band_start:.4g} "
                    "(give a larger band, or band_growth)"
                )
                self.log(f"ERROR: {self.band_errors[0]}")
            return False
        self.restore()
        old, band = self.contact, 2.0 * self.band
        settings = self._rebuild["settings"]
        with self.phase("contact"):
            try:
                new = ContactSet(
                    self.V, self.scene, band=band, origins=lattice_origins(old),
                    **dict(settings, mu=old.mu),
                )  # fmt: skip
                carry_state(new, old, self.u_committed, self.lam, self.scene.h_contact)
                failed = ""
            except (RuntimeError, ValueError) as e:  # e.g. a point outside the rank's cells
                failed = str(e)
            failed = next((f for f in self.comm.allgather(failed) if f), "")
        if failed:
            raise ContactSolverError(f"contact band {band:.4g}: rebuilding Gamma_c: {failed}")
        self.contact, self.pairs, self.band = new, new.pairs, band
        self.coupled = self._coupling_points()
        self._rebuild_linear()
        self.log(
            f"contact band doubled to {band:.4g}: active points reached 0.9 of "
            f"{band / 2:.4g} at load level {lam:.4g}; the step is done again"
        )
        return True

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
        # multiplier nodes laid out again at the contact edges (`NewtonOptions.al_align`)
        "edge_alignments": int(problem.contact.alignments),
        "cutbacks": int(sum(s.cutback for s in problem.steps)),
        "factorisations": int(problem.factorisations),
        # the sparsity grown for a closing point outside it (`SolverOptions.coupling_gap`)
        "coupling_rebuilds": int(problem.coupling_rebuilds),
        "linear_solver": problem.linear.name,
        "schur_factorisations": int(problem.schur_factorisations),
        # the contact band at the start and at the end (`ContactProblem.grow_band`)
        "band": {"start": problem.band_start, "end": problem.band},
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


def enforcement(c, h, E_c, cut):
    """The ContactSet settings of the options `c` (ContactOptions) at mesh size h and contact
    modulus E_c: defaults resolved, checked, and eq 51's regularisation. The penalty: eps_n =
    eps_t = eps0 h / E_c. The augmented Lagrangian with point-wise traction: eps_n and eps_t
    the tuned factors (defaults.TUNING) times h / E_c, part of the discretisation; eps0 then
    relaxes the Uzawa step by min(1, eps_n / eps)."""
    eps = penalty_parameter(c.eps0, h, E_c)  # eq 51
    augmented = c.enforcement == "augmented"
    multipliers = ("P1" if augmented else None) if c.multipliers == "default" else c.multipliers
    traction = ("points" if augmented else "nodes") if c.traction == "default" else c.traction
    if traction not in TRACTIONS:
        raise ValueError(f"traction must be one of {TRACTIONS}, got {traction!r}")
    projected = augmented and multipliers == "P1" and traction == "points"
    mass = c.multiplier_mass
    if mass is None:  # the default where Uzawa projects on P1 nodes
        mass = DEFAULT_MULTIPLIER_MASS if projected else "lumped"
    if mass not in MULTIPLIER_MASSES:
        raise ValueError(f"multiplier_mass must be one of {MULTIPLIER_MASSES}, got {mass!r}")
    consistent = mass != "lumped"  # "consistent" or "hybrid"
    if consistent and not projected:
        raise ValueError(
            f"multiplier_mass {mass!r} needs enforcement 'augmented' with P1 multipliers and "
            f"traction 'points', got {c.enforcement!r}, {multipliers!r}, {traction!r}"
        )
    out = dict(eps_n=eps, eps_t=eps, relaxation=1.0, eps_t_start=None)
    tune = defaults.TUNING
    if augmented and multipliers is not None and traction == "points":
        k_n = tune.consistent_eps0 if consistent else tune.pointwise_eps0
        fine = penalty_parameter(k_n, h, E_c) * float(c.regularisation)
        out.update(eps_n=fine, relaxation=min(1.0, fine / eps))
        out["eps_t"] = out["eps_t_start"] = penalty_parameter(tune.pointwise_eps0_t, h, E_c)
        if consistent:
            out["eps_t"] = penalty_parameter(tune.consistent_eps0_t, h, E_c)
    length = c.multiplier_length
    if length is None:
        spacing = 1.5 if cut else 1.0  # the lumped projection's
        length = h * (tune.consistent_length if consistent else spacing)
    return dict(
        out,
        mu=c.mu,
        grid_refine=c.grid_refine,
        num_gauss=c.num_gauss,
        rank=c.contact_rank,
        lattice_origin=c.pair_grid_origin,
        multipliers=multipliers,
        multiplier_length=length,
        enforcement=c.enforcement,
        traction=traction,
        multiplier_mass=mass,
    )
