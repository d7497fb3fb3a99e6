"""Contact geometry of a body pair on a body-fitted mesh, built once per scene.

Small strain: Gamma_c, the closest points and the cells that contain them are computed in
the reference configuration; Newton only changes u in the gaps (eqs 27-30). For each pair:

1. the pair's *search box*: the overlap of the two bodies' bounding boxes, each inflated by
   the contact band. Pairs whose inflated boxes do not overlap are never searched.
2. a structured grid on that box and each body's level set on it (`body_levelset`: the
   exact signed distance of the body's shape sampled at the nodes, or, for a body given by a
   grid level set, that level set's C1 interpolant there);
3. Gamma_c (eqs 21-24, `_cpp.contact_surface`) with Gauss points, normals n (body i -> j),
   tangents t;
4. closest points P_i, P_j (eq 25, `closest_points`: exact on a body's analytic shape, the
   iteration of eq 25 on the grid level set for a body without one), g_n0 = (P_j - P_i).n
   (eq 28, `_cpp.compute_gaps` in the reference configuration);
5. the mesh cells containing P_i and P_j (binned point location in C++; on a cut scene's
   structured grid, index arithmetic) and the basis values there (basix), packed into a
   `ContactQuadrature` for the C++ kernel (eq 48);
6. optionally (`multipliers`), the multiplier nodes along Gamma_c (`multiplier_nodes`): one
   traction per node, piecewise constant (P0) or linear (P1) along the contact surface's
   curves, about h apart: a pressure space the trace can carry. The quadrature is then of
   mortar type: Gamma_c's pieces are split where a closest point passes into another cell of
   its body (`label_breaks`, bisection) and at the multiplier elements' ends
   (`multiplier_breaks`), and cut where both bodies end (`beyond_end`), so that each piece
   integrates a smooth integrand (`_cpp.segment_quadrature`): the patch test is exact on
   non-matching meshes.
"""

import functools
import threading
from dataclasses import dataclass

import basix
import numpy as np

from dolfinx_forms import _cpp, defaults
from dolfinx_forms.geometry.obstacles import RigidObstacle


# where the law acts when the pair has multiplier nodes (`PairGeometry.traction`)
TRACTIONS = ("nodes", "points")
# the mass matrix of Uzawa's projection of point tractions on P1 multiplier nodes with
# traction "points" (`PairGeometry.node_multipliers`)
MULTIPLIER_MASSES = ("lumped", "consistent", "hybrid")
DEFAULT_MULTIPLIER_MASS = "hybrid"  # with the augmented Lagrangian (`solver.ContactProblem`)
# "hybrid": a node whose hat carries at least defaults.TUNING.hybrid_closed_fraction of its
# weight on closed points gets the consistent row, the others the lumped row


