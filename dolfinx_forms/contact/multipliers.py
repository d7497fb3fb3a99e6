"""The augmented Lagrangian's multipliers of a contact set (seed 003's Uzawa loop, driven by
`solvers.newton.augmented_loop`): per pair and law point, lambda_n and lambda_t, started each
step from the committed tractions; their vector layout for the loop, the admissible set
(lambda_n <= 0, |lambda_t| <= mu |lambda_n|), and the tractions the loop updates them to.
`Multipliers` is the part of `contact_set.ContactSet` that owns them."""

import numpy as np

from dolfinx_forms import defaults


class Multipliers:
    """Mixin of ContactSet: needs its pairs, committed, start_tractions, last, mu, eps_t,
    eps_t_start, lambda_n and lambda_t."""

    def _committed_tractions(self, k):
        c = self.committed[k]
        if c is None and self.start_tractions[k] is not None:
            return self.start_tractions[k]
        zero = np.zeros(self.pairs[k].num_law_points)
        return (zero, zero) if c is None else (c["law_tau_n"], c["law_tau_t"])

    def start_step(self):
        """Multipliers of a new step (or a retried one): the committed tractions; eps_t its
        loop's first; the multiplier nodes equally spaced (`align_edges` aligns them with the
        step's own contact edges, so that a step's answer does not depend on the steps
        before: a band grown and the step done again gives the answer of the wider band)."""
        self.eps_t = self.eps_t_start
        for g in self.pairs:  # equally spaced nodes again: a step's layout has no history
            if g.zones:
                g.align_edges({}, 0.0)
        for k in range(len(self.pairs)):
            tn, tt = self._committed_tractions(k)
            self.lambda_n[k], self.lambda_t[k] = tn.copy(), tt.copy()

    def multipliers(self):
        """The multipliers of all pairs on this rank as one vector [lambda_n..., lambda_t...]
        (lambda_t only with friction)."""
        parts = self.lambda_n + (self.lambda_t if self.mu > 0 else [])
        return np.concatenate(parts) if parts else np.zeros(0)

    def set_multipliers(self, x):
        n = [g.num_law_points for g in self.pairs]
        cuts = np.cumsum(n)[:-1] if n else []
        self.lambda_n = [a.copy() for a in np.split(x[: sum(n)], cuts)]
        if self.mu > 0:
            self.lambda_t = [a.copy() for a in np.split(x[sum(n) :], cuts)]

    def admissible(self, x):
        """x (laid out as `multipliers`) projected on the admissible tractions: lambda_n <= 0,
        |lambda_t| <= mu |lambda_n| (an extrapolated update may leave them)."""
        n = sum(g.num_law_points for g in self.pairs)
        # with the consistent projection a fixed point has small tensile multipliers just past
        # the contact edge (the L2 fit of the pressure's edge; the law clips the traction):
        # clipping them at the points stalls the loop, so its pairs are left as they are (the
        # hybrid's consistent rows likewise)
        free = np.concatenate(
            [np.full(g.num_law_points, g.multiplier_mass != "lumped") for g in self.pairs]
            or [np.zeros(0, bool)]
        )
        x = x.copy()
        x[:n] = np.where(free, x[:n], np.minimum(x[:n], 0.0))
        if self.mu > 0:
            bound = self.mu * np.abs(x[:n])
            x[n:] = np.where(free, x[n:], np.clip(x[n:], -bound, bound))
        return x

    def freeze_rows(self, freeze=True):
        """multiplier_mass "hybrid": keep (True) which nodes have consistent rows, as the last
        projection chose them, or choose them afresh at every projection again (False). The
        Uzawa loop freezes them where it cycles (`newton.augmented_loop`): a row that switches
        as points open and close makes the update discontinuous, which can have no fixed
        point; frozen, the projection is linear."""
        for g in self.pairs:
            if g.multiplier_mass == "hybrid":
                g.frozen_rows = g.hybrid_rows if freeze else None

    def tractions(self):
        """The tractions of the last evaluation, laid out as `multipliers` (Uzawa's T); with
        traction "points" projected on the multiplier nodes and interpolated back."""

        def law(g, s, key):
            if not g.law_at_points_with_nodes:
                return s[key]
            closed = s["law_tau_n"] < 0 if key == "law_tau_n" else None  # hybrid: normal only
            return g.interpolate(g.node_multipliers(s[key], closed))

        keys = ["law_tau_n"] + (["law_tau_t"] if self.mu > 0 else [])
        parts = [law(g, s, key) for key in keys for g, s in zip(self.pairs, self.last)]
        return np.concatenate(parts) if parts else np.zeros(0)

    def align_edges(self):
        """Lay each pair's P1 multiplier nodes out again where its contact zones' edges moved by
        more than 0.1 node spacing from those the nodes are aligned with (`PairGeometry.
        contact_zones`, `align_edges`: the first node outside an edge defaults.TUNING.
        edge_offset elements past it). The zones are those of the last evaluation, its edges
        where the shifted gap g_n + eps_n lambda_h changes sign. Returns whether any pair's
        nodes changed (on this rank)."""
        changed = False
        for k, g in enumerate(self.pairs):
            s = self.last[k]
            if s is None or not g.law_at_points_with_nodes or g.layout[0] != "P1":
                continue
            length = g.layout[1]
            zones = g.contact_zones(s["law_g_n"] + self.eps_n * self.lambda_n[k], 2.0 * length)
            if not _moved(zones, g.zones or {}, 0.1 * length):
                continue
            g.align_edges(zones, defaults.TUNING.edge_offset)
            changed = True
        return changed


def _moved(new, old, tol):
    """Whether two {chain: [(sL, sR)]} zone sets differ (an edge by more than tol)."""
    if new.keys() != old.keys() or any(len(new[q]) != len(old[q]) for q in new):
        return True
    for q in new:
        for a, b in zip(new[q], old[q]):
            for x, y in zip(a, b):
                if (x is None) != (y is None) or (x is not None and abs(x - y) > tol):
                    return True
    return False
