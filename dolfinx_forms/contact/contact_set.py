"""The contact set: every pair's contact points and their state, one owner of the history.

For each body pair (`contact.pair_geometry`, built once per scene in the reference
configuration) the C++ kernel of eq 48 gives, from the displacement, the gaps (eqs 26-31),
the return mapping (Algorithm 1) and the residual and consistent tangent. The plastic slip
g_t^p (eqs 10-12) lives in one `_cpp.FrictionHistory` per pair: the kernel reads its
committed values, each Newton iteration sets its trial values, an accepted step commits
them and a rejected one restores them exactly.

The law acts at the *law points*: the pair's multiplier nodes (`contact.multiplier_nodes`,
each with the weighted mean gap of its points; traction "nodes"), or the points themselves
(without multiplier nodes, or with traction "points").

Enforcement: "penalty" (eqs 8, 12: the answer depends on eps) or "augmented" (augmented
Lagrangian, Uzawa's outer loop of seed 003): multipliers lambda_n, lambda_t per law point enter
the law as tau_n = min(0, lambda_n + g_n / eps_n) (the kernel's gap shift eps_n lambda_n) and
tau_t,trial = lambda_t + (g_t - g_t,start) / eps_t (through the slip the kernel reads); after
each converged Newton solve `newton.augmented_loop` sets lambda <- tau, until the tractions
stop changing. The fixed point has zero mean gap at every active node and zero slip over the
step at every sticking one, whatever eps: eps sets the speed of the loop, not the answer. The
multipliers of a step start from the committed tractions; a rejected step restores them.

With traction "points" the multipliers are P1 along Gamma_c but the law acts at every point
with them interpolated there, lambda_h(x_p): tau_n,p = min(0, lambda_h(x_p) + g_n,p / eps_n),
and Uzawa's update is the lumped L2 projection lambda <- Pi tau (`PairGeometry.project`). At the
fixed point a node whose hat lies in contact has the weighted mean gap
eps_n ((M_L - M) lambda)_i / W_i (M, M_L: the consistent and lumped mass of the hats), a
stabilised mortar constraint of size eps_n h^2 lambda'' (Hertz: 7.5e-4 h), while the traction
keeps the point-wise shape of the gap between the nodes: the contact edge and the stick/slip
boundary fall between nodes as with the penalty (Hertz at h = a/20: p(x) 0.91 % body-fitted,
1.19 % cut, against 2.43 % and 3.46 % with traction "nodes"). eps_n and eps_t are then part
of the discretisation (`defaults.TUNING`: pointwise_eps0, pointwise_eps0_t), and the user's eps0
only relaxes the Uzawa step (`relaxation` <= 1). A zero mean gap at every active node instead
(Uzawa on the nodes' weighted mean gaps, lambda <- min(0, lambda + M_L^-1 int psi (tau -
lambda_h)) node by node) converges to 1e-9 h, but its pressure depends on where the nodes fall
against the contact edge: Hertz at h = 0.05, loads 350-520 (nodes 1.25 h apart, eps 1.5 h/E:
its best at a/20), 0.92-1.55 % body-fitted and 1.15-2.05 % cut, against 0.92-1.02 % and
0.99-1.17 % for this projection (docs/notes/design.md).
multiplier_mass "consistent" projects with the hats' consistent mass instead, lambda <-
M^-1 int psi tau (`PairGeometry.consistent_projection`): a node in contact then has zero
weighted mean gap and every other one a gap >= 0 (int_open psi (eps lambda_h + g)), at the price
of a coarser pressure (Hertz a/20: 1.16 % / 1.53 %, 1.0-1.3 % body-fitted over loads 350-520);
its multipliers are left unclipped (`admissible`).
multiplier_mass "hybrid" (the default with "augmented") takes from each what it does well
(`PairGeometry.hybrid_projection`): a node whose hat is mostly in contact
(defaults.TUNING.hybrid_closed_fraction of its weight on closed points) gets the consistent row, so
int psi_i g >= 0 at the fixed point and = 0 where the hat is all in contact; the nodes at and past
the contact edge keep the lumped row, which does not fit the square-root edge by an overshooting L2
fit. Tangential tractions are projected lumped (the lumped q(x)); their regularisation is continued
within each step (eps_t_start = 1.5 h/E until the loop nearly converges, `NewtonOptions.al_switch`,
then eps_t = 1 h/E, `defaults.TUNING.consistent_eps0_t`): at 1.5 h/E alone the smoothed multipliers
let points just past the stick/slip boundary stick (stick zone +0.49 % mean over 24 Mindlin runs,
0.17 % with the continuation). Where the loop cycles (a row switching as points open and close) the
rows are frozen (`freeze_rows`). Hertz a/20, loads 350-520: p(x) 0.78-1.09 % body-fitted,
1.12-1.50 % cut, every weighted gap < 1e-9 h (docs/notes/design.md).
Its multipliers are left unclipped too.
"""

