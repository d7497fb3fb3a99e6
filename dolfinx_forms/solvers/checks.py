"""Checks of a converged contact state that the code can make itself: never wrong with exit 0.

`contact_warnings(problem)` looks at every pair's committed points (on the ranks that hold
them) and returns, on every rank, one line per failed check:

* penetration: an active point's gap below -PENETRATION h (the penalty is too soft for the
  load: its answer then depends on eps0);
* band: an active point whose initial gap is within 10 % of the contact band (Gamma_c covers
  initial gaps up to the band only: the zone may be cut at its edge, give a larger band). The
  single-step solver doubles the band and does the step again when that happens
  (`ContactProblem.grow_band`), so this fires where the band may not grow (band_growth 0),
  and its bound reached is an error (`band_errors`, first in the list);
* checkerboard: two or more runs of open points between active ones along a pair's contact
  surface, each shorter than h (more point-wise constraints than the trace can follow: a
  stiff point-wise penalty; the augmented enforcement's segments do not do this). Separate
  contact spots of one pair (rough grains) are further apart than h, or are one gap;
* resolution (multipliers): fewer than MIN_NODES multiplier nodes carry pressure (the zone
  spans fewer than ~5 multiplier elements) and some do not (the zone ends on Gamma_c; the
  cut patch test's 6 nodes, all loaded, are exact): the P1 multipliers, smeared over the hats that
  straddle the contact edges, then widen the zone and soften the contact. Hertz, augmented
  (penalty): a/2, 6 nodes body-fitted (4 cut), a +9.2 % (+2.7 %), p(x) 8.0 % (6.4 %); a/3, 8
  (6) nodes, a +6.3 % (+1.2 %), p(x) 4.3 % (5.9 %); a/4, 11 (7) nodes, a +3.8 %, p(x) 3.4 %
  (4.5 %). A column of discs (R = 10, h = 0.5, contacts ~0.7 h wide; tried in the multi-step
  MPM before it offered the augmented Lagrangian): half-widths 0.62-0.75 against the stiff penalty's
  0.33-0.35, the force 9-18 % low.

* unheld body: a rigid motion of a body (a translation, or the rotation about its centre) that
  the last tangent does not resist (no Dirichlet condition, closed contact or rigid-mode
  spring: e.g. a free block). The stiffness is singular: the linear solver returned one of
  many solutions (a free block came back "converged" in 5 Newton iterations, exit 0) and that
  motion means nothing. A frictionless block pressed on a flat face is not flagged: the
  contact surface's normals tilt at its corners and hold it weakly (3e-5 in this measure).

The demos put them in metrics.json (`solver.warnings`) and on the console, with the largest
penetration (`penetration`): point-wise, and as the law points' (with traction "points", the
multiplier nodes') weighted mean gap, which is what the augmented enforcement's multipliers
constrain (a mortar method's weak
non-penetration: its fixed point has zero mean gap at every active node, the point-wise gap
between nodes is the P1 trace's discretisation error).
"""

import numpy as np
from petsc4py import PETSc

PENETRATION = 0.1  # of h_contact
# |J r| / (|J|_inf |r|) of an unresisted rigid motion: round-off, ~1e-16 on a free block; a
# held one measured 1.8e-5 (Hertz block, clamped at its bottom) or more
RIGID_RTOL = 1e-9
MIN_NODES = 7  # multiplier nodes with pressure, below which a zone is under-resolved


