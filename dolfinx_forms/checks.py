"""Checks of a converged contact state that the code can make itself: never wrong with exit 0.

`contact_warnings(problem)` looks at every pair's committed points (on the ranks that hold
them) and returns, on every rank, one line per failed check:

* penetration: an active point's gap below -PENETRATION h (the penalty is too soft for the
  load: its answer then depends on eps0);
* band: an active point whose initial gap is within 10 % of the contact band (Gamma_c covers
  initial gaps up to the band only: the zone may be cut at its edge, give a larger band);
* checkerboard: open points whose two neighbours along a pair's contact surface are active,
  twice or more (more point-wise constraints than the trace can follow: a stiff point-wise
  penalty; the augmented enforcement's segments do not do this). Two separate contact spots
  of one pair (rough grains) are not flagged: one gap between them.

The demos put them in metrics.json (`solver.warnings`) and on the console.
"""

import numpy as np

PENETRATION = 0.1  # of h_contact


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
    a = active[np.argsort(g.points @ t, kind="stable")]
    holes = int(np.sum(~a[1:-1] & a[:-2] & a[2:]))
    if holes >= 2:
        out.append(
            f"{name}: {holes} open points between two active ones (a pressure checkerboard: "
            "point-wise penalty too stiff for the mesh; raise eps0, or --enforcement augmented)"
        )
    return out


def contact_warnings(problem):
    """All failed checks of the committed state, the same list on every rank."""
    cs = problem.contact
    names = cs.names(problem.scene)
    mine = []
    for k, (g, s) in enumerate(zip(cs.pairs, cs.committed)):
        if s is not None:
            mine += pair_warnings(g, s, problem.scene.h_contact, problem.band, "-".join(names[k]))
    return [w for part in problem.comm.allgather(mine) for w in part]
