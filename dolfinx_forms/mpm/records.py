"""What an implicit MPM step records and hands to the next one, from its converged state
(ImplicitMPM.step): the contact record (pair resultants, zones, stick fractions; the bodies'
contact forces and moments; the obstacles' forces), the supports' reactions, and the friction
history carried to the next step's contact points (the contact set owns the history; this
only finds, for each new point, the old point it continues)."""

import numpy as np
from mpi4py import MPI

from dolfinx_forms.common import allreduce_array
from dolfinx_forms.contact.resultants import traction_resultant
from dolfinx_forms.solvers.problem import zone_ends


def support_forces(sim, problem, scene):
    """{body: [fx, fy]} exerted on each body by its Dirichlet conditions: the residual
    (internal - external + contact forces) summed over the body's prescribed dofs."""
    out = {}
    if not problem.dirichlet:
        return {b.name: [0.0, 0.0] for b in sim.bodies}
    problem.residual(1.0, zero_bc=False)
    R = problem.R.array.reshape(-1, 2)
    owned = problem.n_owned
    bc = np.zeros(owned, bool)
    bc[problem.bc_owned] = True
    cell_dofs = problem.V.dofmap.list.array.reshape(-1, 4)
    for b in sim.bodies:
        nodes = np.unique(cell_dofs[scene.body_cells(b.tag)])
        nodes = nodes[2 * nodes + 1 < owned]
        f = np.zeros(2)
        for c in range(2):
            sel = bc[2 * nodes + c]
            f[c] = R[nodes[sel], c].sum()
        out[b.name] = allreduce_array(sim.comm, f, MPI.SUM).tolist()
    return out


def transfer_friction(sim, problem, keys):
    """Each new contact point starts from the state of the nearest contact point of the same
    pair in the previous step if one lies within h (else from zero): its elastic tangential
    gap e_t = g_t - g_t^p (the committed slip is set to -e_t, so the trial traction at du = 0
    is the old one, eq 11) and, with the augmented Lagrangian, its tractions, where the step's
    multipliers start (the Uzawa loop then needs few updates)."""
    cs = problem.contact
    if cs.mu == 0 and not cs.augmented:
        return
    from scipy.spatial import cKDTree

    for k, g in enumerate(cs.pairs):
        old = sim.friction.get(keys[k])
        n = len(g.weights)
        if g.num_law_points != n:  # the law at multiplier nodes: no point-wise record
            continue
        gtp, tn, tt = np.zeros(n), np.zeros(n), np.zeros(n)
        if old is not None and len(old[0]):
            d, idx = cKDTree(old[0]).query(g.points)
            near = d <= sim.h
            gtp[near] = -old[1][idx[near]]
            tn[near], tt[near] = old[2][idx[near]], old[3][idx[near]]
        if cs.mu > 0:
            cs.set_committed_slip(k, gtp)
        if cs.augmented:
            cs.set_start_tractions(k, tn, tt)


def friction_record(problem, keys):
    """{pair key: (points, elastic tangential gap, tau_n, tau_t)} of the converged step, on
    every rank: what the next step's points start from (`transfer_friction`)."""
    cs, out = problem.contact, {}
    for k, g in enumerate(cs.pairs):
        s = cs.committed[k]
        if (cs.mu > 0 or cs.augmented) and s is not None and g.num_law_points == len(g.weights):
            slip = cs.elastic_slip(k) if cs.mu > 0 else np.zeros(len(g.weights))
            out[keys[k]] = (g.points.copy(), slip, s["law_tau_n"], s["law_tau_t"])
    return {k: v for d in problem.comm.allgather(out) for k, v in d.items()}


