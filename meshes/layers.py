"""Body-fitted triangle meshes from nested layers around a contact point, without a mesher.

A body touching at a point O of its boundary (a block under an indenter, a half-disc or
half-ellipse on its lowest point) is covered by nested U-shaped layers around O. Layer k is
the polyline of four straight sides through five points

    Q0 (on the body's boundary) -> Q1 (corner) -> Q2 (middle) -> Q3 (corner) -> Q4 (boundary),

e.g. for the block [-W, W] x [-D, 0] and O = (0, 0) the U of the box [-X_k, X_k] x [-Y_k, 0]
(Q0 = (-X_k, 0), Q1 = (-X_k, -Y_k), Q2 = (0, -Y_k), ...), the last layer the block's own
outline; layer 0 is O itself. Each side is divided uniformly at about the layer's spacing, and
the strip between side j of layer k and side j of layer k + 1 (two parallel segments) is
triangulated by zipping their nodes in order along the side: any such merge of two parallel
rows is a valid triangulation, and where the rows hold the same positions (the uniform layers
near O) the triangles are the halves of a square grid's cells. The nodes Q0 and Q4 of every
layer lie on the body's boundary, exactly on its curve. A layout symmetric about the vertical
line through O gives a mirror-symmetric mesh (the tie rule below).

Why: meshing the Hertz scene with gmsh costs 0.3-0.5 s (loading libgmsh and its ~90
dependencies, then Frontal-Delaunay), more than the contact solve at a/20; these layers take
milliseconds. gmsh stays the mesher of general shapes.
"""

from __future__ import annotations

import numpy as np

__all__ = ["zip_strips", "layer_nodes", "layer_mesh"]

TIE = 1e-10  # positions along a strip within this fraction of the mesh's extent are equal


def zip_strips(x, a_start, a_count, b_start, b_count, direction, a_first):
    """Triangles (m, 3) filling strips between two rows of nodes.

    Strip p joins the rows a = x[a_start[p]:a_start[p] + a_count[p]] and b (likewise), each
    ordered along the unit vector direction[p]. The rows' segments are merged by the positions
    of their middles along direction[p]: a step along row a from a_i to a_i+1 makes the
    triangle (a_i, a_i+1, b_j), one along b (b_j, b_j+1, a_i). Equal positions (to TIE) step
    row a first where a_first[p], else b.
    Triangles are counter-clockwise; a strip of two single nodes has none."""
    a_start, b_start = np.asarray(a_start, np.int64), np.asarray(b_start, np.int64)
    a_count, b_count = np.asarray(a_count, np.int64), np.asarray(b_count, np.int64)
    na, nb = a_count - 1, b_count - 1  # events: every node of a row but its first
    strips = np.arange(len(a_start))

    def events(start, n):
        strip = np.repeat(strips, n)
        first_event = np.repeat(np.cumsum(n) - n, n)
        return strip, start[strip] + 1 + np.arange(n.sum()) - first_event

    sa, node_a = events(a_start, na)
    sb, node_b = events(b_start, nb)
    strip = np.concatenate([sa, sb])
    node = np.concatenate([node_a, node_b])
    on_b = np.concatenate([np.zeros(len(sa), bool), np.ones(len(sb), bool)])
    # the step's key: the middle of the segment it crosses (a merge by the nodes themselves
    # would not give the same triangles run backwards, so no mirror symmetry)
    d = np.asarray(direction, float)[strip]
    pos = np.einsum("ij,ij->i", x[node] + x[node - 1], d)
    # positions equal to round-off are a tie (the rows' nodes are computed apart)
    scale = max(np.ptp(x[:, 0]), np.ptp(x[:, 1])) if len(x) else 1.0
    pos = np.rint(pos / (TIE * scale))
    later = on_b == np.asarray(a_first, bool)[strip]  # the row that steps second on a tie
    order = np.lexsort((later, pos, strip))
    strip, node, on_b = strip[order], node[order], on_b[order]
    first = np.searchsorted(strip, strips)
    done_b = np.cumsum(on_b) - on_b  # steps along b before each event, then within its strip
    done_b -= done_b[first][strip]
    done_a = np.arange(len(strip)) - first[strip] - done_b
    cur_a, cur_b = a_start[strip] + done_a, b_start[strip] + done_b
    tri = np.where(
        on_b[:, None],
        np.column_stack([cur_b, node, cur_a]),
        np.column_stack([cur_a, node, cur_b]),
    )
    return _counter_clockwise(x, tri)


