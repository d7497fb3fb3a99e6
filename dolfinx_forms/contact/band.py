"""A contact set rebuilt over a wider band, its committed state carried over (issue 29, item 4).

`solvers.problem.ContactProblem.grow_band` doubles the band of a problem whose converged load
step has active points at the band's edge (an initial gap above 0.9 band: Gamma_c may cut the
contact zone off there) and does that step again from the committed state, with the wider
Gamma_c. The rebuilt pairs keep the old pair grids' lattices (`lattice_origins`): the level
sets then have the same node values where both grids reach, so Gamma_c is the same curve with
the same contact points wherever the old band covered it, bar the segments it clipped at its
edge. Each new law point (a contact point, or a multiplier node with traction "nodes") takes
the committed state of the old one at its place (`carry_state`):

* the same law point (within MATCH of the level-set spacing): its committed plastic slip, slip
  origin and accumulated plastic slip, and its committed tractions (the augmented Lagrangian's
  multipliers start each step from them) are copied: the step starts from the state a band
  that wide from the start would have reached, since every point the old band left out was
  open (no active point had come near its edge);
* any other (past the old band, or on a segment the old band clipped): a point open since
  friction was switched on (the open branch of Algorithm 1: its plastic slip follows the
  tangential gap, no traction), unless the nearest old law point within h was closed: then
  that point's elastic tangential gap e_t = g_t - g_t^p, its slip since friction was switched
  on and its tractions (as the MPM steps carry friction over, `mpm.records.transfer_friction`).

With multiplier nodes the nodes lie at equal arc lengths along each chain of Gamma_c, whose
length the band sets: the rebuilt nodes are not the old ones, and a law at the nodes
(traction "nodes") takes the nearest old node's state (the second case, within h), an answer
to the discretisation's accuracy: the band alone moves such an answer (Hertz at h = a/5,
bands 0.1 and 0.4 from the start: Fy by 1e-5 to 6e-3), and a band grown from 0.05 to 0.1
gives the 0.1 band's Fy to 5e-6 to 9e-5. The points' law (the penalty's, and the augmented
Lagrangian's default traction "points") carries its state point by point, exactly; the
augmented Lagrangian's answer is then the fixed point of the final band's nodes.
"""

import numpy as np

MATCH = 1e-6  # of the level-set spacing: the same law point in the old and the new set


def lattice_origins(cs):
    """{candidate index: the first node of that pair's level-set grid} of a contact set."""
    return {c: np.array(g.search_box[0], dtype=float) for c, g in zip(cs.index, cs.pairs)}


def law_positions(g):
    """Where pair geometry g's law points lie: its contact points, or (traction "nodes") its
    multiplier nodes' centres (the hat-weighted means of their points)."""
    if not g.law_at_nodes:
        return g.points
    return np.stack([g.project(g.points[:, c])[0] for c in range(2)], axis=1)


def carry_state(new, old, u, lam, h):
    """Set the committed state of the contact set `new`, a rebuild of `old` over a wider band,
    from old's (module doc), at the committed displacement array u and load level lam; h: the
    contact mesh size (how far a closed law point's state reaches)."""
    from scipy.spatial import cKDTree

    new.halvings, new.alignments = old.halvings, old.alignments
    new.friction_origin = old.friction_origin
    new.set_load(lam)
    friction = new.mu > 0
    g_t = [new._evaluate(k, u, mu=0.0)["law_g_t"] for k in range(len(new.pairs))]
    g_t0 = _origin_gaps(new, u, lam) if friction else g_t
    where = {c: k for k, c in enumerate(old.index)}
    for k, (c, g) in enumerate(zip(new.index, new.pairs)):
        n = g.num_law_points
        gtp, start = g_t[k].copy(), g_t0[k].copy()  # open since friction was switched on
        tn, tt = np.zeros(n), np.zeros(n)
        ko = where.get(c)
        s = None if ko is None else old.committed[ko]
        if s is not None:
            d, q = cKDTree(law_positions(old.pairs[ko])).query(law_positions(g))
            same = d <= MATCH * g.grid_spacing
            near = ~same & (d <= h) & (s["law_state"][q] > 0)
            gtp_o = np.asarray(old.history[ko].committed)
            if friction and len(gtp_o):
                gtp[same], start[same] = gtp_o[q[same]], old.slip_start[ko][q[same]]
                qn = q[near]  # the elastic gap, and the slip since friction on, carried over
                gtp[near] = g_t[k][near] - (s["law_g_t"][qn] - gtp_o[qn])
                start[near] = g_t[k][near] - (s["law_g_t"][qn] - old.slip_start[ko][qn])
            carried = same | near
            tn[carried], tt[carried] = s["law_tau_n"][q[carried]], s["law_tau_t"][q[carried]]
        new.history[k].trial = gtp
        new.history[k].commit()
        new.slip_start[k] = start
        plastic = gtp - start
        if s is not None and friction:
            plastic[same] = old.plastic[ko][q[same]]
            plastic[near] = old.plastic[ko][q[near]]
        new.plastic[k] = plastic
        new.lambda_n[k], new.lambda_t[k] = tn.copy(), tt.copy()
        if s is None:  # no step accepted yet, or a pair the old band did not reach
            continue
        new.committed[k] = {"law_tau_n": tn, "law_tau_t": tt}  # the slip the kernel reads
        e = dict(new._evaluate(k, u))
        e["law_tau_n"], e["law_tau_t"] = tn, tt
        at_points = g.interpolate if g.law_at_nodes else np.copy
        e["tau_n"], e["tau_t"] = at_points(tn), at_points(tt)
        new.committed[k], new.last[k] = e, dict(e)


def _origin_gaps(cs, u, lam):
    """The law points' tangential gaps where friction was switched on (zero: from the start)."""
    if cs.friction_origin is None:
        return [np.zeros(g.num_law_points) for g in cs.pairs]
    u0, lam0 = cs.friction_origin
    cs.set_load(0.0 if lam0 is None else lam0)  # None: switched on before any evaluation
    out = [cs._evaluate(k, u0, mu=0.0)["law_g_t"] for k in range(len(cs.pairs))]
    cs.set_load(lam)
    return out