def contact_record(sim, problem, scene, keys):
    """Per pair: resultants, active zone, stick fraction; per obstacle: force and moment;
    the friction record for the next step (points moved by the mean step displacement)."""
    cs = problem.contact
    pairs = []
    for k, g in enumerate(cs.pairs):
        s = cs.committed[k]
        active = s["state"] != 0
        w = g.weights
        pn, pt = -s["tau_n"], s["tau_t"]
        wa = w[active]
        f = traction_resultant(g, s, "j")[0]  # on body j (the obstacle) from body i
        pairs.append(
            dict(
                fx=float(f[0]),
                fy=float(f[1]),
                body_i=keys[k][0],
                body_j=keys[k][1],
                x=float(np.average(g.points[active, 0], weights=wa)) if active.any() else 0.0,
                y=float(np.average(g.points[active, 1], weights=wa)) if active.any() else 0.0,
                normal_force=float(np.sum(w * pn)),
                tangential_force=float(np.sum(w * pt)),
                active_length=float(np.sum(wa)),
                stick_fraction=float(np.sum(w[s["state"] == 1]) / np.sum(wa))
                if active.any()
                else 0.0,
                half_width=half_width(g, s),
                num_points=int(len(w)),
            )
        )
    sim.friction = friction_record(problem, keys)
    # each pair lives on one rank: share the records, in the order of one rank
    gathered = sim.comm.allgather(list(zip(cs.index, pairs)))
    pairs = [p for _, p in sorted((q for lst in gathered for q in lst), key=lambda q: q[0])]
    # contact resultants on each body: +sum w (tau_n n + tau_t t) on side i, the opposite on
    # side j; moment about the body's material-point centroid
    forces = {b.name: np.zeros(3) for b in sim.bodies}
    tags, centroids = {b.name: b.tag for b in sim.bodies}, {}
    for k, g in enumerate(cs.pairs):
        s = cs.committed[k]
        for side, name, p in (("i", keys[k][0], g.p_i), ("j", keys[k][1], g.p_j)):
            if name in forces:
                if name not in centroids:  # once per body, not per pair
                    pts = sim.points[tags[name]]
                    centroids[name] = np.average(pts.x, axis=0, weights=pts.vol)
                F, M = traction_resultant(g, s, side, p, centroids[name])
                forces[name] += np.array([F[0], F[1], M])
    total = allreduce_array(sim.comm, np.array(list(forces.values())).reshape(-1, 3), MPI.SUM)
    body_forces = dict(zip(forces, total.tolist()))  # one reduction for all bodies
    obstacles = obstacle_forces(problem, sim.obstacles)
    return dict(pairs=pairs, obstacles=obstacles, body_forces=body_forces)


def half_width(g, s):
    """Half the extent in x of the active contact zone of pair geometry g in state s."""
    order = np.argsort(g.points[:, 0])
    xl, xr = zone_ends(g.points[order, 0], (s["state"] != 0)[order], s["g_n"][order])
    return 0.0 if xl is None else 0.5 * (xr - xl)


def obstacle_forces(problem, obstacles):
    """{obstacle name: dict(fx, fy, moment)} exerted on each obstacle (all ranks)."""
    res, out = problem.contact.obstacle_resultants(), {}
    for ob in obstacles:
        F, M = res[ob.name]
        F = allreduce_array(problem.comm, np.asarray(F, float), MPI.SUM)
        out[ob.name] = dict(
            fx=float(F[0]), fy=float(F[1]), moment=problem.comm.allreduce(M, op=MPI.SUM)
        )
    return out


def penetrations(sim):
    """The deepest material point of each body inside another body or inside a rigid obstacle
    it meets: {body name: (depth, the other's name)}, depth = -phi_other at the point (> 0:
    inside; bodies with no point inside are left out). The contact acts on the level sets'
    contours, not on the points: a point past the other's surface is material the level set no
    longer bounds (a corner rounded by the grid, a drifted level set). Candidates only: the
    points inside the other's box (an obstacle's current box, a body's material box from
    `body_boxes`) of the broad phase's pairs; the points are on every rank, so is this."""
    out = {}
    # per body its points' coordinates as contiguous columns and their extent, tested first:
    # 100 grains make ~900 box tests a step, 60-100 ms as (n, 2) masks, ~25 ms so
    cols = {b.tag: (np.ascontiguousarray(sim.points[b.tag].x[:, :2].T)) for b in sim.bodies}
    spans = {t: (c.min(axis=1), c.max(axis=1)) for t, c in cols.items() if c.shape[1]}

    def test(body, box, phi, other):
        if body.tag not in spans:
            return
        lo, hi = spans[body.tag]
        if np.any(lo > box[1]) or np.any(hi < box[0]):
            return
        (x, y), (x0, y0), (x1, y1) = cols[body.tag], box[0], box[1]
        at = np.flatnonzero((x >= x0) & (x <= x1) & (y >= y0) & (y <= y1))
        if len(at):
            depth = -float(np.min(phi(np.ascontiguousarray(np.stack([x[at], y[at]], 1)))))
            if depth > out.get(body.name, (0.0, None))[0]:
                out[body.name] = (depth, other)

    for ob in sim.obstacles:
        box = ob.current_bbox
        for b in sim.bodies:
            if ob.bodies is None or b.tag in np.atleast_1d(ob.bodies):
                test(b, box, ob.values, ob.name)
    boxes = sim.body_boxes() if len(sim.bodies) > 1 else None
    pairs = sim.candidate_pairs(boxes) if boxes is not None else []
    for i, j in pairs:
        for a, c in ((i, j), (j, i)):
            # the other's material box lies inside its level set's window (its grid)
            phi = sim.levelsets[sim.bodies[c].tag]
            test(sim.bodies[a], boxes[c], lambda x: np.asarray(phi.evaluate(x)[0]),
                 sim.bodies[c].name)  # fmt: skip
    return out