def _counter_clockwise(x, tri):
    """tri reordered counter-clockwise; ValueError for a triangle of no area (two rows that
    are not apart: a layout whose layers touch)."""
    p = x[tri]
    d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    area = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    if len(area):
        scale = max(np.ptp(x[:, 0]), np.ptp(x[:, 1])) ** 2
        bad = np.abs(area) <= 1e-14 * scale
        if bad.any():
            raise ValueError(
                f"layers: {int(bad.sum())} triangle(s) of no area, the first at "
                f"{p[bad][0].mean(axis=0)} (two layers not apart there)"
            )
    flip = area < 0
    tri[flip] = tri[flip][:, [0, 2, 1]]
    return tri


def layer_nodes(points, spacing):
    """Nodes of the layers (x (n, 2), starts (K, 5)): layer k's five points points[k] (K, 5, 2)
    joined by four sides, side j divided into max(1, round(length / spacing[k])) equal parts
    (none if its length is below 1e-12 of the layers' extent: the side is the node Q_j). The
    nodes of layer k run Q0 -> Q4 without repeating a shared point; side j of layer k is
    x[starts[k, j]:starts[k, j + 1] + 1] (starts[k, 4]: the node Q4)."""
    P = np.asarray(points, float)
    h = np.asarray(spacing, float)
    K = len(P)
    seg = P[:, 1:] - P[:, :-1]  # (K, 4, 2)
    length = np.hypot(seg[..., 0], seg[..., 1])
    tiny = 1e-12 * max(np.ptp(P[..., 0]), np.ptp(P[..., 1]))
    parts = np.where(length > tiny, np.maximum(1, np.rint(length / h[:, None])), 0).astype(int)
    # node count per layer: Q0, then each side's parts (its interior nodes and its end point)
    per_layer = 1 + parts.sum(axis=1)
    layer_start = np.concatenate([[0], np.cumsum(per_layer)[:-1]])
    starts = layer_start[:, None] + np.concatenate(
        [np.zeros((K, 1), int), np.cumsum(parts, axis=1)], axis=1
    )
    n = per_layer.sum()
    x = np.empty((n, 2))
    x[layer_start] = P[:, 0]
    # every side's nodes after its start point: t = i / parts, i = 1 .. parts
    flat = parts.ravel()
    side = np.repeat(np.arange(4 * K), flat)
    i = 1 + np.arange(flat.sum()) - np.repeat(np.cumsum(flat) - flat, flat)
    t = i / flat[side]
    k, j = np.divmod(side, 4)
    x[starts[k, j] + i] = P[k, j] + t[:, None] * seg[k, j]
    return x, starts


def layer_mesh(points, spacing):
    """(x (n, 2), triangles (m, 3) int64) of the layers points (K, 5, 2) (module docstring,
    points[0]: O five times, points[-1]: the body's outline) at the spacings (K,). Sides 0 and 3
    are the U's arms, 1 and 2 its halves either side of the middle Q2. Ties step the inner row
    first on sides 0 and 2 and the outer one on sides 1 and 3: the mirror image of side 0 is
    side 3 run backwards (of side 1, side 2), and a merge run backwards takes the other
    diagonal at a tie, so a layout symmetric about the vertical through Q2 gives a
    mirror-symmetric mesh (tested)."""
    P = np.asarray(points, float)
    x, starts = layer_nodes(P, spacing)
    K = len(P)
    k, j = np.divmod(np.arange(4 * (K - 1)), 4)
    a_start = starts[k, j]
    a_count = starts[k, j + 1] - a_start + 1
    b_start = starts[k + 1, j]
    b_count = starts[k + 1, j + 1] - b_start + 1
    d = P[k + 1, j + 1] - P[k + 1, j]  # the outer side's direction (the inner side's, parallel)
    norm = np.hypot(d[:, 0], d[:, 1])
    d = np.where(norm[:, None] > 0, d / np.where(norm > 0, norm, 1)[:, None], 0.0)
    tri = zip_strips(x, a_start, a_count, b_start, b_count, d, (j == 0) | (j == 2))
    return x, tri
