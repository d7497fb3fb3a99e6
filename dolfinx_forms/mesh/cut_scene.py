"""Structured-grid (cut-cell) scenes: bodies as level sets on one tensor-product grid.

Geometry: a tensor-product background grid of quadrilaterals (x lines `xlines`, y lines
`ylines`, strictly increasing, uniform or graded, see :func:`graded_lines`). Body b is
  window_b ∩ {cut_shape_b < 0},
window_b = [x0, x1] x [y0, y1] with all four bounds grid lines (its grid-aligned sides carry
the Dirichlet conditions and tractions), cut_shape_b a dolfinx_forms shape (< 0 inside) whose
zero contour alone cuts cells (so no kink of the level set lies inside a cell at the window
corners). The exact shape for contact is Body.shape = Intersection([cut_shape, Box(window)]).
Active cells of body b: the grid cells inside its window with min(phi) < 0 over their four
vertices (phi = cut_shape at the vertices); a cell is "interior" (kind 0) if max(phi) <= 0, else
"cut" (kind 1). All bodies' active cells form ONE quadrilateral DOLFINx mesh as a disjoint
union: each body has its own vertices (coincident, distinct vertices where bodies overlap
the same grid region). The body tag and kind of every cell come from the construction (carried
through the distribution by the topology's original cell index), not from the shapes.
Ghost facets (tag 1): interior facets (two cells of one body) with at least one cut cell.
Boundaries: named facet tags as in the gmsh scenes; names on a cut (non grid-aligned)
boundary are kept in Scene.boundaries but mark no facet. The verification scenes built on
it are in meshes/cut.py.
"""

from __future__ import annotations

from dataclasses import dataclass

import dolfinx
import dolfinx.fem
import dolfinx.mesh
import numpy as np
import ufl

from dolfinx_forms.fem.cut import CUT, GHOST_FACET, grid_cells, shape_values
from dolfinx_forms.mesh.scene import (
    Body,
    CutData,
    Scene,
    partitioner_kwargs,
    tag_boundaries,
)


# --------------------------------------------------------------------------- grid lines
def _grade(length, s0, growth, h_far):
    """Spacings (n,) summing exactly to `length` > 0, continuing a grid whose last spacing is
    s0: n is the fewest spacings min(s0 r^i, h_far), i = 1..n, that reach `length` with
    r = growth; then r in [1, growth] is lowered until they sum to `length` exactly. If even
    r = 1 overshoots (a short segment), n uniform spacings length / n (>= s0 / 2 for n >= 2)."""
    s1 = min(s0 * growth, h_far)
    nmax = np.ceil(length / s1) + 2  # the spacings are >= s1, and grow geometrically to h_far
    if growth > 1:
        ngeo = np.ceil(np.log1p(length * (growth - 1) / s1) / np.log(growth))
        nmax = min(nmax, ngeo + np.ceil(length / h_far) + 2)
    i = np.arange(1, int(nmax) + 1)

    def seq(r):
        return np.minimum(s0 * r**i, h_far)

    n = int(np.searchsorted(np.cumsum(seq(growth)), length * (1 - 1e-12))) + 1
    i = i[:n]
    if n * min(s0, h_far) > length:
        return np.full(n, length / n)
    lo, hi = 1.0, growth
    for _ in range(60):  # bisection on the growth rate (a scalar: 60 halvings of [1, growth])
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if seq(mid).sum() < length else (lo, mid)
    s = seq(hi)
    return s * (length / s.sum())


def _graded_side(points, s0, growth, h_far):
    """Lines beyond points[0] through each of points[1:] (increasing distances from the fine
    zone, all hit exactly), the first spacing continuing s0."""
    out = []
    for p0, p1 in zip(points[:-1], points[1:]):  # a few required points, not cells
        s = _grade(p1 - p0, s0, growth, h_far)
        q = p0 + np.cumsum(s)
        q[-1] = p1
        out.append(q)
        s0 = s[-1]
    return np.concatenate(out) if out else np.zeros(0)


