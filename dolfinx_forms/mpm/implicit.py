"""The implicit level-set MPM step loop (section 4.4 of the seed paper).

Each body is a level set on a fixed uniform background grid plus material points; obstacles are
rigid level sets (`obstacles.py`). One load step:

1. the cut scene of the current level sets (`build_scene`, supplied by the application, e.g.
   `meshes.mpm.grid_scene`): active cells, integration points; Gamma_c and the closest points
   come from the current grid level sets (eqs 21-25), never from the initial shapes. The
   DOLFINx mesh is rebuilt only when a body's active cells or their kinds (or the pairs)
   change; forms and sparsity are made anew every step, because the cut weights and the
   contact couplings move with the level sets (their compiled kernels are kept in memory,
   `fem.jit_memo`);
2. the material points' stress is projected to the integration points of the new cells by MLS
   (eqs 38-45, `_cpp.MLSProjector`), per body, and enters the residual as the initial stress
   int sigma_0 : grad v;
3. the friction history is carried from the previous step's contact points to the new ones
   (`transfer_friction`);
4. Newton on the displacement increment du of the step (`ContactProblem`, penalty contact and
   Coulomb friction, obstacles' motion and Dirichlet increments ramped with lam, cut-back),
   started from the last step's increment where that lowers the first residual (quasi-static,
   `extrapolate`: `increment.py`);
5. the material points move and update stress and volume (`material_points.update`);
6. du is extended off each body along the normal (eq 20) and the level set advected by it
   (eq 19, HJ-WENO5 + TVD-RK3), reinitialised when |grad phi| drifts; obstacles move.

Nothing persistent changes before step 4 converges, and `snapshot`/`restore` copy every piece
of state (points, level sets, obstacle poses, friction record, counters): a rejected step leaves
the simulation exactly as it was, but for the last step's problem and mesh, freed before the
step built its own (`problem` and `scene` are then None: the next step builds them again). A
quasi-static step that fails is done again in halves, each on its own cut cells (`step`,
`max_splits`).

Linear laws: small strain per step with the Jaumann update of the points' stress
(material_points.py). Finite-strain laws (`Law.finite_strain`: NeoHookean, J2Plasticity, user
laws): F and the law's history at the points, an updated-Lagrangian step on Omega_n
(finite_strain.py). Other nonlinear laws are refused. The background grid must be uniform
(WENO5).
"""

from __future__ import annotations

import gc
import time
from contextlib import nullcontext
from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from dolfinx_forms import _cpp
from dolfinx_forms.common import worker_threads
from dolfinx_forms.mpm import material_points as mp
from dolfinx_forms.fem.boundary import Load
from dolfinx_forms.fem import jit_memo
from dolfinx_forms.fem.cut import grid_cells, material_window
from dolfinx_forms.fem.laws import as_law, law_key
from dolfinx_forms.mpm import evolution, increment, records
from dolfinx_forms.mpm import finite_strain as fs
from dolfinx_forms.solvers.newton import QUASI_STATIC_RISE_LIMIT, ContactSolverError, quasi_static
from dolfinx_forms.solvers.options import options
from dolfinx_forms.solvers.problem import ContactProblem


@dataclass
class MPMBody:
    """A deformable body: name, cell tag, law (Law or (E, nu)) and initial shape (`_cpp.Shape`
    sampled exactly at the grid nodes, or a `_cpp.LevelSet` on the background grid)."""

    name: str
    tag: int
    law: object
    shape: object


MAX_BAND_GROWTH = 4  # doublings of the contact band within one step (16 times the start)
# halvings of a failed quasi-static step (`ImplicitMPM.step`): down to an eighth of it. The
# neo-Hookean block of block_compression.py failed at 34 % in 20 steps and ran in 40.
MAX_SPLITS = 3
# the augmented Lagrangian's point-wise regularisation eps_n (traction "points", the lumped
# projection: 2 h / E_c, `defaults.TUNING.pointwise_eps0`) times this on bodies at finite
# strain. Where the pressure peaks within a multiplier element (a platen's corner) the points
# penetrate by eps_n (tau - lambda_h), proportional to eps_n: 0.107 h at the neo-Hookean
# block's corners at 32 % (block_compression.py, h = 0.05; the penalty at eps0 0.1: 0.041 h).
# The corner, compressed to det F 0.65-0.75 beside the penetrated rim, then loses the stiffness
# of its sideways mode: at step 17 (34 %) the tangent's softest eigenvalue was 1.2 of 8.2e3 at
# the step's start and -0.19 after the first Newton iterate (bulk -1.60, contact +1.29, ghost
# penalty +0.12), and Newton moved the corner nodes by 1.3 mm (det F <= 0), at every split of
# the step. The 40 % run in 20 steps failed at step 17 / 18 / 19 with factors 1 / 0.5 / 0.25
# and completes with 0.1 (as the penalty does at eps0 0.1: eps 0.1 h / E_c). Measured there:
# corner penetration 0.13 -> 0.02 h at 32 %; force error at 30 %: 0.81 -> 1.38 % (neo-Hookean),
# 0.82 -> 1.37 % (J2), with 12 instead of 29 (43) Newton iterations per step. J2 at 40 % then
# folded points beside a top corner (det f <= 0 at 4 points in step 18): `_step` rejects such
# an increment, and the step is split
FINITE_STRAIN_REGULARISATION = 0.1
# a plastic law's steps start from du = 0 (`extrapolate` None): the last increment, though it
# lowers the first residual, leads Newton through more active-set and plastic changes. J2 and
# Drucker-Prager blocks (block_compression.py defaults): 11.5 -> 7.2 and 9.4 -> 7.4 Newton
# iterations per step (the augmented J2: 22.2 -> 16.1), the J2 disc crush (disc_crush.py
# defaults, the MPM): 1319 -> 377 iterations, 37.9 -> 12.3 s, forces the same to 4e-6; the
# neo-Hookean crush keeps it (289 -> 210 iterations with it)