def pair_warnings(g, s, h, band, name, augmented=False):
    """The warnings of one pair: g its `contact.PairGeometry`, s its committed kernel state,
    augmented: the enforcement is the augmented Lagrangian."""
    dropped = getattr(g, "dropped", None) or []  # a PairGeometry, or a stand-in in tests
    out = [f"{name}: closest-point projection failed, {d}" for d in dropped]
    active = s["state"] > 0
    if not active.any():
        return out
    pen = -s["g_n"][active].min()
    if pen > PENETRATION * h:
        out.append(f"{name}: penetration {pen:.3g} = {pen / h:.2g} h exceeds {PENETRATION} h "
                   + _penetration_cause(g, s, h, augmented))  # fmt: skip
    near = active & (g.g_n0 > 0.9 * band)
    if near.any():
        out.append(
            f"{name}: {int(near.sum())} active points have an initial gap within 10 % of the "
            f"band {band:.3g}: the contact zone may reach the edge of Gamma_c (give a larger band)"
        )
    # order along the pair's mean tangent (a contact surface per pair is a curve)
    t = np.mean(g.tangents, axis=0)
    t = t / max(np.linalg.norm(t), 1e-300)
    holes = short_gaps(g.points @ t, active, h)
    if holes >= 2:
        out.append(
            f"{name}: {holes} gaps shorter than h in the contact zone (a pressure checkerboard: "
            "more constraints than the mesh can follow; penalty: raise eps0 or use --enforcement "
            "augmented; augmented: a larger multiplier spacing)"
        )
    if g.num_nodes:
        carrying = int(np.sum(g.project(active.astype(float))[0] > 0))
        # a zone over every node has no edge for the hats to smear (a patch test's interface)
        if carrying < min(MIN_NODES, g.num_nodes):
            out.append(
                f"{name}: only {carrying} multiplier nodes carry the contact pressure (fewer "
                f"than {MIN_NODES}): the P1 multipliers widen the zone and soften the contact "
                "(use a finer h, or the penalty)"
            )
    return out


def node_penetration(g, s):
    """The largest penetration of the multiplier nodes that carry pressure, as their weighted
    mean gaps (traction "points": what the augmented multipliers constrain); 0 without one."""
    gbar, carrying = g.project(s["g_n"])[0], g.project(s["tau_n"])[0] < 0
    return max(-float(gbar[carrying].min()), 0.0) if np.any(carrying) else 0.0


def _penetration_cause(g, s, h, augmented):
    """Why the points penetrate: the penalty's compliance, or (the augmented Lagrangian's
    multiplier nodes, traction "points") the P1 trace between nodes whose weighted mean gaps,
    the quantity its multipliers constrain, are (nearly) closed: at a level-set corner or an
    edge singularity the pressure varies faster than the nodes can follow (block_compression
    at 30 %, augmented: 0.11-0.15 h at the platens' corners at h = 0.05 and 0.1, the nodes'
    gaps within 0.04 h)."""
    if not (augmented and getattr(g, "law_at_points_with_nodes", False)):
        return "(the penalty is too soft for this load: lower eps0, or --enforcement augmented)"
    node_pen = node_penetration(g, s)
    where = (
        f"at points between the multiplier nodes (their weighted mean gaps, which the augmented "
        f"Lagrangian constrains, at most {node_pen / h:.2g} h)"
    )
    if node_pen > PENETRATION * h:  # what the loop closes is open: not its fixed point
        return f"{where}: the augmented Lagrangian's constraint is not met"
    return (
        f"{where}: the P1 multipliers cannot follow the pressure there (a corner or an edge "
        "singularity; it shrinks with h)"
    )


def short_gaps(u, active, h):
    """Runs of inactive points between active ones, along the coordinate u, whose active
    neighbours are less than h apart."""
    order = np.argsort(u, kind="stable")
    u, a = u[order], active[order]
    idx = np.flatnonzero(a)
    if len(idx) < 2:
        return 0
    jumps = np.flatnonzero(np.diff(idx) > 1)  # idx[k] active, idx[k + 1] the next active
    return int(np.sum(u[idx[jumps + 1]] - u[idx[jumps]] < h))


def contact_warnings(problem):
    """All failed checks of the committed state, the same list on every rank."""
    cs = problem.contact
    names = cs.names(problem.scene)
    mine = []
    for k, (g, s) in enumerate(zip(cs.pairs, cs.committed)):
        if s is not None:
            mine += pair_warnings(
                g, s, problem.scene.h_contact, problem.band, "-".join(names[k]), cs.augmented
            )
    errors = list(getattr(problem, "band_errors", []))  # the band's growth bound reached
    parts = problem.comm.allgather(mine)
    return errors + [w for part in parts for w in part] + unheld_bodies(problem)