def graded_lines(a, b, fine, h, growth=1.2, h_far=None, required=()) -> np.ndarray:
    """Strictly increasing grid lines from a to b (both lines).

    On fine = (c0, c1) the lines are exactly c0 + k h (c0 and c1 are lines: (c1 - c0) / h must
    be an integer to 1e-9); outside, the spacing grows geometrically by at most `growth` per
    line, up to h_far (None: no cap), and every point of `required` (e.g. 0, -depth, R) is a
    line exactly: the grid is graded piecewise between consecutive required points, each piece
    scaled to fit (see _grade). A required point inside the fine zone must be on its lattice.
    Spacings can only get smaller than h / 2 where required points are closer than that.
    """
    a, b, h, growth = float(a), float(b), float(h), float(growth)
    c0, c1 = (float(c) for c in fine)
    h_far = np.inf if h_far is None else max(float(h_far), h)
    if not h > 0:
        raise ValueError(f"graded_lines: h must be > 0, got h={h}")
    if not growth >= 1:
        raise ValueError(f"graded_lines: growth must be >= 1, got growth={growth}")
    if not a <= c0 <= c1 <= b or a == b:
        raise ValueError(
            f"graded_lines: need a <= fine[0] <= fine[1] <= b and a < b, got a={a}, "
            f"fine=({c0}, {c1}), b={b}"
        )
    k = (c1 - c0) / h
    if abs(k - round(k)) > 1e-9:
        raise ValueError(
            f"graded_lines: fine=({c0}, {c1}) is not a whole number of cells of "
            f"h={h} ((c1 - c0) / h = {k!r})"
        )
    tol = 1e-9 * h
    fine_lines = c0 + h * np.arange(round(k) + 1)
    fine_lines[-1] = c1
    req = np.unique(np.concatenate([np.asarray(required, float).ravel(), [a, b]]))
    if req[0] < a - tol or req[-1] > b + tol:
        raise ValueError(f"graded_lines: required={list(required)} has points outside [{a}, {b}]")
    in_fine = (req >= c0 - tol) & (req <= c1 + tol)
    idx = np.rint((req[in_fine] - c0) / h).astype(int)
    off = np.abs(req[in_fine] - fine_lines[idx]) > tol
    if off.any():
        raise ValueError(
            f"graded_lines: required={list(required)}: {req[in_fine][off]} lie in "
            f"fine=({c0}, {c1}) but not on its lines {c0} + k*{h}"
        )
    fine_lines[idx] = req[in_fine]  # exactly the required values (e.g. 0, not 2e-17)
    right = _graded_side(np.concatenate([[c1], req[req > c1 + tol]]), h, growth, h_far)
    left = _graded_side(-np.concatenate([[c0], req[req < c0 - tol][::-1]]), h, growth, h_far)
    lines = np.concatenate([-left[::-1], fine_lines, right])  # mirrored: the points stay exact
    assert np.all(np.diff(lines) > 0), "graded_lines: lines not strictly increasing"
    return lines


def half_plane(point, normal, extent) -> object:
    """The half-plane {(x - point) . normal < 0} (normal: outward) as a dolfinx_forms Polygon, a
    square of side 2 extent on the line through `point`: its signed distance is exact within
    `extent` of `point` (use extent >> the scene)."""
    import dolfinx_forms as df

    p, n = np.asarray(point, float), np.asarray(normal, float) / np.linalg.norm(normal)
    t = np.array([-n[1], n[0]])
    L = float(extent)
    return df.Polygon(np.array([p - L * t, p + L * t, p + L * (t - 2 * n), p - L * (t + 2 * n)]))


# --------------------------------------------------------------------------- the cut scene
@dataclass
class CutBody:
    name: str
    tag: int
    window: np.ndarray  # (2, 2) [[x0, y0], [x1, y1]], all four values grid lines
    shape: object  # the cut level set (a shape or a grid _cpp.LevelSet; only its zero contour
    # cuts cells), < 0 inside
    bbox: np.ndarray | None = None  # (2, 2) bounding box of the body; None: from the grid


def _line_index(lines, values, what):
    """Indices of `values` in `lines` (to 1e-9 of the grid extent), else ValueError."""
    tol = 1e-9 * (lines[-1] - lines[0])
    i = np.clip(np.searchsorted(lines, values), 1, len(lines) - 1)
    i = np.where(np.abs(lines[i - 1] - values) < np.abs(lines[i] - values), i - 1, i)
    bad = np.abs(lines[i] - values) > tol
    if bad.any():
        raise ValueError(f"{what}: {np.asarray(values)[bad]} not on the grid lines")
    return i