# NewtonOptions.rise_limit on this path's quasi-static steps (unless the user's NewtonOptions set
# it): a Newton step across a change of the active set that raises the residual above the
# solve's lowest is halved on a nonlinear bulk (solvers/newton.py QUASI_STATIC_RISE_LIMIT, the
# body-fitted updated Lagrangian's too). Finite-strain J2 with friction diverged through such
# steps on its soft plastic zone (disc_crush.py, H = 0 / 1 at step 8-9, the default J2 at step
# 24); the details at the option. Not in dynamics: the neo-Hookean disc of bouncing_disc.py
# (h = 0.2, dt = 0.02, eps0 1e-4) then bounced on, its floor force at rest 0.86 to 1.18 of its
# weight (1.00001-1.00003 with whole steps)
RISE_LIMIT = QUASI_STATIC_RISE_LIMIT
# step-record counters that add up over a step's sub-steps (the rest: the last sub-step's)
_SUMMED = ("newton_iterations", "cutbacks", "factorisations", "coupling_rebuilds",
           "mls_widened", "mls_F_nearest", "wall_s", "predicted")  # fmt: skip


def equilibrium_error(record):
    """Largest |contact + support resultant| over the bodies of a step record, relative to the
    largest normal contact force: every body's equilibrium in one number."""
    worst = max(
        np.hypot(*np.add(f[:2], record["support_forces"][n]))
        for n, f in record["body_forces"].items()
    )
    return worst / max([q["normal_force"] for q in record["pairs"]] + [1e-300])


def _guard_jacobian(F, targets, x, F_points):
    """In place on the MLS values F (n, 4) of the deformation gradient at `targets`: a value
    whose det F is below half the smallest of the points' (F_points (m, 4) at x) is an
    extrapolation artifact of a thin support (a grain's points spread by a hard impact), and
    det F <= 0 makes the law's ln det F NaN: it takes its nearest point's F instead (that
    point's own, det > 0). Returns how many did."""
    det = lambda A: A[:, 0] * A[:, 3] - A[:, 1] * A[:, 2]  # noqa: E731
    bad = np.flatnonzero(det(F) < 0.5 * det(F_points).min())
    if len(bad):
        from scipy.spatial import cKDTree

        F[bad] = F_points[cKDTree(x).query(targets[bad])[1]]
    return len(bad)


def _ratio_range(points):
    """[min, max] of the points' vol / vol0 (det F)."""
    r = points.vol / points.vol0
    return [float(r.min()), float(r.max())] if len(r) else [1.0, 1.0]


def _stress_tensor(s):
    return ufl.as_matrix([[s[0], s[2]], [s[2], s[1]]])


