"""The resultant of a pair's contact tractions, the one routine every record uses (obstacle
forces for force control, the MPM step's pair and body forces).

At each contact point the traction on body i is tau_n n + tau_t t per unit length (n from
body i to body j; compression tau_n < 0), on body j its opposite (eqs 8-12 with the sign of
eq 37's contact term)."""

import numpy as np


def traction_vectors(g, state):
    """(n, 2): the traction tau_n n + tau_t t per unit length on body i at each contact point
    of pair geometry `g` (normals, tangents) in the kernel state `state` (tau_n, tau_t)."""
    return state["tau_n"][:, None] * g.normals + state["tau_t"][:, None] * g.tangents


def traction_resultant(g, state, side="i", points=None, centre=None):
    """(force (2,), moment) of the contact tractions of pair geometry `g` (weights, normals,
    tangents) in the kernel state `state` (tau_n, tau_t) on body `side` ("i" or "j"); the
    moment about `centre` with the tractions applied at `points` (default: zero moment)."""
    t = traction_vectors(g, state) * g.weights[:, None]
    if side == "j":
        t = -t
    force = np.array([t[:, 0].sum(), t[:, 1].sum()])  # column by column: the sums' order fixed
    if points is None or centre is None:
        return force, 0.0
    r = points - centre
    return force, float(np.sum(r[:, 0] * t[:, 1] - r[:, 1] * t[:, 0]))


def contact_resultant(problem):
    """[Fx, Fy]: the resultant of every pair's committed contact tractions on its second body
    (body j, or the obstacle), summed over the pairs and the ranks: the contact force as a
    vector (results.contact_force, sum w p_n, adds pressures along a curved zone)."""
    from mpi4py import MPI

    cs = problem.contact
    f = np.zeros(2)
    for g, s in zip(cs.pairs, cs.committed):
        if s is not None and len(g.weights):
            f += traction_resultant(g, s, "j")[0]
    return problem.comm.allreduce(f, op=MPI.SUM).tolist()