@dataclass
class PairGeometry:
    """Contact points of one body pair and what the kernel needs (see module doc)."""

    pair: tuple
    points: np.ndarray  # (nq, 2) on Gamma_c
    weights: np.ndarray  # (nq,)
    normals: np.ndarray  # (nq, 2) body i -> j
    tangents: np.ndarray  # (nq, 2) t = (-n_y, n_x)
    p_i: np.ndarray  # (nq, 2) closest points on body i
    p_j: np.ndarray  # (nq, 2)
    g_n0: np.ndarray  # (nq,)
    quadrature: object  # _cpp.ContactQuadrature
    grid_spacing: float
    search_box: np.ndarray  # (2, 2)
    obstacle: object = None  # obstacles.RigidObstacle on side j (no dofs), or None
    # (nq, 2) multiplier nodes of each point and their weights (`multiplier_nodes`), or None:
    # every point carries its own traction
    mult_nodes: np.ndarray = None
    mult_weights: np.ndarray = None
    # where the law acts with multiplier nodes: "nodes" (on their weighted mean gaps) or
    # "points" (at each point, the multipliers interpolated there: `pair_geometry`'s traction)
    traction: str = "nodes"
    # with traction "points": "lumped" (each node the hat-weighted mean of its points),
    # "consistent" (the L2 projection M^-1 int psi v) or "hybrid": `node_multipliers`
    multiplier_mass: str = "lumped"
    # "hybrid": the nodes whose rows the last projection made consistent, and the rows kept
    # (not chosen afresh) while set: `hybrid_projection`, `contact_set.ContactSet.freeze_rows`
    hybrid_rows: np.ndarray = None
    frozen_rows: np.ndarray = None
    # contact points left out because a closest point was not found (`_Sides.quadrature`):
    # one line each, reported by solvers.checks.pair_warnings
    dropped: list = None
    # the multiplier nodes' layout: (kind, length, `chain_positions` of the points), and the
    # contact zones {chain: [(sL, sR)]} their nodes are aligned with (`align_edges`), or None
    layout: tuple = None
    zones: dict = None

    @property
    def law_at_nodes(self):
        return self.mult_nodes is not None and self.traction == "nodes"

    @property
    def law_at_points_with_nodes(self):
        """Multiplier nodes that carry the multipliers while the law acts at the points."""
        return self.mult_nodes is not None and self.traction == "points"

    @property
    def num_law_points(self):
        return int(self.mult_nodes.max()) + 1 if self.law_at_nodes else len(self.weights)

    @property
    def num_nodes(self):
        return 0 if self.mult_nodes is None else int(self.mult_nodes.max()) + 1

    def interpolate(self, node_values):
        """Values at the multiplier nodes interpolated to the points."""
        v = np.asarray(node_values)[np.maximum(self.mult_nodes, 0)]
        return np.sum(np.where(self.mult_nodes >= 0, self.mult_weights * v, 0.0), axis=1)

    def project(self, point_values):
        """Point values projected on the multiplier nodes: their weighted means over each
        node's hat, sum_p w_p psi_p v_p / sum_p w_p psi_p (the lumped L2 projection), and those
        weights W (0 for none)."""
        wp = np.where(self.mult_nodes >= 0, self.weights[:, None] * self.mult_weights, 0.0)
        idx = np.maximum(self.mult_nodes, 0).ravel()
        W = np.bincount(idx, wp.ravel(), self.num_nodes)
        F = np.bincount(idx, (wp * np.asarray(point_values)[:, None]).ravel(), self.num_nodes)
        return F / np.maximum(W, 1e-300), W

    def _mass_entries(self):
        """The hats' consistent mass under the points' own quadrature as (rows, cols, values):
        int psi_a psi_b summed point by point."""
        psi = np.where(self.mult_nodes >= 0, self.mult_weights, 0.0)
        nodes = np.maximum(self.mult_nodes, 0)
        rows = np.repeat(nodes, 2, axis=1).ravel()  # (p, a, b) -> node a, node b
        cols = np.tile(nodes, (1, 2)).ravel()
        vals = (self.weights[:, None, None] * psi[:, :, None] * psi[:, None, :]).ravel()
        return rows, cols, vals

    def consistent_projection(self, point_values):
        """Point values L2-projected on the P1 multiplier nodes, M^-1 int psi v, with M the
        hats' consistent mass under the points' own quadrature (so a P1 field comes back
        exactly); M is factorised once per pair (`mass_solver`)."""
        if getattr(self, "_mass_lu", None) is None:
            self._mass_lu = mass_solver(*self._mass_entries(), np.zeros(self.num_nodes))
        mean, W = self.project(point_values)
        return self._mass_lu(mean * W)

    def hybrid_projection(self, point_values, closed):
        """Point values projected on the P1 multiplier nodes with one row per node: a node
        whose hat has at least defaults.TUNING.hybrid_closed_fraction of its weight on the closed
        points (`closed`, bool per point) the consistent row, (M lambda)_i = int psi_i v; any other
        node the lumped row (its hat-weighted mean). At Uzawa's fixed point the first have
        int psi_i g >= 0, zero when their hat is all in contact (the consistent projection's
        argument, row by row), and the second keep the lumped projection's edge: no L2 fit of
        the pressure's square-root edge, so no overshoot there. `frozen_rows` (set by
        `contact_set.ContactSet.freeze_rows`) fixes which rows are consistent: the projection
        is then linear, as the other two."""
        psi = np.where(self.mult_nodes >= 0, self.mult_weights, 0.0)
        nodes = np.maximum(self.mult_nodes, 0)
        mean, W = self.project(point_values)
        rows_c = self.frozen_rows
        if rows_c is None:
            Wc = np.bincount(
                nodes.ravel(), ((self.weights * closed)[:, None] * psi).ravel(), self.num_nodes
            )
            rows_c = (Wc >= (defaults.TUNING.hybrid_closed_fraction - 1e-12) * W) & (W > 0)
        self.hybrid_rows = rows_c
        key = rows_c.tobytes()
        if getattr(self, "_hybrid_key", None) != key:  # refactorised when the rows change
            rows, cols, vals = self._mass_entries()
            keep = rows_c[rows]
            lumped = np.where(rows_c, 0.0, np.where(W > 0, W, 1.0))
            solve = mass_solver(rows[keep], cols[keep], vals[keep], lumped)
            self._hybrid_key, self._hybrid_lu = key, solve
        return self._hybrid_lu(mean * W)

    def node_multipliers(self, point_values, closed=None):
        """Uzawa's projection of point tractions on the multiplier nodes (traction "points"):
        lumped, the fixed point has the weighted mean gap eps ((M_L - M) lambda)_i / W_i at a
        node in contact; consistent, zero (and >= 0 at every node, see `contact_set`); hybrid
        (`hybrid_projection`, closed: the closed points, bool), >= 0 at a node mostly in
        contact and zero when its hat is all in contact. Hybrid projects tangential tractions
        (closed None) lumped."""
        if self.multiplier_mass == "consistent":
            return self.consistent_projection(point_values)
        if self.multiplier_mass == "hybrid" and closed is not None:
            return self.hybrid_projection(point_values, np.asarray(closed, bool))
        return self.project(point_values)[0]

    def contact_zones(self, gap, min_length):
        """The contact zones along each chain of the multiplier nodes: {chain: [(sL, sR)]},
        the arc lengths where the (shifted) gap of the points, `gap`, crosses zero between an
        open and a closed point (None: the zone runs to the chain's end); zones shorter than
        min_length are left out."""
        c, s, _ = self.layout[2]
        zones = {}
        for q in np.unique(c):
            idx = np.flatnonzero(c == q)
            idx = idx[np.argsort(s[idx], kind="stable")]
            g, sq = gap[idx], s[idx]
            closed = g < 0
            if closed.all() or not closed.any():
                continue
            d = np.diff(closed.astype(np.int8))
            cross = lambda i: float(sq[i] + (sq[i + 1] - sq[i]) * g[i] / (g[i] - g[i + 1]))
            starts = [cross(i) for i in np.flatnonzero(d == 1)]
            ends = [cross(i) for i in np.flatnonzero(d == -1)]
            starts = ([None] if closed[0] else []) + starts
            ends = ends + ([None] if closed[-1] else [])
            zq = [
                (a, b)
                for a, b in zip(starts, ends)
                if (b if b is not None else sq[-1]) - (a if a is not None else sq[0]) >= min_length
            ]
            if zq:
                zones[int(q)] = zq
        return zones

    def align_edges(self, zones, offset):
        """Lay the P1 multiplier nodes out again, aligned with the contact zones `zones`
        (`contact_zones`; `multiplier_nodes`, `edge_aligned_ends`); the projection's cached
        factorisations and rows go with the old nodes."""
        kind, length, positions = self.layout
        self.mult_nodes, self.mult_weights = multiplier_nodes(
            None, kind, length, 0.0, positions, zones, offset
        )
        self.zones = zones
        self._mass_lu = self._hybrid_key = self._hybrid_lu = None
        self.hybrid_rows = self.frozen_rows = None

    def to_points(self, law_values):
        """Values at the law points (multiplier nodes or points) at the points."""
        return self.interpolate(law_values) if self.law_at_nodes else law_values


# multiplier nodes of a pair up to which its mass matrix is inverted densely by numpy (1000:
# ~50 ms once per pair); above, scipy's sparse LU, whose import costs 0.14 s here: more than the
# whole augmented loop of a cut Hertz run
DENSE_MASS_NODES = 1000


def mass_solver(rows, cols, vals, diag):
    """b -> A^-1 b for the n x n matrix A = sum of vals at (rows, cols) + diag(diag), n =
    len(diag): a mass matrix of P1 multiplier hats (tridiagonal along each chain, some rows
    lumped)."""
    n = len(diag)
    if n <= DENSE_MASS_NODES:
        A = np.bincount(rows * n + cols, vals, n * n).astype(float).reshape(n, n)
        A[np.diag_indices(n)] += diag
        inv = np.linalg.inv(A)
        return lambda b: inv @ b
    import scipy.sparse as sp
    import scipy.sparse.linalg as spl

    lu = spl.splu((sp.csc_matrix((vals, (rows, cols)), shape=(n, n)) + sp.diags(diag)).tocsc())
    return lu.solve