def _body_grid(xlines, ylines, body):
    """Rank 0: (vertices (nv, 2), cells (nc, 4) DOLFINx order, kinds (nc,), bbox (2, 2)) of
    the active cells of one body, vertices numbered from 0 (only those of active cells)."""
    w = np.asarray(body.window, float)
    if w.shape != (2, 2) or not np.all(w[1] > w[0]):
        raise ValueError(
            f"body {body.name!r}: window must be [[x0, y0], [x1, y1]] with x0 < x1 "
            f"and y0 < y1, got {w.tolist()}"
        )
    i0, i1 = _line_index(xlines, w[:, 0], f"body {body.name!r}: window x bounds")
    j0, j1 = _line_index(ylines, w[:, 1], f"body {body.name!r}: window y bounds")
    X, Y = xlines[i0 : i1 + 1], ylines[j0 : j1 + 1]
    pts = np.stack(np.meshgrid(X, Y), axis=-1).reshape(-1, 2)  # vertex (i, j) is j (nx+1) + i
    g = grid_cells(X, Y, shape_values(body.shape, pts))
    quads, active, kinds = g["quads"], g["active"], g["kinds"]
    if not active.any():
        raise ValueError(
            f"body {body.name!r}: no active cell (cut shape >= 0 at every vertex of "
            f"window {w.tolist()})"
        )
    used, cells = np.unique(quads[active], return_inverse=True)
    bbox = g["bbox"] if body.bbox is None else body.bbox
    return pts[used], cells.reshape(-1, 4), kinds, np.asarray(bbox, float)


def _ghost_facets(mesh, kinds):
    """MeshTags (value GHOST_FACET) on the local facets with two local cells, one of them cut."""
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim - 1, tdim)
    f2c = mesh.topology.connectivity(tdim - 1, tdim)
    off = f2c.offsets
    interior = np.flatnonzero(np.diff(off) == 2)
    a, b = f2c.array[off[interior]], f2c.array[off[interior] + 1]
    facets = interior[(kinds[a] == CUT) | (kinds[b] == CUT)].astype(np.int32)
    values = np.full(len(facets), GHOST_FACET, np.int32)
    tags = dolfinx.mesh.meshtags(mesh, tdim - 1, facets, values)
    tags.name = "ghost_facets"
    return tags