from concurrent.futures import ThreadPoolExecutor

import numpy as np

from dolfinx_forms import _cpp
from dolfinx_forms.common import worker_threads
from dolfinx_forms.contact.multipliers import Multipliers
from dolfinx_forms.contact.resultants import traction_resultant
from dolfinx_forms.geometry.pairs import pair_geometry

STATE_NAMES = {0: "open", 1: "stick", 2: "slip"}
# candidates a thread of `build_pairs` takes at least (fewer: the loop stays serial)
PAIRS_PER_THREAD = 8
_NONE = np.zeros(0)


def pair_key(pair, obstacle=None):
    """The key of a pair in a rank map: (i, j) for bodies, (i, obstacle name) for an obstacle."""
    return (int(pair[0]), obstacle.name) if obstacle is not None else (int(pair[0]), int(pair[1]))


class ContactSet(Multipliers):
    """Contact points of `scene.pairs` on rank `rank` (empty elsewhere; or a {pair_key: rank}
    map: each pair on its own rank, the others on rank 0; the cells of a pair may be ghost
    cells there: its dofs are local indices, ghosts included, and the residual and tangent
    rows of ghost dofs reach their owners by the callers' reverse scatter and PETSc's
    off-process assembly), penalty eps_n, eps_t
    (eq 51) and friction coefficient mu (0: frictionless, no history). obstacles:
    `obstacles.RigidObstacle`s, each paired with every body it may touch (its `bodies`); their
    prescribed motion at load level lam is set by `set_load`. eps_t_start (augmented, >= eps_t,
    default eps_t): the tangential regularisation each step's loop starts from, continued to
    eps_t once it converges (`newton.augmented_loop`). origins: {candidate index (`index`):
    the point its pair's level-set grid passes through} (a rebuild over a wider band keeps the
    old grids' lattices, `contact.band`)."""

    def __init__(
        self,
        V,
        scene,
        eps_n,
        eps_t,
        mu,
        band,
        grid_refine=4,
        num_gauss=2,
        rank=0,
        obstacles=(),
        lattice_origin=None,
        multipliers=None,
        multiplier_length=None,
        enforcement="penalty",
        traction="nodes",
        relaxation=1.0,
        multiplier_mass="lumped",
        eps_t_start=None,
        origins=None,
    ):
        if enforcement not in ("penalty", "augmented"):
            raise ValueError(f"enforcement must be 'penalty' or 'augmented', got {enforcement!r}")
        if not 0.0 < relaxation <= 1.0:
            raise ValueError(f"relaxation must be in (0, 1], got {relaxation!r}")
        self.enforcement = enforcement
        self.relaxation = float(relaxation)
        self.halvings = 0  # Uzawa steps halved where the active set cycled (`newton.al_stall`)
        self.alignments = 0  # multiplier node layouts aligned with the contact edges
        self.eps_n, self.eps_t, self.mu = float(eps_n), float(eps_t), float(mu)
        # the augmented loop's continuation in eps_t: each step's loop converges at eps_t_start
        # first, then at eps_t (`newton.augmented_loop`); self.eps_t is the one in use
        self.eps_t_final = self.eps_t
        self.eps_t_start = self.eps_t if eps_t_start is None else float(eps_t_start)
        if not self.eps_t_start >= self.eps_t:
            raise ValueError(f"eps_t_start must be >= eps_t = {eps_t!r}, got {eps_t_start!r}")
        self.obstacles = list(obstacles)
        kw = dict(
            grid_refine=grid_refine,
            num_gauss=num_gauss,
            lattice_origin=lattice_origin,
            multipliers=multipliers,
            multiplier_length=multiplier_length,
            traction=traction,
            multiplier_mass=multiplier_mass,
        )
        self.pairs, self.index = build_pairs(V, scene, band, rank, self.obstacles, kw, origins)
        self._lam = None
        # friction history, slip origin and multipliers live at the law points (the multiplier
        # nodes, or the points): `PairGeometry.num_law_points`
        self.history = [_cpp.FrictionHistory(g.num_law_points, 1) for g in self.pairs]
        self.slip_start = [np.zeros(g.num_law_points) for g in self.pairs]
        # plastic slip since friction was switched on, summed over accepted steps
        self.plastic = [np.zeros(g.num_law_points) for g in self.pairs]
        self.last = [None] * len(self.pairs)  # kernel output of the last evaluation
        self.committed = [None] * len(self.pairs)  # point states of the last accepted step
        # augmented Lagrangian multipliers (per law point): the step's
        # current ones and the committed tractions they start from
        self.lambda_n = [np.zeros(g.num_law_points) for g in self.pairs]
        self.lambda_t = [np.zeros(g.num_law_points) for g in self.pairs]
        # tractions a pair without a committed state starts from (the material-point path
        # carries them from the previous step's points: `set_start_tractions`)
        self.start_tractions = [None] * len(self.pairs)
        # where friction was switched on (displacement, load level; None: from the start, at
        # u = 0): the slip origin of points a rebuild adds (`contact.band`)
        self.friction_origin = None

    def __len__(self):
        return len(self.pairs)

    def insert_couplings(self, pattern, points=None):
        """The pairs' tangent blocks into a sparsity pattern: of the law points `points`
        (indices per pair), or of every law point (None)."""
        for k, g in enumerate(self.pairs):
            _cpp.insert_coupling(pattern, g.quadrature, None if points is None else points[k])

    def add_zeros(self, A, points=None):
        for k, g in enumerate(self.pairs):
            _cpp.add_coupling_zeros(A, g.quadrature, None if points is None else points[k])

    def law_gaps0(self, k):
        """Pair k's gap per law point before the step's deformation: the smallest of its
        points' (up to the weighted mean), the point's lesser of g_n0 and g_n0 + u_j.n after an
        obstacle's whole step motion (eq 26 with u_i = 0)."""
        g = self.pairs[k]
        gap = np.asarray(g.g_n0, float)
        if g.obstacle is not None:
            u_j = g.obstacle.step_displacement(g.p_j, 1.0)
            gap = np.minimum(gap, gap + np.einsum("pi,pi->p", u_j, g.normals))
        if not g.law_at_nodes:  # the law at the points
            return gap
        out = np.full(g.num_law_points, np.inf)
        nodes = np.asarray(g.mult_nodes)
        gaps = np.broadcast_to(gap[:, None], nodes.shape)
        on = nodes >= 0
        np.minimum.at(out, nodes[on], gaps[on])
        return out

    def names(self, scene):
        """(body i, body j or obstacle) names of each pair: the key of a pair across scenes."""
        return [
            (
                scene.bodies[g.pair[0]].name,
                g.obstacle.name if g.obstacle is not None else scene.bodies[g.pair[1]].name,
            )
            for g in self.pairs
        ]

    def set_load(self, lam):
        """Prescribed displacement of the obstacles at the closest points for the fraction lam
        of their step motion (u_j_prescribed of the kernel, eq 26)."""
        if lam == self._lam:
            return
        for g in self.pairs:
            if g.obstacle is not None:
                g.quadrature.u_j_prescribed = g.obstacle.step_displacement(g.p_j, lam)
        self._lam = lam

    def obstacle_resultants(self):
        """{obstacle name: (force (2,), moment)} exerted by the bodies on each obstacle in the
        last accepted state (`resultants.traction_resultant`); zeros without contact."""
        out = {ob.name: (np.zeros(2), 0.0) for ob in self.obstacles}
        for k, g in enumerate(self.pairs):
            s = self.committed[k]
            if g.obstacle is None or s is None:
                continue
            # on the obstacle (side j), its moment about the obstacle's current centre
            F, M = traction_resultant(g, s, "j", g.p_j, g.obstacle.current_center)
            F0, M0 = out[g.obstacle.name]
            out[g.obstacle.name] = (F0 + F, M0 + M)
        return out

    @property
    def augmented(self):
        return self.enforcement == "augmented"

    def _slip_read(self, k):
        """The slip the kernel reads: the committed one, shifted in the augmented loop so that
        tau_t,trial = lambda_t + (g_t - g_t,start) / eps_t (g_t,start = gtp_c + eps_t tau_c)."""
        gtp = np.asarray(self.history[k].committed)
        if not self.augmented:
            return gtp
        return gtp + self.eps_t * (self._committed_tractions(k)[1] - self.lambda_t[k])

    def _evaluate(self, k, u, b=None, A=None, fd=False, fd_step=1e-9, mu=None, closed_gap=0.0):
        mu = self.mu if mu is None else mu
        gtp = self._slip_read(k) if mu > 0 else _NONE
        shift = self.eps_n * self.lambda_n[k] if self.augmented else None
        return _cpp.assemble_contact(
            self.pairs[k].quadrature,
            self.eps_n,
            self.eps_t,
            mu,
            u,
            gtp,
            b,
            A,
            fd,
            fd_step,
            closed_gap,
            shift,
        )

    def assemble(self, u, b, A=None, fd=False, fd_step=1e-9, closed_gap=0.0, stick=False):
        """Add the contact residual of displacement array u to the array b (local, with
        ghosts) and, with A, the consistent tangent; keep the trial states. closed_gap: open
        points with g_n < closed_gap lend a closed point's tangent (the predictor, kernel).
        stick (with friction): every closed point sticks (residual and tangent of an infinite
        mu): the elastic predictor of the first iteration of a step, whose trial slip is the
        whole step's motion."""
        mu = 1e30 if stick and self.mu > 0 else None
        for k in range(len(self.pairs)):
            s = self._evaluate(k, u, b, A, fd, fd_step, mu=mu, closed_gap=closed_gap)
            self.last[k] = s
            if self.mu > 0:
                self.history[k].trial = s["gtp_trial"]

    def commit(self):
        if self.mu > 0:  # the step's plastic slip: the return mapping's, from the slip it read
            for k, h in enumerate(self.history):
                self.plastic[k] = self.plastic[k] + (np.asarray(h.trial) - self._slip_read(k))
        # Keep the accepted step's point states: re-evaluating them with the committed slip
        # would put the slipped points exactly on the cone, where stick/slip is a coin toss.
        self.committed = [dict(s) for s in self.last]
        if self.mu > 0:
            for h in self.history:
                h.commit()

    def restore(self):
        for h in self.history:
            h.restore()

    def set_committed_slip(self, k, gtp):
        """Pair k starts the step from the committed plastic slip `gtp` (one value per law
        point; the material-point transfer of a new step's points). This object is the one
        owner of the friction history: nothing else writes `history` or `slip_start`."""
        gtp = np.asarray(gtp, dtype=float)
        self.history[k].trial = gtp
        self.history[k].commit()
        self.slip_start[k] = gtp.copy()

    def set_start_tractions(self, k, tau_n, tau_t):
        """Pair k's multipliers start from these law-point tractions while it has no committed
        state (the material-point transfer of a new step's points; Multipliers.start_step)."""
        self.start_tractions[k] = (np.asarray(tau_n, float), np.asarray(tau_t, float))

    def elastic_slip(self, k):
        """The committed elastic tangential gap g_t - g_t^p of pair k's points (eq 31), for
        the transfer to the next step's points; None before a step is committed."""
        s = self.committed[k]
        if s is None:
            return None
        return np.asarray(s["g_t"] - self.history[k].committed, dtype=float)

    def set_friction(self, mu, u):
        """Change mu between stages. Switching friction on starts from zero tangential
        traction: the committed plastic slip is the current (law point) tangential gap."""
        mu = float(mu)
        if mu > 0 and self.mu == 0:
            self.friction_origin = (np.array(u, dtype=float), self._lam)
            for k, h in enumerate(self.history):
                g = self.pairs[k]
                h.trial = self._evaluate(k, u, mu=0.0)["law_g_t"]
                h.commit()
                self.lambda_t[k] = np.zeros(g.num_law_points)
                if self.committed[k] is not None:
                    self.committed[k]["law_tau_t"] = np.zeros(g.num_law_points)
                    self.committed[k]["tau_t"] = np.zeros(len(g.weights))
                self.slip_start[k] = h.committed
                self.plastic[k] = np.zeros(g.num_law_points)
        self.mu = mu

    def signature(self):
        """The active set (point states), to detect Newton cycling."""
        return tuple(s["law_state"].tobytes() for s in self.last if s is not None)

    def state_counts(self):
        states = (
            np.concatenate([s["law_state"] for s in self.last])
            if self.last
            else np.zeros(0, np.int8)
        )
        return np.bincount(states.astype(int), minlength=3)

    def points(self, u):
        """Per-point records of all pairs on this rank (reference configuration)."""
        out = []
        for k, g in enumerate(self.pairs):
            s = self.committed[k] if self.committed[k] is not None else self._evaluate(k, u)
            # plastic slip accumulated since friction was switched on (mu = 0: all of g_t);
            # augmented: the whole tangential gap (g_t = g_t^p + eps_t tau_t) since then, as
            # the converged stick is exact
            # traction "points": the plastic slip (the stick between the nodes is not exact)
            if self.mu > 0 and g.law_at_points_with_nodes:
                slip = self.plastic[k]
            elif self.mu > 0:
                slip = self.history[k].committed - self.slip_start[k]
                if self.augmented:
                    slip = slip + self.eps_t * s["law_tau_t"]
                slip = g.to_points(slip)
            else:
                slip = s["g_t"]
            out.append(
                dict(
                    x=g.points[:, 0],
                    y=g.points[:, 1],
                    w=g.weights,
                    normals=g.normals,
                    p_n=-s["tau_n"],
                    p_t=s["tau_t"],
                    gap_n=s["g_n"],
                    slip=slip,
                    state=s["state"],
                )
            )
        return out