def surface_chains(pieces, tol):
    """The pieces (m, 2, 2) of a contact surface joined into chains at shared end points
    (within tol): a list of [(piece, reversed), ...] in order along each chain."""
    ends = np.unique(
        np.round(pieces.reshape(-1, 2) / tol).astype(np.int64), axis=0, return_inverse=True
    )[1].ravel()
    at = {}
    for k, e in enumerate(ends):
        at.setdefault(int(e), []).append(k)  # end k = 2 piece + side
    seen = np.zeros(len(pieces), bool)
    degree = np.array([len(at[int(e)]) for e in ends])
    chains = []
    # open chains first (from an end that no other piece shares), then closed loops
    for start in list(np.flatnonzero(degree == 1)) + list(range(len(ends))):
        piece = start // 2
        if seen[piece]:
            continue
        chain, rev = [], start % 2 == 1  # leave the start end behind
        while not seen[piece]:
            seen[piece] = True
            chain.append((piece, rev))
            far = 2 * piece + (0 if rev else 1)
            nxt = [k for k in at[int(ends[far])] if k // 2 != piece and not seen[k // 2]]
            if not nxt:
                break
            piece, rev = nxt[0] // 2, nxt[0] % 2 == 1
        chains.append(chain)
    return chains


def chain_arcs(pieces, tol):
    """Arc length along the chains of (m, 2, 2) `pieces` (`surface_chains`): per piece the arc
    length at its start, that start point (a piece may run against its chain), its chain, and
    the chains' lengths."""
    size = np.linalg.norm(pieces[:, 1] - pieces[:, 0], axis=1)
    arc, start = np.zeros(len(pieces)), np.zeros((len(pieces), 2))
    chain_of, lengths = np.zeros(len(pieces), np.int64), []
    for c, chain in enumerate(surface_chains(pieces, tol)):
        k = np.array([k for k, _ in chain], np.int64)
        rev = np.array([r for _, r in chain], bool)
        arc[k] = np.r_[0.0, np.cumsum(size[k])[:-1]]
        start[k] = np.where(rev[:, None], pieces[k, 1], pieces[k, 0])
        chain_of[k] = c
        lengths.append(size[k].sum())
    return arc, start, chain_of, np.array(lengths)


def multiplier_breaks(pieces, length, tol):
    """The ends of the multiplier elements of `multiplier_nodes` (each chain of arc length L in
    n = round(L / length) equal elements) that fall inside the (m, 2, 2) `pieces`: (piece,
    parameter t in (0, 1) from the piece's first end) pairs, for `split_segments`."""
    arc, start, chain_of, lengths = chain_arcs(pieces, tol)
    n_el = np.round(lengths / length).astype(np.int64)[chain_of]
    el = lengths[chain_of] / np.maximum(n_el, 1)  # element length of each piece's chain
    size = np.linalg.norm(pieces[:, 1] - pieces[:, 0], axis=1)
    first = np.floor((arc + tol) / el).astype(np.int64) + 1  # element ends strictly inside
    last = np.ceil((arc + size - tol) / el).astype(np.int64) - 1
    last = np.minimum(last, n_el - 1)  # no end past the chain's (nor any for one element)
    count = np.maximum(last - first + 1, 0)
    piece = np.repeat(np.arange(len(pieces)), count)
    j = first[piece] + np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    t = (j * el[piece] - arc[piece]) / size[piece]
    forward = np.linalg.norm(start - pieces[:, 0], axis=1) <= tol
    return piece, np.where(forward[piece], t, 1.0 - t)


def split_segments(pieces, cells, piece, t, tol):
    """(m, 2, 2) pieces (and their grid cells) cut at the parameters t of `piece`: the pieces
    in order, each split into its sub-pieces. Cuts closer than tol (a length) to an end or to
    the cut before are skipped: no sub-piece is shorter than tol (its ends would join no
    chain)."""
    m = len(pieces)
    step = tol / np.maximum(np.linalg.norm(pieces[:, 1] - pieces[:, 0], axis=1), 1e-300)
    order = np.lexsort((t, piece))
    piece, t = piece[order], t[order]
    keep = (t > step[piece]) & (t < 1.0 - step[piece])
    piece, t = piece[keep], t[keep]
    close = np.zeros(len(piece), bool)
    close[1:] = (piece[1:] == piece[:-1]) & (np.diff(t) <= step[piece[1:]])
    piece, t = piece[~close], t[~close]
    key = np.r_[np.arange(m), piece, np.arange(m)]
    ts = np.r_[np.zeros(m), t, np.ones(m)]
    order = np.lexsort((ts, key))
    key, ts = key[order], ts[order]
    pair = np.flatnonzero(key[1:] == key[:-1])  # consecutive parameters of one piece
    k, t0, t1 = key[pair], ts[pair], ts[pair + 1]
    a, b = pieces[k, 0], pieces[k, 1]
    # ends shared by two sub-pieces are one number (t1 of one is t0 of the next), the pieces'
    # own ends are kept bitwise: the chains join
    x0 = np.where((t0 == 0.0)[:, None], a, a + t0[:, None] * (b - a))
    x1 = np.where((t1 == 1.0)[:, None], b, a + t1[:, None] * (b - a))
    return np.stack([x0, x1], axis=1), cells[k].astype(np.int32)


def label_breaks(pieces, labels, tol, iterations=36, label=None, branching=8):
    """Where the integer labels of the points of the (m, 2, 2) `pieces` change along them
    (`labels(points)` -> (n, k), e.g. the cells that hold the closest points on each body):
    for each label that differs between a piece's ends, its first change, by a search that
    reads `branching` - 1 points of each bracket per round (a power of 2: rounds of log2 of it
    bisections, the same dyadic points; each read is a projection call whose cost is mostly
    its overhead) to 2^-iterations of the piece (below tol for pieces up to ~6 h /
    grid_refine long at tol = 1e-10 dx). Labels are read tol (a length, at least
    `split_segments`' shortest piece; above the closest points' own error, or that error reads
    as a change at every cut made) inside the ends, so a change closer to an end is ignored.
    One change per label and round: call it again on the split pieces for more.
    label(points, col) -> (n,): the label col[i] of points[i] alone (default: labels(points)
    read there), for a search that reads one label per point. Returns (piece, t) pairs for
    `split_segments`."""
    a, b = pieces[:, 0], pieces[:, 1]
    inset = np.minimum(tol / np.maximum(np.linalg.norm(b - a, axis=1), 1e-300), 0.25)[:, None]
    la, lb = labels(a + inset * (b - a)), labels(b - inset * (b - a))
    k, col = np.nonzero(la != lb)  # one search per (piece, label) that changes
    lo, hi = inset[k, 0], 1.0 - inset[k, 0]
    if label is None:

        def label(points, col):
            return labels(points)[np.arange(len(points)), col]

    levels = int(round(np.log2(branching)))
    j = np.arange(1, branching) / branching  # exact: dyadic fractions of the bracket
    for _ in range(-(-iterations // levels)):
        t = lo[:, None] + (hi - lo)[:, None] * j  # (n, branching - 1)
        x = a[k, None] + t[..., None] * (b[k] - a[k])[:, None]
        same = label(x.reshape(-1, 2), np.repeat(col, len(j))).reshape(t.shape)
        same = same == la[k, col][:, None]
        first = np.argmin(same, axis=1)  # the first point past the change (none: the end)
        first[same.all(axis=1)] = len(j)
        edges = np.column_stack([lo, t, hi])
        lo, hi = edges[np.arange(len(lo)), first], edges[np.arange(len(lo)), first + 1]
    return k, 0.5 * (lo + hi)


def beyond_end(points, closest, normals, tol):
    """True where a point of Gamma_c lies past the end of a body's face: the offset to its
    closest point runs more along Gamma_c than across it (`normals`: Gamma_c's). Inside the
    face's shadow the offset is the gap, across Gamma_c up to the angle between the bodies'
    normals; past a corner that ends the face it runs along Gamma_c."""
    d = np.asarray(points) - np.asarray(closest)
    across = np.abs(np.einsum("ij,ij->i", d, normals))
    along = np.abs(normals[:, 0] * d[:, 1] - normals[:, 1] * d[:, 0])
    return along > across + tol


def chain_positions(surface, tol):
    """Where the contact surface's points (`_cpp.contact_surface`'s dict) lie along the chains
    of its pieces (`surface_chains`): (chain of each point, its arc length from the chain's
    start, the chains' lengths)."""
    pieces = surface["segments"]
    used = np.unique(surface["segment"])
    local = np.searchsorted(used, surface["segment"])
    arc, start, chain_of, lengths = chain_arcs(pieces[used], tol)
    s = arc[local] + np.linalg.norm(surface["points"] - start[local], axis=1)
    return chain_of[local], s, lengths


def edge_aligned_ends(L, length, zones, offset):
    """The ends of the multiplier elements along a chain of arc length L whose contact zones
    are `zones` ([(sL, sR)], arc lengths of their edges, sorted; None: the zone reaches the
    chain's end there): over each zone n elements of equal length l (about `length`) placed so
    that the first node outside each edge lies `offset` l past it, and elements of about
    `length` between the zones and to the chain's ends (an element shorter than length / 4
    there is joined to its neighbour). Where an edge falls against the nodes sets the P1
    multipliers' error at the edge (Hertz at R = 40, a/40: p(x) 0.41-0.63 % as the edge moves
    through an element); with it fixed, the error is the same fraction of the edge's pressure
    at every h (docs/demos/convergence_study.md)."""
    short = 0.25 * length
    ends = [0.0]
    for sL, sR in zones:
        lo, hi = (0.0 if sL is None else sL), (L if sR is None else sR)
        k = (sL is not None) + (sR is not None)
        n = max(1, int(round((hi - lo) / length + k * offset)))
        el = (hi - lo) / max(n - k * offset, 0.5)
        z = (lo - (offset * el if sL is not None else 0.0)) + el * np.arange(n + 1)
        z = z[(z > ends[-1] + short) & (z < L - short)]
        if len(z) == 0:
            continue
        m = int(round((z[0] - ends[-1]) / length))
        ends += list(np.linspace(ends[-1], z[0], m + 1)[1:-1]) + list(z)
    m = max(1, int(round((L - ends[-1]) / length)))
    ends += list(np.linspace(ends[-1], L, m + 1)[1:])
    return np.array(ends)


def multiplier_nodes(surface, kind, length, tol, positions=None, zones=None, offset=0.0):
    """Multiplier nodes of the contact surface's points (`_cpp.contact_surface`'s dict, points
    filtered): along each chain of pieces (`surface_chains`), of arc length L, n = round(L /
    length) elements of equal length; "P0": one node per element (weight 1), "P1": the hat
    functions of the n + 1 element ends (weights 1 - theta, theta). A chain shorter than
    length / 2 gets one node. positions: `chain_positions` (computed if None). zones (P1):
    {chain: its contact zones} laid out by `edge_aligned_ends` with `offset` instead.
    Returns (nodes (nq, 2), weights (nq, 2)), -1 / 0 for none."""
    if kind not in ("P0", "P1"):
        raise ValueError(f"multipliers must be 'P0' or 'P1', got {kind!r}")
    c, s, lengths = chain_positions(surface, tol) if positions is None else positions
    n_el = np.round(lengths / length).astype(np.int64)
    aligned = {}
    for q, zq in (zones or {}).items():
        if kind == "P1" and n_el[q] > 0 and zq:
            aligned[q] = edge_aligned_ends(lengths[q], length, zq, offset)
            n_el[q] = len(aligned[q]) - 1
    n_nodes = np.where(n_el == 0, 1, n_el + (kind == "P1"))
    first = np.r_[0, np.cumsum(n_nodes)[:-1]]
    nodes = np.full((len(s), 2), -1, np.int32)
    weights = np.zeros((len(s), 2))
    t = s / np.where(n_el[c] > 0, lengths[c] / np.maximum(n_el[c], 1), 1.0)
    for q, E in aligned.items():  # t: the element and the fraction of it
        on = c == q
        k = np.searchsorted(E, s[on], side="right") - 1
        k = np.minimum(np.maximum(k, 0), len(E) - 2)
        t[on] = k + (s[on] - E[k]) / (E[k + 1] - E[k])
    # np.minimum/np.maximum: np.clip's own overhead (~10 us a call) adds up over the pairs
    e = np.minimum(np.maximum(np.floor(t), 0), np.maximum(n_el[c] - 1, 0)).astype(np.int64)
    theta = np.minimum(np.maximum(t - e, 0.0), 1.0)
    single = n_el[c] == 0
    nodes[:, 0] = first[c] + np.where(single, 0, e)
    weights[:, 0] = 1.0
    if kind == "P1":
        hat = ~single
        nodes[hat, 1] = nodes[hat, 0] + 1
        weights[hat, 0], weights[hat, 1] = 1.0 - theta[hat], theta[hat]
    # nodes that no point reaches with a positive weight (a chain end past the last point)
    # would carry no equation: renumber the others
    reached = np.zeros(int(n_nodes.sum()), bool)
    reached[nodes[weights > 0]] = True
    new = np.cumsum(reached) - 1
    weights[nodes >= 0] = np.where(reached[nodes[nodes >= 0]], weights[nodes >= 0], 0.0)
    nodes = np.where((nodes >= 0) & (weights > 0), new[np.maximum(nodes, 0)], -1).astype(np.int32)
    swap = nodes[:, 0] < 0  # the first node must exist
    nodes[swap] = nodes[swap][:, ::-1]
    weights[swap] = weights[swap][:, ::-1]
    return nodes, weights


def _bbox(body):
    return body.current_bbox if isinstance(body, RigidObstacle) else body.bbox


def search_box(body_i, body_j, band):
    """Overlap of the two bounding boxes inflated by `band`, or None if they are disjoint."""
    lo = np.maximum(_bbox(body_i)[0], _bbox(body_j)[0]) - band
    hi = np.minimum(_bbox(body_i)[1], _bbox(body_j)[1]) + band
    if np.any(lo >= hi):
        return None
    return np.array([lo, hi])


def near_box(box, body_i, body_j, band, step, dx):
    """The part of the search `box` where both bodies can come within `band` of each other: both
    level sets on a coarse grid of spacing `step`, the nodes where max(phi_i, phi_j) <= band
    + 2 * (cell diagonal) kept (a signed distance, or its lower bound for an intersection, is
    1-Lipschitz), their bounding box grown by 2 steps, within `box`, its corner on box[0] + dx
    Z^2 (the fine grid's nodes, hence Gamma_c, are the ones of the whole box). The fine grid of
    the pair then covers the contact and not the bodies' whole overlap (Hertz: |x| < 2 a of a
    20 R wide overlap). For bodies with exact shapes or obstacles only (a grid level set is
    known on its grid)."""
    n = np.maximum(np.ceil((box[1] - box[0]) / step).astype(int), 1)
    grid = _cpp.StructuredGrid(
        np.linspace(box[0, 0], box[1, 0], n[0] + 1), np.linspace(box[0, 1], box[1, 1], n[1] + 1)
    )
    nodes = grid.nodes()
    phi = [np.asarray(body_levelset(grid, b).values).reshape(-1) for b in (body_i, body_j)]
    near = np.maximum(*phi) <= band + 2 * np.hypot(*((box[1] - box[0]) / n))
    if not near.any():
        return box
    q = nodes[near]
    grow = 2 * (box[1] - box[0]) / n
    lo = np.maximum(q.min(axis=0) - grow, box[0])
    lo = box[0] + np.floor((lo - box[0]) / dx + 1e-9) * dx
    return np.array([lo, np.minimum(q.max(axis=0) + grow, box[1])])


def has_exact_shape(body):
    """True if the body's shape is an analytic signed distance (`_cpp.Shape`); False for a body
    given by a grid level set (`_cpp.LevelSet`), e.g. one built from a polyline or evolved."""
    return isinstance(body.shape, _cpp.Shape)


def body_levelset(grid, body):
    """The body's level set on `grid`: its exact shape sampled at the nodes, or, for a body given
    by a grid level set, that level set's C1 interpolant evaluated at the nodes (ValueError if
    its grid does not cover `grid`). A rigid obstacle gives its level set in its current pose."""
    if isinstance(body, RigidObstacle):
        return body.levelset(grid)
    if has_exact_shape(body):
        return _cpp.levelset_from_shape(grid, body.shape)
    if not isinstance(body.shape, _cpp.LevelSet):
        raise TypeError(
            f"body {body.name!r}: shape must be a Shape or a LevelSet, "
            f"got {type(body.shape).__name__}"
        )
    try:
        values, _ = body.shape.evaluate(grid.nodes())
    except IndexError as e:
        raise ValueError(
            f"body {body.name!r}: its level-set grid does not cover the contact "
            f"search box ({e})"
        ) from None
    return _cpp.LevelSet(grid, values)


def closest_points(body, phi, points, length_scale, exact=True):
    """Closest points on the boundary of `body` (eq 25) of (n, 2) `points`, as the dict of
    `_cpp.closest_point_projection`. With `exact` and an analytic shape: exact closest points
    on the shape (corners included); otherwise the iteration of eq 25 on the grid level set
    `phi` (the body's level set on the pair grid, `body_levelset`)."""
    if isinstance(body, RigidObstacle):
        return body.closest_points(points, length_scale, phi)
    if exact and has_exact_shape(body):
        return _cpp.closest_point_projection(body.shape, points, length_scale)
    r = _cpp.closest_point_projection(phi, points)
    slow = np.flatnonzero(r["status"] == int(_cpp.ProjectionStatus.max_iterations))
    if len(slow):
        # a point near the medial axis of a rough outline (in a grain's concave lobe) has two
        # near-closest points and the iteration may cycle between them: it gets 500 iterations
        # to 1e-8 h, and its last iterate is accepted if it lies on the contour (to 1e-8 h),
        # either candidate being a closest point to that accuracy (a rough grain in a column's
        # shear stopped a run on one such point)
        x = np.ascontiguousarray(points[slow])
        again = _cpp.closest_point_projection(phi, x, 1e-8, 500)
        f, g = phi.evaluate(again["points"])[:2]
        on = np.abs(f) <= 1e-8 * phi.grid.min_spacing * np.linalg.norm(g, axis=1)
        again["converged"] |= on & (again["status"] == int(_cpp.ProjectionStatus.max_iterations))
        for k in ("points", "status", "iterations", "converged"):
            r[k][slow] = again[k]
    return r


@functools.lru_cache(maxsize=None)
def _basix_element(cell_type, degree):
    cell = {"triangle": basix.CellType.triangle, "quadrilateral": basix.CellType.quadrilateral}[
        cell_type
    ]
    # Degree <= 2: every Lagrange variant has the same points, so this matches DOLFINx's element
    return basix.create_element(
        basix.ElementFamily.P, cell, degree, basix.LagrangeVariant.gll_warped
    )


class BodyLocator:
    """Point location restricted to one body's cells (C++ bins), with basis values. cells:
    the body's cells if known (`Scene.body_cells`), else found from cell_tags."""

    def __init__(self, mesh, cell_tags, tag, cell_type, degree, cells=None):
        x = mesh.geometry.x
        gdofs = mesh.geometry.dofmap.array.reshape(-1, 3 if cell_type == "triangle" else 4)
        cells = (cell_tags.find(tag) if cells is None else cells).astype(np.int32)
        self.locator = _cpp.CellLocator(x, gdofs.astype(np.int32), cells)
        self.element = _basix_element(cell_type, degree)

    def locate(self, points, max_distance):
        r = self.locator.locate(np.ascontiguousarray(points), max_distance)
        return r["cells"], r["X"], r["outside"]

    def cell_label(self, points, max_distance):
        """An integer per point that changes wherever its cell does (here: the cell)."""
        return self.locate(points, max_distance)[0]

    def basis(self, X):
        return self.element.tabulate(0, X)[0, :, :, 0]


_LOCATORS_LOCK = threading.Lock()


def grid_locator(scene, tag, degree=1, owned_only=False):
    """The GridLocator of body `tag` of a cut scene, made once per scene (the pairs of a body
    and the material-point update share it)."""
    key = (int(tag), int(degree), bool(owned_only))
    with _LOCATORS_LOCK:  # the pairs are made in threads (`contact_set.build_pairs`)
        cache = scene.__dict__.setdefault("_grid_locators", {})
        if key not in cache:
            cache[key] = GridLocator(
                scene.mesh, scene.cell_tags, tag, scene.cut, degree, owned_only=owned_only,
                cells=scene.body_cells(tag),
            )  # fmt: skip
        return cache[key]


class GridLocator:
    """Point location among one body's active cells of a cut scene's structured grid
    (`_cpp.GridCellLocator`: the grid index of a point by bisection on the tensor lines, looked
    up in a table over the body's cells, so the cost per point is O(1) in the number of cells
    and the memory the body's size). A point in an inactive grid cell (e.g. a closest point on
    the exact boundary where the straight cut misses a sliver) goes to the nearest active cell
    of the 3 x 3 neighbourhood, with extrapolated reference coordinates, if it is within
    max_distance of it. `locate` returns (cells, X, outside) like BodyLocator: outside = 0
    inside a cell, else the distance to it (inf, cell -1 and X NaN when nothing is within
    max_distance). cells: the body's cells if known (`Scene.body_cells`)."""

    def __init__(self, mesh, cell_tags, tag, cut, degree, owned_only=False, cells=None):
        self.xl, self.yl = np.asarray(cut.xlines), np.asarray(cut.ylines)
        g = mesh.geometry.dofmap.array.reshape(-1, 4)
        cells = (cell_tags.find(tag) if cells is None else cells).astype(np.int32)
        if owned_only:  # e.g. to take each point's value from one rank, partition-independently
            cells = cells[cells < mesh.topology.index_map(2).size_local]
        xv = np.ascontiguousarray(mesh.geometry.x[g[cells], :2])  # (n, 4, 2)
        self.locator = _cpp.GridCellLocator(self.xl, self.yl, xv, cells)
        self.element = _basix_element("quadrilateral", degree)

    def _index(self, p):
        i = np.searchsorted(self.xl, p[:, 0], side="right") - 1
        j = np.searchsorted(self.yl, p[:, 1], side="right") - 1
        i, j = np.maximum(i, 0), np.maximum(j, 0)  # np.clip: ~10 us of overhead a call
        return np.minimum(i, len(self.xl) - 2), np.minimum(j, len(self.yl) - 2)

    def cell_label(self, points, max_distance, inward=None):
        """An integer per point that changes wherever its cell does: its grid cell's index (a
        point in an inactive grid cell goes to a neighbour's cell, inside that grid cell).
        inward: (n, 2) directions into the body at the points (closest points on its boundary)."""
        # a closest point on a grid line (a block's face) goes to the cell on the body's side
        # of it whatever its round-off: a face along a line would otherwise change label at
        # every point. Into the body, not a fixed direction: a disc grazing a grid line (nine
        # discs, their 1e-3 overlap) crosses it at a tangent, where a shift of the line by the
        # tie moves the crossing by sqrt(R tie) along Gamma_c: down-left for every pair broke
        # the discs' mirror symmetry (the augmented Lagrangian's mortar pieces, split there, 6e-7
        # apart on mirrored pairs: forces 4e-5, stresses 9e-4 off D4). Without `inward`: down-left
        p = np.asarray(points, float)[:, :2]
        tie = 1e-9 * max(self.xl[-1] - self.xl[0], self.yl[-1] - self.yl[0])
        if inward is None:
            shift = -tie
        else:
            d = np.asarray(inward, float)[:, :2]
            shift = tie * d / np.maximum(np.linalg.norm(d, axis=1), 1e-300)[:, None]
        i, j = self._index(p + shift)
        return i * (len(self.yl) - 1) + j

    def locate(self, points, max_distance):
        p = np.ascontiguousarray(np.asarray(points, float)[:, :2])
        r = self.locator.locate(p, max_distance)
        return r["cells"], r["X"], r["outside"]

    def basis(self, X):
        return self.element.tabulate(0, X)[0, :, :, 0]


def pair_geometry(
    V,
    scene,
    pair,
    band,
    *,
    grid_refine=4,
    num_gauss=2,
    max_outside=None,
    projection="auto",
    obstacle=None,
    lattice_origin=None,
    multipliers=None,
    multiplier_length=None,
    traction="nodes",
    multiplier_mass="lumped",
):
    """Contact quadrature of `pair` (indices into scene.bodies), or of body pair[0] and the
    rigid `obstacle` (pair[1] ignored): side j then has no dofs (nodes_j = 0).
    lattice_origin: None (the pair grid starts at the search box's corner) or a point: the pair
    grid's nodes then lie on origin + (h / grid_refine) Z^2, the same lattice for every pair.

    band: largest initial gap covered by Gamma_c (eq 22 uses eps = band / 2), a length.
    grid_refine: level-set grid cells per mesh size h_contact.
    projection: "auto" (exact closest points on a body's analytic shape, eq 25 on the grid
    level set for a body without one) or "levelset" (eq 25 on the grid level sets for both).
    multipliers: None (a traction per point), "P0" or "P1": multiplier nodes along Gamma_c
    about multiplier_length (default h) apart (`multiplier_nodes`).
    traction (with multipliers): "nodes", the law acts on each node's weighted mean gap and the
    points carry the nodes' tractions interpolated; or "points", the law acts at each point
    and the nodes only carry the multipliers (`contact_set`: the augmented Lagrangian's
    P1 multipliers with a point-wise traction). multiplier_mass (traction "points"): "lumped",
    "consistent" or "hybrid", Uzawa's projection on the nodes (`PairGeometry.node_multipliers`).
    Returns None when the pair cannot touch (disjoint inflated boxes or empty Gamma_c).
    """
    if projection not in ("auto", "levelset"):
        raise ValueError(f"projection must be 'auto' or 'levelset', got {projection!r}")
    if traction not in TRACTIONS:
        raise ValueError(f"traction must be one of {TRACTIONS}, got {traction!r}")
    if multiplier_mass not in MULTIPLIER_MASSES:
        raise ValueError(
            f"multiplier_mass must be one of {MULTIPLIER_MASSES}, got {multiplier_mass!r}"
        )
    i, j = pair
    bi = scene.bodies[i]
    bj = scene.bodies[j] if obstacle is None else obstacle
    dx = scene.h_contact / grid_refine
    grid, box = pair_grid(bi, bj, band, dx, lattice_origin)
    if grid is None:
        return None
    phi_i, phi_j = body_levelset(grid, bi), body_levelset(grid, bj)
    s = _cpp.contact_surface(phi_i, phi_j, 0.5 * band, num_gauss)
    # Gamma_c through level-set grid nodes leaves zero-length segments: drop their points
    keep = s["weights"] > 1e-9 * dx
    s = {
        k: (v[keep] if isinstance(v, np.ndarray) and len(v) == len(keep) else v)
        for k, v in s.items()
    }
    if len(s["weights"]) == 0:
        return None
    sides = _Sides(V, scene, bi, bj, obstacle, phi_i, phi_j, projection, max_outside, dx)
    mult, positions, length = (None, None), None, None
    if multipliers is not None:
        length = scene.h_contact if multiplier_length is None else multiplier_length
        s = mortar_quadrature(s, sides, length, num_gauss)
        positions = chain_positions(s, 1e-10 * dx)
        mult = multiplier_nodes(s, multipliers, length, 1e-10 * dx, positions)
    # without multiplier nodes no other array refers to the points: a point whose closest
    # point is not found (an iterate leaving the pair grid, a degenerate gradient) is left
    # out and reported, not a failed step
    s, p_i, p_j, q = sides.quadrature(s, may_drop=multipliers is None)
    if len(s["weights"]) == 0:
        return None
    if mult[0] is not None and traction == "nodes":
        q.set_multiplier_nodes(*mult)
    geometry = PairGeometry(
        pair,
        s["points"],
        s["weights"],
        s["normals"],
        s["tangents"],
        p_i,
        p_j,
        sides.g_n0,
        q,
        dx,
        box,
        obstacle,
        *mult,
        traction,
        multiplier_mass,
    )
    geometry.dropped = sides.dropped
    geometry.layout = None if multipliers is None else (multipliers, length, positions)
    return geometry


def pair_grid(bi, bj, band, dx, lattice_origin=None):
    """(the pair's level-set grid of spacing dx over the search box, the box), or (None,
    None) when the bodies' inflated boxes are disjoint. A grid level set is known on its
    own grid only: the pair grid stays inside it (ValueError if it cannot cover the overlap)."""
    box = search_box(bi, bj, band + 4 * dx)
    if box is None:
        return None, None
    if all(isinstance(b, RigidObstacle) or has_exact_shape(b) for b in (bi, bj)):
        box = near_box(box, bi, bj, band + 4 * dx, 8 * dx, dx)
    if lattice_origin is not None:
        # nodes on the lattice origin + dx Z^2: the pair grids of mirror-image pairs are
        # mirror images (symmetric assemblies stay symmetric), whatever the boxes
        o = np.asarray(lattice_origin, float)
        box[0] = o + np.floor((box[0] - o) / dx + 1e-9) * dx
    n = np.maximum(np.ceil((box[1] - box[0]) / dx - 1e-9).astype(int), 3)
    hi = box[0] + n * dx  # keep the spacing exactly dx
    # the boxes' overlap before the band's inflation (touching boxes give a flat one)
    core = np.array(
        [np.maximum(_bbox(bi)[0], _bbox(bj)[0]), np.minimum(_bbox(bi)[1], _bbox(bj)[1])]
    )
    core = core if np.all(core[0] <= core[1]) else None
    for b in (bi, bj):  # a grid level set is known on its grid only: stay inside it
        if not isinstance(b, RigidObstacle) and isinstance(b.shape, _cpp.LevelSet):
            g = b.shape.grid
            glo, ghi = np.array([g.x[0], g.y[0]]), np.array([g.x[-1], g.y[-1]])
            tol = 1e-9 * np.max(ghi - glo)
            if core is not None and (np.any(core[0] < glo - tol) or np.any(core[1] > ghi + tol)):
                raise ValueError(
                    f"body {b.name!r}: its level-set grid {[glo.tolist(), ghi.tolist()]} does "
                    f"not cover the contact search box {core.tolist()}"
                )
            box[0] = np.maximum(box[0], glo)
            n = np.maximum(np.floor((np.minimum(hi, ghi) - box[0]) / dx).astype(int), 3)
            hi = np.minimum(box[0] + n * dx, ghi)
    grid = _cpp.StructuredGrid(
        np.linspace(box[0, 0], hi[0], n[0] + 1), np.linspace(box[0, 1], hi[1], n[1] + 1)
    )
    return grid, box


class _Sides:
    """The two sides of a pair on the DOLFINx mesh: closest points (eq 25), the cells that
    hold them, and the contact quadrature's dofs and bases (a rigid obstacle: no dofs)."""

    def __init__(self, V, scene, bi, bj, obstacle, phi_i, phi_j, projection, max_outside, dx):
        self.bodies, self.phi = (bi, bj), (phi_i, phi_j)
        self.h, self.dx, self.exact = scene.h_contact, dx, projection == "auto"
        self.max_outside = 0.5 * self.h if max_outside is None else max_outside
        self._phi_int = None
        self.dofmap = V.dofmap.list.array.reshape(-1, V.dofmap.dof_layout.num_dofs)
        degree, cut = V.ufl_element().degree(), getattr(scene, "cut", None)
        self.locators = [
            None  # rigid side: no dofs, its motion is prescribed (u_j_prescribed)
            if body is obstacle
            else (
                grid_locator(scene, body.tag, degree)
                if cut is not None  # structured grid: O(1) location by index
                else BodyLocator(
                    scene.mesh, scene.cell_tags, body.tag, scene.cell_type, degree,
                    cells=scene.body_cells(body.tag),
                )  # fmt: skip
            )
            for body in (bi, bj)
        ]

    @property
    def phi_int(self):
        """The intermediate level set (eq 23), made when the mortar splitting needs it."""
        if self._phi_int is None:
            self._phi_int = _cpp.intermediate_levelset(*self.phi)
        return self._phi_int

    def project_on(self, side, points, scale=None):
        return closest_points(
            self.bodies[side], self.phi[side], points, scale or self.h, exact=self.exact
        )

    def project(self, points, scale=None):
        return [self.project_on(side, points, scale) for side in (0, 1)]

    def cell_label(self, side, points, proj):
        loc = self.locators[side]
        if loc is None:
            return np.zeros(len(points), np.int32)
        if isinstance(loc, GridLocator) and hasattr(self.phi[side], "evaluate"):
            # into the body at its closest points: minus its level set's gradient
            return loc.cell_label(proj, self.max_outside, -self.phi[side].evaluate(proj)[1])
        return loc.cell_label(proj, self.max_outside)

    def past_both(self, points, proj):
        n = np.asarray(self.phi_int.evaluate(points)[1])
        n /= np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]
        tol = 1e-9 * self.dx
        return beyond_end(points, proj[0], n, tol) & beyond_end(points, proj[1], n, tol)

    def labels(self, points):
        """Per body the cell that holds the closest point; whether the point lies past the
        ends of both bodies (`beyond_end`)."""
        # exact shapes' gradients by differences of 1e-7 scale: fine enough near corners
        proj = [pr["points"] for pr in self.project(points, 1e-3 * self.h)]
        cells = [self.cell_label(side, points, p) for side, p in enumerate(proj)]
        return np.stack(cells + [self.past_both(points, proj)], axis=1)

    def label(self, points, col):
        """labels(points)[i, col[i]]: a cell label needs one body's closest point only."""
        out = np.empty(len(points), np.int64)
        for c in np.unique(col):
            at = np.flatnonzero(col == c)
            if c == 2:
                proj = [pr["points"] for pr in self.project(points[at], 1e-3 * self.h)]
                out[at] = self.past_both(points[at], proj)
            else:
                p = self.project_on(c, points[at], 1e-3 * self.h)["points"]
                out[at] = self.cell_label(c, points[at], p)
        return out

    def quadrature(self, s, may_drop=False):
        """(s, p_i, p_j, the ContactQuadrature) of the contact points of `s`: closest points
        (eq 25), initial gaps (eq 28), the dofs and bases at the closest points. A point whose
        closest point on a body is not found raises RuntimeError; with may_drop (no multiplier
        nodes refer to the points) it is left out instead and named in `self.dropped`
        (pair_warnings reports it), and s comes back without it."""
        proj = self.project(s["points"])
        failed = ~(proj[0]["converged"] & proj[1]["converged"])
        self.dropped = []
        for body, pr in zip(self.bodies, proj):
            for k in np.flatnonzero(~pr["converged"])[:1]:
                status = _cpp.ProjectionStatus(int(pr["status"][k])).name
                self.dropped.append(f"onto {body.name!r} at {s['points'][k]} ({status})")
        if failed.any() and not may_drop:
            raise RuntimeError(f"closest-point projection failed: {self.dropped[0]}")
        if failed.any():
            keep = ~failed
            self.dropped = [f"{int(failed.sum())} points left out: {'; '.join(self.dropped)}"]
            s = {k: (v[keep] if isinstance(v, np.ndarray) and len(v) == len(keep) else v)
                 for k, v in s.items()}  # fmt: skip
            proj = [{k: v[keep] for k, v in pr.items()} for pr in proj]
        p_i, p_j = proj[0]["points"], proj[1]["points"]
        normals, tangents = s["normals"], s["tangents"]
        zero = np.zeros_like(p_i)  # reference configuration: g_n = g_n0 (eq 28)
        self.g_n0 = _cpp.compute_gaps(p_i, p_j, zero, zero, normals, tangents)["g_n0"]
        sides = []
        for body, p, loc in zip(self.bodies, (p_i, p_j), self.locators):
            if loc is None:
                sides.append((np.zeros((len(p), 0), np.int32), np.zeros((len(p), 0))))
                continue
            cells, X, outside = loc.locate(p, self.max_outside)
            if np.any(cells < 0):
                bad = np.flatnonzero(cells < 0)[0]
                raise RuntimeError(
                    f"closest point {p[bad]} on body {body.name!r} is not within "
                    f"{self.max_outside:g} of any of its cells on this rank"
                )
            sides.append((self.dofmap[cells].astype(np.int32), loc.basis(X)))
        q = _cpp.ContactQuadrature(
            s["weights"], normals, tangents, self.g_n0, sides[0][0], sides[1][0], sides[0][1],
            sides[1][1],
        )  # fmt: skip
        return s, p_i, p_j, q


def mortar_quadrature(s, sides, length, num_gauss):
    """Mortar-type integration of Gamma_c (`s`, from contact_surface): its pieces split at
    the multiplier elements' ends (nodes `length` apart) and where a closest point moves into
    another cell of its body, so that each piece integrates a smooth integrand (a hat times
    the traces of both bodies' bases): the contact terms are then exact for a flat interface
    on non-matching meshes. Returns the new segment quadrature."""
    dx = sides.dx
    tol = 1e-10 * dx  # shortest piece; chain ends join within it
    used = np.unique(s["segment"])
    segs, cells = s["segments"][used], s["cells"][used]
    # a piece (h / grid_refine) rarely holds more than one change; after the first round
    # only the sub-pieces of the pieces just split can hold one (the others had none).
    # Those are read 1e-3 dx inside their ends: the labels' closest points on a curved
    # exact shape carry round-off up to ~1e-4 dx (gradients by differences of 1e-10 h; Hertz
    # cylinder at h = a/20), so a change just cut keeps reappearing within that of the cut
    # (pieces 1e-9 to 1e-4 dx long, of no weight, for all 6 rounds); a second change missed
    # that close to an end costs O((1e-3 dx / h)^2) of that piece's integral.
    check, inset = np.ones(len(segs), bool), 100 * tol
    for _ in range(6):
        piece, t = label_breaks(segs[check], sides.labels, inset, label=sides.label)
        inset = 1e-3 * dx
        if len(piece) == 0:
            break
        piece = np.flatnonzero(check)[piece]
        segs, parent = split_segments(segs, np.arange(len(segs)), piece, t, tol)
        cells, check = cells[parent], np.isin(parent, piece)
    # where both bodies end (the corners of two blocks), so does Gamma_c: the closing
    # level set's sign, which clipped it, is off by its reinitialisation error (~dx / 40)
    if len(segs):
        on = sides.labels(0.5 * (segs[:, 0] + segs[:, 1]))[:, 2] == 0
        segs, cells = segs[on], cells[on]
    segs, cells = split_segments(segs, cells, *multiplier_breaks(segs, length, tol), tol)
    return _cpp.segment_quadrature(sides.phi_int, segs, cells.astype(np.int32), num_gauss)