def cut_scene(
    comm,
    xlines,
    ylines,
    bodies,
    boundary_markers,
    pairs,
    h_contact,
    contact_box=None,
    ghost_mode=dolfinx.mesh.GhostMode.shared_facet,
) -> Scene:
    """Collective: the cut-cell Scene (cell_type "quadrilateral", Scene.cut set) of `bodies`
    (CutBody or (name, tag, window, cut_shape[, bbox]) tuples) on the grid xlines x ylines.

    boundary_markers, pairs, contact_box: as in :func:`dolfinx_forms.mesh.scene.scene_from_gmsh` (no
    contact_box: derived from the pairs and the bodies' bounding boxes, see
    :func:`dolfinx_forms.mesh.scene.pairs_contact_boxes`; False: DOLFINx's graph partitioner). Each
    rank makes the cells of every size-th body; rank 0 gathers them in the bodies' order and
    passes them to create_mesh (the other ranks pass empty arrays); the
    body tag and kind of each cell reach the owner and ghosts through
    topology.original_cell_index. ValueError (on every rank) if a window bound is not a grid
    line or a body has no active cell.
    """
    import dolfinx_forms as df

    xlines, ylines = (np.asarray(v, float) for v in (xlines, ylines))
    bodies = [b if isinstance(b, CutBody) else CutBody(*b) for b in bodies]
    for name, lines in (("xlines", xlines), ("ylines", ylines)):  # every rank: the same lines
        if lines.ndim != 1 or len(lines) < 2 or not np.all(np.diff(lines) > 0):
            raise ValueError(f"cut_scene: {name} must be strictly increasing (>= 2 lines)")
    # each rank the cells of every size-th body (level sets sampled on their windows: at 400
    # grains 0.26 s a step on rank 0 alone), gathered on rank 0 in the bodies' order
    mine, failed = [], None
    for k in range(comm.rank, len(bodies), comm.size):
        try:
            mine.append((k, _body_grid(xlines, ylines, bodies[k])))
        except Exception as e:  # every rank raises (the others would wait in gather)
            failed = (k, isinstance(e, ValueError), str(e), e)
            break
    failures = [f for f in comm.allgather(failed and failed[:3]) if f]  # (body, kind, text)
    if failures:
        k, value_error, message = min(failures)
        if failed is not None and failed[0] == k:
            raise failed[3]
        raise (ValueError if value_error else RuntimeError)(message)
    gathered = comm.gather(mine, root=0)
    status = None
    if comm.rank == 0:
        try:
            parts = [p for _, p in sorted((q for g in gathered for q in g), key=lambda q: q[0])]
            offsets = np.cumsum([0] + [len(p[0]) for p in parts])
            x = np.concatenate([p[0] for p in parts])
            cells = np.concatenate([p[1] + o for p, o in zip(parts, offsets)]).astype(np.int64)
            counts = [len(p[1]) for p in parts]
            tags = np.repeat(np.array([b.tag for b in bodies], np.int32), counts)
            kinds = np.concatenate([p[2] for p in parts])
            status = ("ok", tags, kinds, [p[3] for p in parts])
        except Exception as e:  # every rank raises (the others would wait in bcast)
            error = e
            status = ("error", isinstance(e, ValueError), str(e))
    status = comm.bcast(status, root=0)
    if status[0] != "ok":
        if comm.rank == 0:
            raise error
        raise (ValueError if status[1] else RuntimeError)(f"rank 0: {status[2]}")
    _, tags, kinds, bboxes = status
    if comm.rank != 0:
        x, cells = np.zeros((0, 2)), np.zeros((0, 4), np.int64)

    domain = ufl.Mesh(ufl.VectorElement("Lagrange", ufl.quadrilateral, 1))
    # default contact box: from the pairs and the bodies' bboxes (known on every rank)
    box_bodies = [Body(b.name, b.tag, None, bbox) for b, bbox in zip(bodies, bboxes)]
    kwargs = partitioner_kwargs(
        comm, x, cells, "quadrilateral", contact_box, box_bodies, pairs, h_contact
    )
    mesh = dolfinx.mesh.create_mesh(comm, cells, x, domain, ghost_mode=ghost_mode, **kwargs)

    tdim = mesh.topology.dim
    original = np.asarray(mesh.topology.original_cell_index)  # owned + ghost: index on rank 0
    local = np.arange(len(original), dtype=np.int32)
    cvalues, ckinds = tags[original], kinds[original]
    cell_tags = dolfinx.mesh.meshtags(mesh, tdim, local, cvalues)
    cell_tags.name = "bodies"
    kind_tags = dolfinx.mesh.meshtags(mesh, tdim, local, ckinds)
    kind_tags.name = "kinds"
    windows = {b.tag: np.asarray(b.window, float) for b in bodies}
    # a grid level set (an evolved body) is its own contact shape: its window only limits cells
    scene_bodies = [
        Body(
            b.name,
            b.tag,
            b.shape
            if isinstance(b.shape, df.LevelSet)
            else df.Intersection([b.shape, df.Box(*windows[b.tag])]),
            bbox,
        )
        for b, bbox in zip(bodies, bboxes)
    ]
    facet_tags, boundaries = tag_boundaries(mesh, cvalues, scene_bodies, boundary_markers)
    cut = CutData(
        xlines=xlines,
        ylines=ylines,
        windows=windows,
        levelsets={b.tag: b.shape for b in bodies},
        kind_tags=kind_tags,
        ghost_facets=_ghost_facets(mesh, ckinds),
    )
    return Scene(
        mesh=mesh,
        cell_tags=cell_tags,
        facet_tags=facet_tags,
        boundaries=boundaries,
        bodies=scene_bodies,
        pairs=[tuple(p) for p in pairs],
        h_contact=float(h_contact),
        cell_type="quadrilateral",
        cut=cut,
    )