def build_pairs(V, scene, band, rank, obstacles, kw, origins=None):
    """The pair geometries this rank holds (`geometry.pairs.pair_geometry`) and, for each, its
    index among the candidates (scene.pairs, then each obstacle with each body it may touch).
    rank: the rank that computes every pair, or {pair key: rank} (pair_key; others on 0).
    origins: {candidate index: lattice origin of its pair grid} (others: kw's)."""

    def owner(key):
        return rank.get(key, 0) if isinstance(rank, dict) else rank

    me = V.mesh.comm.rank
    candidates = [(tuple(pair), None) for pair in scene.pairs] + [
        ((i, -1), ob)
        for ob in obstacles
        for i, b in enumerate(scene.bodies)
        if ob.bodies is None or b.tag in np.atleast_1d(ob.bodies)
    ]
    mine = [(c, pair, ob) for c, (pair, ob) in enumerate(candidates)
            if owner(pair_key(pair, ob)) == me]  # fmt: skip

    def make(item):
        c, pair, ob = item
        at = {} if not origins or c not in origins else {"lattice_origin": origins[c]}
        return pair_geometry(V, scene, pair, band, obstacle=ob, **{**kw, **at})

    # the pairs are independent and their level-set work (contact_surface, the projections)
    # runs in C++ without the GIL: a rank's cores share them (`worker_threads`), in candidate
    # order, so the pairs and any error are the serial loop's
    threads = min(worker_threads(V.mesh.comm), len(mine) // PAIRS_PER_THREAD)
    if threads > 1:
        scene.body_cells(scene.bodies[0].tag)  # the scene's shared tables made once, here
        with ThreadPoolExecutor(threads) as pool:
            made = list(pool.map(make, mine))
    else:
        made = [make(item) for item in mine]
    pairs = [g for g in made if g is not None]
    index = [c for (c, _, _), g in zip(mine, made) if g is not None]
    return pairs, index
