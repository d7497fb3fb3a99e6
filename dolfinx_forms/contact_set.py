"""The contact set: every pair's contact points and their state, one owner of the history.

For each body pair (`contact.pair_geometry`, built once per scene in the reference
configuration) the C++ kernel of eq 48 gives, from the displacement, the gaps (eqs 26-31),
the return mapping (Algorithm 1) and the residual and consistent tangent. The plastic slip
g_t^p (eqs 10-12) lives in one `_cpp.FrictionHistory` per pair: the kernel reads its
committed values, each Newton iteration sets its trial values, an accepted step commits
them and a rejected one restores them exactly.
"""

import numpy as np

from . import _cpp
from .contact import pair_geometry

STATE_NAMES = {0: "open", 1: "stick", 2: "slip"}
_NONE = np.zeros(0)


class ContactSet:
    """Contact points of `scene.pairs` on rank `rank` (empty elsewhere), penalty eps_n, eps_t
    (eq 51) and friction coefficient mu (0: frictionless, no history)."""

    def __init__(self, V, scene, eps_n, eps_t, mu, band, grid_refine=4, num_gauss=2, rank=0):
        self.eps_n, self.eps_t, self.mu = float(eps_n), float(eps_t), float(mu)
        self.pairs = []
        if V.mesh.comm.rank == rank:
            for pair in scene.pairs:
                g = pair_geometry(
                    V, scene, pair, band, grid_refine=grid_refine, num_gauss=num_gauss
                )
                if g is not None:
                    self.pairs.append(g)
        self.history = [_cpp.FrictionHistory(len(g.weights), 1) for g in self.pairs]
        self.slip_start = [np.zeros(len(g.weights)) for g in self.pairs]
        self.last = [None] * len(self.pairs)  # kernel output of the last evaluation
        self.committed = [None] * len(self.pairs)  # point states of the last accepted step

    def __len__(self):
        return len(self.pairs)

    def insert_couplings(self, pattern):
        for g in self.pairs:
            _cpp.insert_coupling(pattern, g.quadrature)

    def add_zeros(self, A):
        for g in self.pairs:
            _cpp.add_coupling_zeros(A, g.quadrature)

    def _evaluate(self, k, u, b=None, A=None, fd=False, fd_step=1e-9, mu=None):
        mu = self.mu if mu is None else mu
        gtp = self.history[k].committed if mu > 0 else _NONE
        return _cpp.assemble_contact(
            self.pairs[k].quadrature, self.eps_n, self.eps_t, mu, u, gtp, b, A, fd, fd_step
        )

    def assemble(self, u, b, A=None, fd=False, fd_step=1e-9):
        """Add the contact residual of displacement array u to the array b (local, with
        ghosts) and, with A, the consistent tangent; keep the trial states."""
        for k in range(len(self.pairs)):
            s = self._evaluate(k, u, b, A, fd, fd_step)
            self.last[k] = s
            if self.mu > 0:
                self.history[k].trial = s["gtp_trial"]

    def commit(self):
        # Keep the accepted step's point states: re-evaluating them with the committed slip
        # would put the slipped points exactly on the cone, where stick/slip is a coin toss.
        self.committed = [dict(s) for s in self.last]
        if self.mu > 0:
            for h in self.history:
                h.commit()

    def restore(self):
        for h in self.history:
            h.restore()

    def set_friction(self, mu, u):
        """Change mu between stages. Switching friction on starts from zero tangential
        traction: the committed plastic slip is the current tangential gap."""
        mu = float(mu)
        if mu > 0 and self.mu == 0:
            for k, h in enumerate(self.history):
                h.trial = self._evaluate(k, u, mu=0.0)["g_t"]
                h.commit()
                self.slip_start[k] = h.committed
        self.mu = mu

    def signature(self):
        """The active set (point states), to detect Newton cycling."""
        return tuple(s["state"].tobytes() for s in self.last if s is not None)

    def state_counts(self):
        states = (
            np.concatenate([s["state"] for s in self.last]) if self.last else np.zeros(0, np.int8)
        )
        return np.bincount(states.astype(int), minlength=3)

    def points(self, u):
        """Per-point records of all pairs on this rank (reference configuration)."""
        out = []
        for k, g in enumerate(self.pairs):
            s = self.committed[k] if self.committed[k] is not None else self._evaluate(k, u)
            # plastic slip accumulated since friction was switched on (mu = 0: all of g_t)
            slip = self.history[k].committed - self.slip_start[k] if self.mu > 0 else s["g_t"]
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
