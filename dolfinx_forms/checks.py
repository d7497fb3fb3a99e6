"""Checks of a converged contact state that the code can make itself: never wrong with exit 0.

`contact_warnings(problem)` looks at every pair's committed points (on the ranks that hold
them) and returns, on every rank, one line per failed check:

* penetration: an active point's gap below -PENETRATION h (the penalty is too soft for the
  load: its answer then depends on eps0);
* band: an active point whose initial gap is within 10 % of the contact band (Gamma_c covers
  initial gaps up to the band only: the zone may be cut at its edge, give a larger band);
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
  MPM, which runs the penalty only): half-widths 0.62-0.75 against the stiff penalty's
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


def pair_warnings(g, s, h, band, name):
    """The warnings of one pair: g its `contact.PairGeometry`, s its committed kernel state."""
    out = []
    active = s["state"] > 0
    if not active.any():
        return out
    pen = -s["g_n"][active].min()
    if pen > PENETRATION * h:
        out.append(
            f"{name}: penetration {pen:.3g} = {pen / h:.2g} h exceeds {PENETRATION} h (the "
            "penalty is too soft for this load: lower eps0, or --enforcement augmented)"
        )
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
            mine += pair_warnings(g, s, problem.scene.h_contact, problem.band, "-".join(names[k]))
    return [w for part in problem.comm.allgather(mine) for w in part] + unheld_bodies(problem)


def unheld_bodies(problem):
    """One line per body with a rigid motion that nothing holds at the committed state (module
    doc), the same on every rank: r (x or y translation, rotation about the body's centre) on
    the body's dofs with |J r| <= RIGID_RTOL |J| |r|, J the last tangent (Dirichlet rows kept
    as identity rows, the contact tangent of the settled active set). All bodies' motions are
    the columns of one sparse R and J R one product (a few nnz(J) flops: an MPM step of many
    grains pays it per step)."""
    from mpi4py import MPI

    if problem.rigid_mode_stiffness > 0:
        return []
    comm, J, bs, V = problem.comm, problem.J, problem.bs, problem.V
    n_own = V.dofmap.index_map.size_local
    X = V.tabulate_dof_coordinates()[:n_own, :2]
    dofmap = V.dofmap.list.array.reshape(-1, V.dofmap.dof_layout.num_dofs)
    bodies = problem.scene.bodies
    body = np.full(n_own, -1)  # the body of each owned node (bodies are disjoint)
    for k, b in enumerate(bodies):
        nodes = np.unique(dofmap[problem.scene.cell_tags.find(b.tag)])
        body[nodes[nodes < n_own]] = k
    count = comm.allreduce(np.bincount(body[body >= 0], minlength=len(bodies)), op=MPI.SUM)
    sums = np.zeros((len(bodies), 2))
    np.add.at(sums, body[body >= 0], X[body >= 0])
    centre = comm.allreduce(sums, op=MPI.SUM) / np.maximum(count, 1)[:, None]
    # R: a row per owned dof, the columns 3 k + (x, y, rotation) of its body k
    held = body >= 0
    d = X - centre[np.maximum(body, 0)]
    vals = np.zeros((n_own, bs, 3))
    vals[:, 0, 0] = vals[:, 1, 1] = 1.0
    vals[:, 0, 2], vals[:, 1, 2] = -d[:, 1], d[:, 0]
    vals[~held] = 0.0
    cols = 3 * np.maximum(body, 0)[:, None, None] + np.arange(3)[None, None, :]
    cols = np.broadcast_to(cols, vals.shape).reshape(-1, 3).astype(PETSc.IntType)
    ptr = np.arange(0, 3 * n_own * bs + 1, 3, dtype=PETSc.IntType)
    R = PETSc.Mat().createAIJ(
        ((n_own * bs, None), (None, 3 * len(bodies))),
        csr=(ptr, cols.ravel(), vals.reshape(-1, 3).ravel()),
        comm=comm,
    )
    _, yj, yv = J.matMult(R).getValuesCSR()  # this rank's rows, global columns
    Jr2 = comm.allreduce(np.bincount(yj, yv**2, 3 * len(bodies)), op=MPI.SUM)
    r2 = comm.allreduce(np.bincount(cols.ravel(), vals.ravel() ** 2, 3 * len(bodies)), MPI.SUM)
    R.destroy()
    norm = J.norm(PETSc.NormType.INFINITY)
    free = (r2 > 0) & (np.sqrt(Jr2) <= RIGID_RTOL * norm * np.sqrt(r2))
    out = []
    for k, b in enumerate(bodies):
        names = [n for m, n in enumerate(("x", "y", "rotation")) if free[3 * k + m]]
        if names:
            out.append(
                f"{b.name}: held by nothing in {', '.join(names)} (no Dirichlet condition or "
                "closed contact resists that rigid motion): the solve returned one of many "
                "solutions (hold it, or close its contacts)"
            )
    return out


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
            # traction "points": the multiplier nodes carrying pressure, their mean gaps
            gbar, active = g.project(s["g_n"])[0], g.project(s["tau_n"])[0] < 0
            law = max(law, -float(gbar[active].min())) if np.any(active) else law
        elif np.any(s["law_state"] > 0):
            law = max(law, -float(s["law_g_n"][s["law_state"] > 0].min()))
    h = problem.scene.h_contact
    pts, law = (problem.comm.allreduce(max(v, 0.0), op=MPI.MAX) for v in (pts, law))
    return {"points": pts / h, "law_points": law / h}