def unheld_bodies(problem):
    """One line per body with a rigid motion that nothing holds at the committed state (module
    doc), the same on every rank. The body's rigid motions r = R_k c (x and y translation,
    rotation about its centre) span a 3-dimensional space; the free ones are the null space of
    the Gram matrix G_k = (J R_k)^T (J R_k) in the metric M_k = R_k^T R_k, i.e. the c with
    |J R_k c| <= RIGID_RTOL |J| |R_k c| (`free_rigid_modes`). J is the last tangent (Dirichlet
    rows kept as identity rows, scaled to |J| here: a motion that moves a held dof is held;
    the contact tangent of the settled active set). A rank test,
    not a test of each mode alone: a body touching at one sliding point is free in x and in
    the rotation about that point, whichever of the singular system's solutions the linear
    solver returned. All bodies' motions are the columns of one sparse R and J R one product
    (a few nnz(J) flops: an MPM step of many grains pays it per step)."""
    from mpi4py import MPI

    if problem.rigid_mode_stiffness > 0:
        return []
    comm, J, bs, V = problem.comm, problem.J, problem.bs, problem.V
    n_own = V.dofmap.index_map.size_local
    X = V.tabulate_dof_coordinates()[:n_own, :2]
    dofmap = V.dofmap.list.array.reshape(-1, V.dofmap.dof_layout.num_dofs)
    bodies = problem.scene.bodies
    nb = len(bodies)
    body = np.full(n_own, -1)  # the body of each owned node (bodies are disjoint)
    for k, b in enumerate(bodies):
        nodes = np.unique(dofmap[problem.scene.body_cells(b.tag)])
        body[nodes[nodes < n_own]] = k
    held = body >= 0
    count = comm.allreduce(np.bincount(body[held], minlength=nb), op=MPI.SUM)
    sums = np.stack([np.bincount(body[held], X[held, a], nb) for a in range(2)], axis=1)
    centre = comm.allreduce(sums, op=MPI.SUM) / np.maximum(count, 1)[:, None]
    # R: a row per owned dof, the columns 3 k + (x, y, rotation) of its body k
    d = X - centre[np.maximum(body, 0)]
    vals = np.zeros((n_own, bs, 3))
    vals[:, 0, 0] = vals[:, 1, 1] = 1.0
    vals[:, 0, 2], vals[:, 1, 2] = -d[:, 1], d[:, 0]
    vals[~held] = 0.0
    cols = 3 * np.maximum(body, 0)[:, None, None] + np.arange(3)[None, None, :]
    cols = np.broadcast_to(cols, vals.shape).reshape(-1, 3).astype(PETSc.IntType)
    ptr = np.arange(0, 3 * n_own * bs + 1, 3, dtype=PETSc.IntType)
    R = PETSc.Mat().createAIJ(
        ((n_own * bs, None), (None, 3 * nb)),
        csr=(ptr, cols.ravel(), vals.reshape(-1, 3).ravel()),
        comm=comm,
    )
    JR = J.matMult(R)
    norm = J.norm(PETSc.NormType.INFINITY)
    jp, jc, jv = JR.getValuesCSR()
    # a Dirichlet row of J is an identity row: a motion that moves a held dof is held, at the
    # scale of the stiffness (a stiff penalty's |J| would otherwise hide the identity rows)
    held_row = np.zeros(len(jp) - 1, bool)
    held_row[np.asarray(problem.bc_owned, dtype=np.int64)] = True
    jv = np.where(np.repeat(held_row, np.diff(jp)), jv * norm, jv)
    A = reduce_rfactors(comm, body_rfactors(jp, jc, jv, nb))
    B = reduce_rfactors(comm, body_rfactors(ptr, cols.ravel(), vals.reshape(-1, 3).ravel(), nb))
    JR.destroy()
    R.destroy()
    out = []
    for k, b in enumerate(bodies):
        names = free_rigid_modes(A[k], B[k], norm, centre[k])
        if names:
            out.append(
                f"{b.name}: held by nothing in {', '.join(names)} (no Dirichlet condition or "
                "closed contact resists that rigid motion): the solve returned one of many "
                "solutions (hold it, or close its contacts)"
            )
    return out