class ImplicitMPM:
    """Bodies and rigid obstacles over many load steps (module docstring).

    grid: (xlines, ylines) of the uniform background grid; build_scene(levelsets) -> Scene: the
    cut scene of {tag: _cpp.LevelSet} on that grid (bodies in the order of `bodies`); obstacles:
    `RigidObstacle`s with their motion per step; dirichlet: `Dirichlet` conditions whose values
    are the increments of one step (at lam = 1); reinit_drift: reinitialise a level set when
    max | |grad phi| - 1 | within 3 h of its zero contour exceeds it; levelset_update:
    "advection" (eq 19) or "reference-map" (the points' map, `evolution.py`); extrapolate:
    quasi-static steps start Newton from the last step's increment per unit of step where that
    lowers the first residual (`increment.py`; False: from du = 0; None: unless a body's law
    carries a history: the module's comment "a plastic law's steps" says why). Other keywords go to
    `ContactProblem` (mu, eps0, band, newton, petsc_options, ghost_penalty, ...)."""

    def __init__(
        self,
        comm,
        grid,
        bodies,
        build_scene,
        *,
        obstacles=(),
        dirichlet=(),
        reinit_drift=0.2,
        levelset_update=evolution.LEVELSET_UPDATES[0],
        dynamics=None,
        max_splits=MAX_SPLITS,
        extrapolate=None,
        timer=None,
        log=print,
        **problem_kw,
    ):
        jit_memo.install()  # new spaces and forms every step: FFCx's answers kept in memory
        self.comm = comm
        self.xlines, self.ylines = (np.asarray(v, float) for v in grid)
        self.grid = _cpp.StructuredGrid(self.xlines, self.ylines)
        self.h = float(self.grid.max_spacing)
        if not np.isclose(self.grid.min_spacing, self.h, rtol=1e-9):
            raise ValueError("ImplicitMPM: the background grid must be uniform (WENO5 advection)")
        self.bodies = list(bodies)
        self.laws = {b.tag: as_law(b.law) for b in self.bodies}
        # linear laws: small strain, the points' stress updated by C : d_eps (one C per distinct
        # law: 13 bodies of one material, 0.4 s -> 0.03 s); finite-strain laws: F and history
        # at the points (finite_strain.py), one compiled point law per distinct law
        tangents, point_laws = {}, {}
        for b in self.bodies:
            law, key = self.laws[b.tag], law_key(self.laws[b.tag])
            if law.finite_strain:
                point_laws.setdefault(key, fs.PointLaw(law))
            elif key not in tangents:
                tangents[key] = mp.law_tangent(law)  # ValueError for other nonlinear laws
        self.C = {t: tangents[law_key(w)] for t, w in self.laws.items() if not w.finite_strain}
        self.point_laws = {
            t: point_laws[law_key(w)] for t, w in self.laws.items() if w.finite_strain
        }
        # each body's level set lives on a window of the grid (grid-line indices (i0, i1, j0,
        # j1)) that only grows (`_grow`): its nodes outside hold the initial shape's values,
        # so a body costs its own size in time and memory, not the grid's
        self.shapes = {b.tag: b.shape for b in self.bodies}
        self.levelsets, self.windows = {}, {}
        for b in self.bodies:
            self.windows[b.tag] = w = self._initial_window(b.shape)
            self.levelsets[b.tag] = self._sample(b.shape, w)
        self.build_scene = build_scene
        self.obstacles = list(obstacles)
        self.dirichlet = list(dirichlet)
        self.reinit_drift = float(reinit_drift)
        if levelset_update not in evolution.LEVELSET_UPDATES:
            raise ValueError(f"levelset_update must be one of {evolution.LEVELSET_UPDATES}")
        self.levelset_update = levelset_update
        self.dynamics = dynamics  # None: quasi-static; a mpm.dynamics.PointNewmark
        if not (isinstance(max_splits, int) and 0 <= max_splits <= 10):
            raise ValueError(f"ImplicitMPM: max_splits must be an integer in [0, 10], got "
                             f"{max_splits!r}")  # fmt: skip
        self.max_splits = max_splits  # halvings of a failed quasi-static step (`step`)
        # quasi-static: Newton starts from the last step's increment where that lowers the
        # first residual (`increment.py`); the Increment of the last accepted (sub-)step
        if extrapolate is None:
            extrapolate = not any(law.history_size for law in self.laws.values())
        self.extrapolate = bool(extrapolate)
        self.increment = None
        self.grid_key = (
            (self.xlines[0], self.ylines[0]),
            self.h,
            (len(self.xlines), len(self.ylines)),
        )
        self.timer = timer
        self.threads = worker_threads(comm)
        self.log = log if comm.rank == 0 else (lambda *a, **k: None)
        if problem_kw.get("enforcement") == "augmented":
            # the lumped projection of the multipliers: with the hybrid one (the single-step
            # default) the grain assembly's Newton cycles from its second step on
            problem_kw.setdefault("multiplier_mass", "lumped")
            if self.point_laws:  # a finite-strain body: the stiffer eps_n (see the constant)
                problem_kw.setdefault("regularisation", FINITE_STRAIN_REGULARISATION)
        if dynamics is None:  # quasi-static: see RISE_LIMIT
            problem_kw = quasi_static(problem_kw)
        options(**problem_kw)  # an unknown option fails here, not at the first step
        self.problem_kw = problem_kw
        # the contact band (the largest initial gap Gamma_c covers): the given one or 2 h to
        # start, doubled whenever a converged step has active points near its edge (`step`)
        self.band = float(problem_kw.pop("band", None) or 2 * self.h)
        self.points = None  # {tag: MaterialPoints}, seeded on the first scene
        # pair key -> (points (n, 2), elastic tangential gap, tau_n, tau_t (n,)): the contact
        # state the next step's points start from (records.transfer_friction)
        self.friction = {}
        self.step_count = 0
        self._substep = 0  # the step in progress's converged sub-steps (`step`)
        self._pending = None  # the problem of the sub-step in progress (`_band_step`)
        self.problem = None
        self.scene = None
        self._key = None  # _scene_key of self.scene

    # ------------------------------------------------------------------ state
    def phase(self, name):
        return nullcontext() if self.timer is None else self.timer.phase(name)

    def snapshot(self):
        """Every piece of state a step changes: the points' arrays and the level sets shared
        (a step replaces them, never writes into them), the rest copied."""
        return dict(
            points=None if self.points is None else {t: p.shared() for t, p in self.points.items()},
            levelsets=dict(self.levelsets),  # LevelSets are immutable: shared, not copied
            windows=dict(self.windows),
            obstacles=[ob.state() for ob in self.obstacles],
            friction={k: tuple(a.copy() for a in v) for k, v in self.friction.items()},
            step_count=self.step_count,
            time=None if self.dynamics is None else self.dynamics.time,
            increment=self.increment,  # immutable: shared
        )

    def restore(self, snap):
        self.points = (
            None if snap["points"] is None else {t: p.shared() for t, p in snap["points"].items()}
        )
        self.levelsets, self.windows = dict(snap["levelsets"]), dict(snap["windows"])
        for ob, s in zip(self.obstacles, snap["obstacles"]):
            ob.set_state(s)
        self.friction = {k: tuple(a.copy() for a in v) for k, v in snap["friction"].items()}
        self.step_count = snap["step_count"]
        self.increment = snap["increment"]
        if self.dynamics is not None:
            self.dynamics.time = snap["time"]

    # ------------------------------------------------------------------ one step
    def step(self):
        """One load step (module docstring). Returns the step record (dict). On failure
        (ContactSolverError, RuntimeError) the state is restored and the error re-raised.

        A quasi-static step whose solve fails (Newton after its own cut-backs, a non-finite
        residual, the geometry of its cut cells) is done again from the same state as two half
        steps, each on the cut cells of its own start (the obstacles' motion and the Dirichlet
        increments, which ramp with lam, go to lam = 1/2; the stress, F and history carried by
        the points in between), down to 2^-max_splits of the step. The record is the last
        sub-step's with the counters summed and `substeps` the number taken (1: not split).
        Dynamics has its own step-size control (mpm/dynamics.py); a Dirichlet value given as a
        nonzero number does not ramp with lam, so either keeps the step whole.

        A converged step whose active contact points reach the edge of the contact band (an
        initial gap above 0.9 band: Gamma_c may cut the contact zone off) is done again from
        the same state with the band doubled, up to MAX_BAND_GROWTH times; the record says
        which band it used (`band`)."""
        snap = self.snapshot()
        self._substep = 0
        try:
            records_ = self._advance(1.0, 0, snap)
        except Exception:
            self.restore(snap)
            # each sub-step freed the problem before it (`_drop_previous`); one still here (a
            # failure before the sub-step's own build) has nothing to fall back to it either:
            # the next step builds problem and mesh again from the restored state
            if self.problem is not None:
                self.problem.destroy()
            self.problem = self.scene = self._key = None
            raise
        snap = None
        record = records_[-1]
        for k in _SUMMED:
            record[k] = type(record[k])(sum(r[k] for r in records_))
        record["residuals"] = [v for r in records_ for v in r["residuals"]]
        record["substeps"] = len(records_)
        for r in records_[:-1]:  # the deepest point of any sub-step (`records.penetrations`)
            for name, (depth, other) in r["penetration"].items():
                if depth > record["penetration"].get(name, (0.0, None))[0]:
                    record["penetration"][name] = (depth, other)
        self.step_count += 1
        record["step"] = self.step_count
        return record

    def _splittable(self):
        ramped = all(callable(d.value) or float(d.value) == 0.0 for d in self.dirichlet)
        return self.dynamics is None and ramped

    def _advance(self, fraction, depth, snap=None):
        """The records of `fraction` of the step, split in halves while it fails (`step`).
        snap: a snapshot of the present state, if the caller has one (restore copies from a
        snapshot, so one serves every attempt from that state: 0.5 s a copy at 400 grains)."""
        try:
            return [self._band_step(fraction, snap)]
        except (ContactSolverError, RuntimeError) as e:
            if depth >= self.max_splits or not self._splittable():
                if depth == 0:
                    raise
                raise ContactSolverError(f"{e} (at 1/{2**depth} of the step)") from e
            self.log(f"{e}; done again in two halves")
        first = self._advance(fraction / 2, depth + 1, snap)  # restored to snap: its state
        return first + self._advance(fraction / 2, depth + 1)

    def _band_step(self, fraction, snap=None):
        """`fraction` of the step, the band doubled while active points reach its edge."""
        snap = snap or self.snapshot()
        for attempt in range(MAX_BAND_GROWTH + 1):
            try:
                record = self._step(fraction)
            except Exception:
                if self._pending is not None:
                    self._pending.destroy()
                    self._pending = None
                self.restore(snap)
                raise
            if attempt == MAX_BAND_GROWTH or not self.band_reached():
                record["band"] = self.band
                self._substep += 1
                return record
            self.restore(snap)
            self.band *= 2.0
            self.log(f"contact band doubled to {self.band:.4g}: active points reached its edge")

    def band_reached(self):
        """Whether an active contact point of the last step has an initial gap above 0.9 band
        (the same on every rank)."""
        near = False
        for g, s in zip(self.problem.contact.pairs, self.problem.contact.committed):
            if s is not None and np.any((s["state"] > 0) & (g.g_n0 > 0.9 * self.band)):
                near = True
        return bool(self.comm.allreduce(near, op=MPI.LOR))

    def _drop_previous(self, keep_scene):
        """Free the last step's problem, and its mesh unless this step keeps it, before this
        step builds its own: nothing reads them again (a failed step falls back to none; the
        next one builds them again). Collected now: they hold reference cycles (problem <->
        solver, pairs <-> bodies), and their memory is then free for this step's, which would
        otherwise come from fresh pages (100 grains x 30 steps: peak 1289 -> 724-754 MB when
        the end of a step collected them; 1000 grains x 10 steps on 2 ranks: 8583 MB kept
        through the step, 8043 MB with its matrices freed here, 7593 MB with all of it)."""
        if self.problem is None and (keep_scene or self.scene is None):
            return
        if self.problem is not None:
            self.problem.destroy()
            self.problem = None
        if not keep_scene:
            self.scene = None
        gc.collect()

    def _step(self, fraction=1.0):
        """The solve and update of `fraction` of the step (lam from 0 to fraction)."""
        t0 = time.perf_counter()
        with self.phase("mesh"):
            pairs = self.candidate_pairs()
            ranks, contact_boxes = self.contact_ranks(pairs)
            key, boxes = self._scene_key(pairs)
            if contact_boxes is not None:
                key += [contact_boxes["boxes"].tobytes(), contact_boxes["owners"].tobytes()]
            rebuilt = self.scene is None or key != self._key
            self._drop_previous(keep_scene=not rebuilt)
            if rebuilt:
                scene = self.build_scene(dict(self.levelsets), pairs, contact_boxes)
            else:  # same active cells, kinds and pairs: the mesh and its tags stay
                scene = self.scene
                for body, b, box in zip(scene.bodies, self.bodies, boxes):
                    body.shape = scene.cut.levelsets[b.tag] = self.levelsets[b.tag]
                    body.bbox = box
        sigma0, laws, mls_info = None, dict(self.laws), {"widened": 0}
        with self.phase("mls"):
            if self.points is not None and self.C:
                sigma0 = self._project(scene, "stress", list(self.C), 3, mls_info)
            laws.update(self._finite_strain_laws(scene, mls_info))
            loads = [] if self.dynamics is None else self._inertia(scene, laws, mls_info)
        if sigma0 is not None:
            S = _stress_tensor(sigma0)
            loads.append(
                Load(
                    lambda v, measure: -ufl.inner(S, ufl.grad(v)) * measure(None, degree=mp.DEGREE),
                    scale=lambda lam: 1.0,
                )
            )
        kw = dict(self.problem_kw, band=self.band, band_growth=0)  # `step` grows it
        kw.setdefault("short_lived", True)  # a mesh per step: MUMPS's cheaper analysis
        kw.setdefault("pair_grid_origin", (self.xlines[0], self.ylines[0]))
        if ranks is not None:
            kw["contact_rank"] = ranks
        extrapolate = self.extrapolate and self.dynamics is None
        predictor = None
        if extrapolate and self.increment is not None:
            predictor = increment.predictor(self.increment, self.grid_key)
        problem = ContactProblem(
            scene,
            laws,
            dirichlet=self.dirichlet,
            loads=loads,
            obstacles=self.obstacles,
            timer=self.timer,
            log=self.log,
            predictor=predictor,
            **options(**kw),
        )
        if self.points is None:
            self.points = {b.tag: mp.seed(scene, problem.integration, b.tag) for b in self.bodies}
            for t, pts in self.points.items():
                h0 = np.asarray(self.laws[t].initial_history, float)
                pts.history = np.tile(h0, (len(pts), 1))
                if self.dynamics is not None:
                    pts.a = np.tile(self.dynamics.a0, (len(pts), 1))
        self._pending = problem  # destroyed if the step fails (`step`)
        keys = problem.contact.names(scene)
        with self.phase("contact"):
            records.transfer_friction(self, problem, keys)
        label = f"MPM step {self.step_count + 1}" + (f" ({fraction:g})" if fraction < 1 else "")
        problem.solve(1, fraction, label=label)
        # ---- converged: from here on the state changes
        record = records.contact_record(self, problem, scene, keys)
        record["support_forces"] = records.support_forces(self, problem, scene)
        with self.phase("points"):
            outside = 0
            moved = []
            at = {b.tag: mp.displacement_at(problem, b.tag, self.points[b.tag].x, self.h)
                  for b in self.bodies}  # fmt: skip
            for b in self.bodies:  # a folded point (det f <= 0): the step is rejected (split)
                bad = np.zeros(0, int)
                if b.tag in self.point_laws:
                    bad = np.flatnonzero(mp.det2(np.eye(2) + at[b.tag][1]) <= 0)
                if len(bad):
                    x = self.points[b.tag].x[bad[0]]
                    raise ContactSolverError(
                        f"{label}: the increment folds {len(bad)} point(s) of body {b.name!r} "
                        f"(det(I + grad du) <= 0; one at ({x[0]:.4g}, {x[1]:.4g}))"
                    )
            for b in self.bodies:
                pts = self.points[b.tag]
                du, grad, n_out = at[b.tag]
                if self.dynamics is not None:
                    self.dynamics.update(pts, du)
                if b.tag in self.point_laws:
                    mp.update_finite(pts, du, grad, self.point_laws[b.tag])
                else:
                    mp.update(pts, du, grad, self.C[b.tag])
                outside += n_out
                moved.append(du)
            if extrapolate:
                self.increment = increment.record(problem, self.grid_key, fraction)
            if self.step_count == 0:  # the whole first step's, over its sub-steps
                first = self._substep == 0
                self.first_step_du = moved if first else [*map(np.add, self.first_step_du, moved)]
        with self.phase("evolution"):
            evo = evolution.evolve(self, problem, scene)
        for ob in self.obstacles:
            ob.advance(fraction)
        with self.phase("points"):
            record["penetration"] = records.penetrations(self)
        if self.dynamics is not None:
            self.dynamics.time += self.dynamics.dt
            record["time"] = self.dynamics.time
            record["kinetic_energy"] = {
                b.name: self.dynamics.kinetic_energy(self.points[b.tag], self.dynamics.rho[b.tag])
                for b in self.bodies
            }
        self.problem, self.scene, self._key, self._pending = problem, scene, key, None
        imap = problem.V.dofmap.index_map
        record.update(
            newton_iterations=int(sum(s.iterations for s in problem.steps)),
            # |R| of every Newton iteration of the accepted solve (a cut-back's are dropped)
            residuals=[float(r) for s in problem.steps for r in s.residuals],
            cutbacks=int(sum(s.cutback for s in problem.steps)),
            predicted=int(problem.guess_taken),  # `increment.py`
            # sparse factorisations of the accepted solve (each step builds its own problem)
            factorisations=int(problem.factorisations),
            coupling_rebuilds=int(problem.coupling_rebuilds),  # SolverOptions.coupling_gap
            num_dofs=int(imap.size_global * problem.bs),
            num_cells=int(scene.mesh.topology.index_map(2).size_global),
            points_outside_cells=outside,
            mesh_rebuilt=bool(rebuilt),
            mls_widened=mls_info["widened"],
            mls_F_nearest=mls_info.get("F_nearest", 0),
            mass={b.name: float(self.points[b.tag].vol0.sum()) for b in self.bodies},
            volume_points={b.name: float(self.points[b.tag].vol.sum()) for b in self.bodies},
            # the smallest and largest vol / vol0 = det F of each body's points
            point_volume_ratio={b.name: _ratio_range(self.points[b.tag]) for b in self.bodies},
            wall_s=time.perf_counter() - t0,
            **evo,
        )
        # the next step factorises its own mesh's J: this one's factors go before it does
        # (400 grains: peak memory 2.80 -> 2.32 GB)
        problem.release_solver()
        return record

    # ------------------------------------------------------------------ level-set windows
    def subgrid(self, window):
        """The grid's sub-grid of grid-line indices (i0, i1, j0, j1)."""
        i0, i1, j0, j1 = window
        return _cpp.StructuredGrid(self.xlines[i0 : i1 + 1], self.ylines[j0 : j1 + 1])

    def _sample(self, shape, window):
        """The level set of a shape (a `_cpp.Shape` or a grid LevelSet) sampled at the nodes of
        a window."""
        grid = self.subgrid(window)
        if isinstance(shape, _cpp.LevelSet):
            return _cpp.LevelSet(grid, shape.evaluate(grid.nodes())[0])
        return _cpp.levelset_from_shape(grid, shape)

    def _initial_window(self, shape, coarse=8, margin=8):
        """A window holding the shape with `margin` cells around it: first from its values on
        every `coarse`-th grid line (a signed distance: nodes within a coarse cell's diagonal of
        the body mark it), widened until every node of the window's border is outside, then
        cut to `margin` cells around its nodes inside. Any window gives the same answers (the
        level set's values outside it are the shape's own, `_grow`): this one is small."""
        nx, ny = len(self.xlines), len(self.ylines)
        ci, cj = np.r_[0:nx:coarse, nx - 1], np.r_[0:ny:coarse, ny - 1]
        X, Y = np.meshgrid(self.xlines[ci], self.ylines[cj])
        P = np.ascontiguousarray(np.stack([X.ravel(), Y.ravel()], axis=1))
        phi = (shape.evaluate(P)[0] if isinstance(shape, _cpp.LevelSet) else shape(P)).reshape(
            X.shape
        )
        near = phi < np.sqrt(2) * coarse * self.h
        if not near.any():
            return 0, nx - 1, 0, ny - 1
        rows, cols = np.flatnonzero(near.any(axis=1)), np.flatnonzero(near.any(axis=0))
        w = [ci[cols[0]], ci[cols[-1]], cj[rows[0]], cj[rows[-1]]]
        while True:
            w = [max(w[0] - margin, 0), min(w[1] + margin, nx - 1)] + [
                max(w[2] - margin, 0),
                min(w[3] + margin, ny - 1),
            ]
            v = self._sample(shape, w).values
            border = np.r_[v[0], v[-1], v[:, 0], v[:, -1]]
            if border.min() > 0 or w == [0, nx - 1, 0, ny - 1]:
                break
        # then `margin` cells around the nodes inside, within it
        rows, cols = np.flatnonzero((v < 0).any(axis=1)), np.flatnonzero((v < 0).any(axis=0))
        if len(rows):
            w = [
                max(w[0] + cols[0] - margin, w[0]),
                min(w[0] + cols[-1] + margin, w[1]),
                max(w[2] + rows[0] - margin, w[2]),
                min(w[2] + rows[-1] + margin, w[3]),
            ]
        return tuple(int(k) for k in w)

    def _grow(self, tag, want):
        """Widen body `tag`'s window to hold the window `want` (the new nodes: the initial
        shape's values, as the whole-grid level set had there)."""
        have = self.windows[tag]
        new = (min(have[0], want[0]), max(have[1], want[1]), min(have[2], want[2]))
        new = tuple(int(k) for k in new + (max(have[3], want[3]),))
        if new == have:
            return
        values = self._sample(self.shapes[tag], new).values
        values[
            have[2] - new[2] : have[3] - new[2] + 1, have[0] - new[0] : have[1] - new[0] + 1
        ] = self.levelsets[tag].values
        self.levelsets[tag] = _cpp.LevelSet(self.subgrid(new), values.ravel())
        self.windows[tag] = new

    def _beyond_window(self, tag):
        """Body `tag`'s level-set value beyond its window in the whole-grid views: its largest
        value there, at least h (positive: the zero contour lies inside the window)."""
        return max(float(self.levelsets[tag].values.max()), self.h)

    def levelset_values(self, tag):
        """Body `tag`'s level set on the whole grid, (ny, nx): its window's values, and beyond
        the window `_beyond_window`. For output and plots."""
        i0, i1, j0, j1 = self.windows[tag]
        full = np.full((len(self.ylines), len(self.xlines)), self._beyond_window(tag))
        full[j0 : j1 + 1, i0 : i1 + 1] = self.levelsets[tag].values
        return full

    def grid_increment(self, name):
        """The last step's extended increment of body `name` on the whole grid (nx ny, 2):
        zero beyond the window its level set was advected on (`evolution.evolve`)."""
        (i0, i1, j0, j1), v = self.grid_increments[name]
        full = np.zeros((len(self.ylines), len(self.xlines), 2))
        full[j0 : j1 + 1, i0 : i1 + 1] = v
        return full.reshape(-1, 2)

    def union_fields(self):
        """The bodies' level sets and step increments on the whole grid in one field each, at
        the cost of the grid and the bodies' windows (per-body whole-grid fields cost bodies x
        grid: 10 GB a frame at 1000 grains). phi (nx ny,): the smallest of the bodies'
        `levelset_values` at each node, exactly; body (nx ny,): the index in `bodies` of the
        body whose window value gives it (the first of equals), -1 where it is a value beyond
        a window; du (nx ny, 2): that body's extended step increment (`grid_increment`)."""
        shape = (len(self.ylines), len(self.xlines))
        # no window value is above its body's `_beyond_window`, so seeding with the smallest
        # of those gives the minimum of the whole-grid fields
        far = min(self._beyond_window(b.tag) for b in self.bodies)
        phi, body = np.full(shape, far), np.full(shape, -1, np.int32)
        for k, b in enumerate(self.bodies):
            i0, i1, j0, j1 = self.windows[b.tag]
            v, sub = self.levelsets[b.tag].values, phi[j0 : j1 + 1, i0 : i1 + 1]
            closer = v < sub
            sub[closer] = v[closer]
            body[j0 : j1 + 1, i0 : i1 + 1][closer] = k
        du = np.zeros(shape + (2,))
        index = {b.name: k for k, b in enumerate(self.bodies)}
        for name, ((i0, i1, j0, j1), v) in getattr(self, "grid_increments", {}).items():
            mine = body[j0 : j1 + 1, i0 : i1 + 1] == index[name]
            du[j0 : j1 + 1, i0 : i1 + 1][mine] = v[mine]
        return phi.ravel(), body.ravel(), du.reshape(-1, 2)

    # ------------------------------------------------------------------ parts
    def body_boxes(self):
        """(n, 2, 2) bounding box of each body's material: the grid nodes with phi <= 0, grown by
        one spacing (the zero contour lies within it)."""
        out = []
        for b in self.bodies:
            i0, i1, j0, j1 = self.windows[b.tag]
            inside = self.levelsets[b.tag].values <= 0
            if not inside.any():
                raise RuntimeError(f"body {b.name!r}: its level set has no node inside")
            rows, cols = np.flatnonzero(inside.any(axis=1)), np.flatnonzero(inside.any(axis=0))
            x, y = self.xlines[i0 : i1 + 1], self.ylines[j0 : j1 + 1]
            lo = np.array([x[cols[0]], y[rows[0]]]) - self.h
            hi = np.array([x[cols[-1]], y[rows[-1]]]) + self.h
            out.append([lo, hi])
        return np.array(out)

    def _scene_key(self, pairs):
        """What decides the cut mesh: each body's active cells and their kinds (interior/cut,
        `cut.grid_cells`), and the pairs; with the bodies' material boxes."""
        key, boxes = [tuple(pairs)], []
        for b in self.bodies:
            phi, (a0, _, b0, _) = self.levelsets[b.tag].values, self.windows[b.tag]
            i0, i1, j0, j1 = material_window(phi)  # grid_scene's window of the body
            g = grid_cells(
                self.xlines[a0 + i0 : a0 + i1 + 1],
                self.ylines[b0 + j0 : b0 + j1 + 1],
                np.ascontiguousarray(phi[j0 : j1 + 1, i0 : i1 + 1]).ravel(),
            )
            key += [(a0 + i0, a0 + i1, b0 + j0, b0 + j1), g["active"].tobytes()]
            key += [g["kinds"].tobytes()]
            boxes.append(g["bbox"])
        return key, boxes

    def contact_ranks(self, pairs):
        """In parallel: the box of each pair's contact region (grid nodes within the band of
        both bodies, grown by the band and 2 h: Gamma_c, its closest points and their cells lie
        inside) and the rank that computes it. Pairs go to ranks in contiguous groups along the
        domain's longest axis, each pair on its own rank whatever its neighbours: the
        partitioner gives each box's cells to its rank, as owned cells or, where another box
        already claimed them, as ghost cells (`dolfinx_forms.mesh.scene.contact_partitioner`).
        Returns ({pair_key: rank}, {"boxes", "owners"}) or (None, None) on one rank."""
        size = self.comm.size
        if size == 1:
            return None, None
        band, xl, yl = self.band, self.xlines, self.ylines
        # each body's nodes within the band, on its window only (beyond it its level set is >=
        # its margin, 8 h): whole-grid masks per body cost O(bodies x grid) a step
        near = {}  # tag -> (i0, j0, mask over the window (rows y, columns x))
        for b in self.bodies:
            i0, _, j0, _ = self.windows[b.tag]
            near[b.tag] = (i0, j0, self.levelsets[b.tag].values < band)
        keys, boxes = [], []

        def add(key, i0, j0, mask):
            if mask.any():
                rows, cols = np.nonzero(mask)
                x, y = xl[i0 + cols], yl[j0 + rows]
                grow = 2 * self.h  # P_i, P_j lie within band / 2 of Gamma_c: their cells in here
                keys.append(key)
                boxes.append([[x.min() - grow, y.min() - grow], [x.max() + grow, y.max() + grow]])

        for i, j in pairs:  # on the overlap of the two windows
            (ai, aj, ma), (bi, bj, mb) = near[self.bodies[i].tag], near[self.bodies[j].tag]
            x0, y0 = max(ai, bi), max(aj, bj)
            x1 = min(ai + ma.shape[1], bi + mb.shape[1])
            y1 = min(aj + ma.shape[0], bj + mb.shape[0])
            if x1 > x0 and y1 > y0:
                m = (
                    ma[y0 - aj : y1 - aj, x0 - ai : x1 - ai]
                    & mb[y0 - bj : y1 - bj, x0 - bi : x1 - bi]
                )
                add((i, j), x0, y0, m)
        for ob in self.obstacles:
            for i, b in enumerate(self.bodies):
                if ob.bodies is None or b.tag in np.atleast_1d(ob.bodies):
                    i0, j0, m = near[b.tag]
                    rows, cols = np.nonzero(m)
                    m = m.copy()
                    m[rows, cols] = ob.values(np.stack([xl[i0 + cols], yl[j0 + rows]], 1)) < band
                    add((i, ob.name), i0, j0, m)
        if not keys:
            return None, None
        boxes = np.array(boxes)
        axis = int(np.argmax([xl[-1] - xl[0], yl[-1] - yl[0]]))
        order = np.argsort(0.5 * (boxes[:, 0, axis] + boxes[:, 1, axis]), kind="stable")
        owners = np.empty(len(keys), np.int32)
        owners[order] = (np.arange(len(keys)) * size) // len(keys)
        ranks = {k: int(r) for k, r in zip(keys, owners)}
        return ranks, {"boxes": boxes, "owners": owners}

    def candidate_pairs(self, boxes=None):
        """Body pairs whose boxes, inflated by the contact band (and the level-set grid of the
        pair search), overlap: the broad phase (`_cpp.candidate_pairs`, sort and sweep), so the
        narrow phase (Gamma_c, eqs 21-24) runs on touching pairs only. boxes: `body_boxes()`,
        if the caller has them."""
        if len(self.bodies) < 2:
            return []
        boxes = self.body_boxes() if boxes is None else boxes
        pairs = _cpp.candidate_pairs(boxes.reshape(len(self.bodies), 4), 0.5 * self.band)
        return [tuple(int(v) for v in p) for p in np.asarray(pairs).reshape(-1, 2)]

    def _quadrature_function(self, scene, dim, name):
        """A `Quadrature` vector Function of `dim` components at the Gauss points (degree
        mp.DEGREE) of every cell, and its (cells, points) dof table."""
        mesh = scene.mesh
        Qe = ufl.VectorElement(
            "Quadrature", mesh.ufl_cell(), mp.DEGREE, dim=dim, quad_scheme="default"
        )
        q = fem.Function(fem.FunctionSpace(mesh, Qe), name=name)
        return q, q.function_space.dofmap.list.array.reshape(len(scene.cell_tags.values), -1)

    def _project(self, scene, field, tags, dim, info, out=None, inside=False):
        """MLS projection of the points' `field` ((n, dim) per point) of the bodies `tags` to
        the Gauss points of their cells: a `Quadrature` Function (`out`, or a new one).
        inside: Gauss points of cut cells outside the body take the value at their closest
        point on the contour (x - phi grad phi / |grad phi|), not the MLS extrapolation beyond
        the points: the finite-strain fields enter ln det F and the law's logarithms, which an
        extrapolated F or b_e with det <= 0 would make NaN."""
        q, qdofs = self._quadrature_function(scene, dim, field) if out is None else out
        arr = q.x.array.reshape(-1, dim)
        widened = nearest = 0
        for t in tags:
            cells = scene.body_cells(t)
            if len(cells) == 0:
                continue
            targets = mp.quadrature_points(scene, cells).reshape(-1, 2)
            if inside:
                phi, grad = self.levelsets[t].evaluate(targets)
                out_ = phi > 0
                g = grad[out_] / np.linalg.norm(grad[out_], axis=1)[:, None]
                targets[out_] -= phi[out_, None] * g
            pts = self.points[t]
            values = field(t, pts) if callable(field) else getattr(pts, field)
            values = np.ascontiguousarray(values.reshape(len(pts), dim))
            r = _cpp.MLSProjector(pts.x, self.h).project(
                values, np.ascontiguousarray(targets), self.threads
            )
            if field == "F":
                nearest += _guard_jacobian(r["values"], targets, pts.x, values)
            arr[qdofs[cells].ravel()] = r["values"]
            widened += int(np.sum(r["widening"] > 1))
        widened = self.comm.allreduce(widened, op=MPI.SUM)
        if widened:
            self.log(f"MLS: {widened} integration points needed a wider support (reported)")
        nearest = self.comm.allreduce(nearest, op=MPI.SUM)
        if nearest:
            self.log(f"MLS: {nearest} integration points took their nearest point's F (reported)")
        info["widened"] += widened
        info["F_nearest"] = info.get("F_nearest", 0) + nearest
        return q

    def _inertia(self, scene, laws, info):
        """Dynamics: v, a and the density projected from the points (at the step's start: zero
        and rho_0), each law with its mass term (in place in `laws`), and the inertia and
        gravity load (mpm/dynamics.py)."""
        dyn, d = self.dynamics, 2
        q, qd = self._quadrature_function(scene, 2 * d + 1, "kinematics")
        arr = q.x.array.reshape(-1, 2 * d + 1)
        for b in self.bodies:  # before the points exist: at rest, a = a0, rho_0
            cells = scene.body_cells(b.tag)
            arr[qd[cells].ravel(), d : 2 * d] = dyn.a0
            arr[qd[cells].ravel(), 2 * d] = dyn.rho[b.tag]
        if self.points is not None:
            values = lambda t, pts: dyn.point_values(pts, dyn.rho[t])  # noqa: E731
            self._project(scene, values, [b.tag for b in self.bodies], 2 * d + 1, info, (q, qd),
                          True)  # fmt: skip
            # the mass is the points' (constant); the level set's area drifts with advection
            # (a percent over a deposit's hundreds of steps), so each body's density is scaled
            # by points' volume / level-set area: its weight and inertia stay the points'
            for b in self.bodies:
                cells = scene.body_cells(b.tag)
                area = _cpp.levelset_area(self.levelsets[b.tag])
                arr[qd[cells].ravel(), 2 * d] *= self.points[b.tag].vol.sum() / area
        laws.update(dyn.laws(laws, q, mp.DEGREE))
        return [dyn.load(q, mp.DEGREE)]

    def _finite_strain_laws(self, scene, info):
        """{tag: fs.UpdatedLaw} of the finite-strain bodies: F_n and the history projected from
        the points (identity and the initial history before the first step), one UpdatedLaw
        per distinct law."""
        if not self.point_laws:
            return {}
        Fq, qd = self._quadrature_function(scene, 4, "F_n")
        Fq.x.array.reshape(-1, 4)[:] = np.eye(2).ravel()
        if self.points is not None:
            self._project(scene, "F", list(self.point_laws), 4, info, (Fq, qd), True)
        out, shared = {}, {}
        for t in self.point_laws:
            law = self.laws[t]
            key = law_key(law)
            if key not in shared:
                tags = [s for s in self.point_laws if law_key(self.laws[s]) == key]
                hq = None
                if law.history_size:
                    k = law.history_size
                    hq, hd = self._quadrature_function(scene, k, "history")
                    hq.x.array.reshape(-1, k)[:] = np.asarray(law.initial_history, float)
                    if self.points is not None:
                        self._project(scene, "history", tags, k, info, (hq, hd), True)
                shared[key] = fs.UpdatedLaw(law, Fq, hq, mp.DEGREE)
            out[t] = shared[key]
        return out