def body_rfactors(ptr, cols, vals, num_bodies):
    """The triangular factors T_k (3 x 3) with T_k^T T_k = A_k^T A_k, A_k the columns 3 k ...
    3 k + 2 of a CSR matrix A (this rank's rows; column 3 k + m: body k, rigid mode m): a QR
    of each body's rows. |A_k c| = |T_k c| without squaring A's condition number (a Gram
    matrix would bury round-off-sized singular values, the free modes, under its round-off).
    Shape (num_bodies, 3, 3)."""
    row = np.repeat(np.arange(len(ptr) - 1), np.diff(ptr))
    key, inv = np.unique(row * num_bodies + cols // 3, return_inverse=True)
    # bincount: np.add.at's sums, in the same order, some 10x faster
    dense = np.bincount(3 * inv.ravel() + cols % 3, vals, 3 * len(key)).reshape(-1, 3)
    return stacked_rfactors(dense, key % num_bodies, num_bodies)


def stacked_rfactors(rows, body, num_bodies):
    """T_k of the rows (n, 3) of each body k = body[i] (one QR per body: a loop over bodies,
    not points)."""
    out = np.zeros((num_bodies, 3, 3))
    order = np.argsort(body, kind="stable")
    bounds = np.searchsorted(body[order], np.arange(num_bodies + 1))
    for k in range(num_bodies):
        block = rows[order[bounds[k] : bounds[k + 1]]]
        if len(block):
            r = np.linalg.qr(block, mode="r")
            out[k, : r.shape[0]] = r
    return out


def reduce_rfactors(comm, T):
    """The T_k of all ranks' rows from each rank's T_k: a QR of the stacked factors."""
    parts = comm.allgather(T)
    if len(parts) == 1:
        return T
    nb = T.shape[0]
    rows = np.concatenate([p.reshape(-1, 3) for p in parts])
    return stacked_rfactors(rows, np.tile(np.repeat(np.arange(nb), 3), len(parts)), nb)


def free_rigid_modes(A, B, norm, centre):
    """Names of the rigid motions c (x, y translation, rotation about `centre`) of one body
    with |J R c| <= RIGID_RTOL norm |R c|, from triangular factors with |J R c| = |A c| and
    |R c| = |B c| (`body_rfactors`). A basis of that null space, named without depending on
    which basis the SVD returns: the free translations ("x", "y", or a direction), then the
    free rotation, if any, by its centre (the point that rotation leaves still)."""
    if abs(np.linalg.det(B)) <= 1e-300:
        return []  # no dof of the body anywhere: nothing to say
    # c = B^-1 w whitens the modes: the singular values of A B^-1 are |J r| / |r|
    Bi = np.linalg.inv(B)
    _, sigma, Wt = np.linalg.svd(A @ Bi)
    N = Bi @ Wt[sigma <= RIGID_RTOL * norm].T  # the free c, columns
    d = N.shape[1]
    if d == 0:
        return []
    if d == 3:
        return ["x", "y", "rotation"]
    # translations in span(N): its vectors with no rotation component
    rot = N[2] / max(np.abs(N).max(), 1e-300)
    if np.all(np.abs(rot) <= 1e-6):
        T, c_rot = N[:2], None
    else:
        # move the rotation into one basis vector, the others then translate only
        j = int(np.argmax(np.abs(N[2])))
        c_rot = N[:, j] / N[2, j]
        T = np.delete(N - np.outer(c_rot, N[2]), j, axis=1)[:2]
    names = []
    if T.shape[1] == 2:
        names += ["x", "y"]
    elif T.shape[1] == 1:
        t = T[:, 0] / np.linalg.norm(T[:, 0])
        names.append(
            "x"
            if abs(t[1]) <= 1e-6
            else "y"
            if abs(t[0]) <= 1e-6
            else f"the translation along ({t[0]:.3g}, {t[1]:.3g})"
        )
    if c_rot is not None:
        if T.shape[1] == 1:  # the rotation's centre is set up to the free translation
            t = T[:, 0] / np.linalg.norm(T[:, 0])
            c_rot[:2] -= (c_rot[:2] @ t) * t
        # the motion (a - w dy, b + w dx) with w = 1 vanishes at centre + (-b, a)
        x0 = centre + np.array([-c_rot[1], c_rot[0]])
        names.append(f"the rotation about ({x0[0]:.4g}, {x0[1]:.4g})")
    return names


def penetration(problem):
    """Largest penetration over every pair's active points (`points`) and active law points
    (`law_points`: their weighted mean gaps), in units of h_contact; 0 without contact. The
    same on every rank."""
    from mpi4py import MPI

    pts = law = 0.0
    for g, s in zip(problem.contact.pairs, problem.contact.committed):
        if s is None:
            continue
        if np.any(s["state"] > 0):
            pts = max(pts, -float(s["g_n"][s["state"] > 0].min()))
        if g.law_at_points_with_nodes:
            law = max(law, node_penetration(g, s))
        elif np.any(s["law_state"] > 0):
            law = max(law, -float(s["law_g_n"][s["law_state"] > 0].min()))
    h = problem.scene.h_contact
    pts, law = (problem.comm.allreduce(max(v, 0.0), op=MPI.MAX) for v in (pts, law))
    return {"points": pts / h, "law_points": law / h}
