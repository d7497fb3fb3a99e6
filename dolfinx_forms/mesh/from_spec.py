"""Scenes from a checked description (`dolfinx_forms.app.scene_spec`): the same Scene contract as
the hand-written generators, on a cut grid (meshes/cut.py) or as gmsh body-fitted meshes.

Shapes give each body an exact signed distance (dolfinx_forms shapes) and a bounding box;
a body is shape ∩ window when it has a window.

* cut: the background grid spans `extent`; spacing h on `fine` (widened to the multiples of
  h, so that 0 is a line) growing by `growth` outside up to h_far, or without `fine` a
  uniform grid of about h (or of `cells` [n_x, n_y]). Every window bound is a grid line
  (outside `fine` the grading bends to hit it; inside it must be a multiple of h). A body's
  window defaults to its bounding box widened to grid lines. The level set that cuts cells
  is the shape, except that a box's sides lying on its window's sides are pushed out (those
  sides are grid lines: no cell is cut there).
* fitted: each body is a gmsh OpenCASCADE surface (disk, ellipse, rectangle, polygon,
  intersected with its window), meshed with size h on `fine` (default: the contact box),
  growing with `slope` per unit distance up to h_far (`structured`: boxes without a window
  are transfinite grids instead); quadrilaterals by recombination (meshed at 2h, every cell
  subdivided). Bodies are separate surfaces: coincident boundaries keep distinct vertices.
Boundaries: `side` = sides of the body's window (cut) or bounding box (fitted); `box` = the
boundary facets inside the box (of `body` if given). Boundary tags 1, 2, ... in order.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["build_scene", "shape_of"]


def _error(key, message):
    from dolfinx_forms.common import SpecError

    return SpecError(key, message)


def _clip_halfplane(box, point, normal):
    """Bounding box of box ∩ {(x - point) . normal <= 0} (box (2, 2); None if empty)."""
    lo, hi = box
    poly = [
        np.array(p, float) for p in ((lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1]))
    ]
    s = [float(np.dot(p - point, normal)) for p in poly]
    out = []
    for k in range(4):  # Sutherland-Hodgman against one plane
        p, q, sp, sq = poly[k], poly[(k + 1) % 4], s[k], s[(k + 1) % 4]
        if sp <= 0:
            out.append(p)
        if (sp < 0 < sq) or (sq < 0 < sp):
            out.append(p + sp / (sp - sq) * (q - p))
    return None if not out else np.array([np.min(out, axis=0), np.max(out, axis=0)])


def shape_of(shape, window=None, size=1e6):
    """(exact signed distance, bounding box (2, 2)) of a checked shape description, clipped to
    `window` if given (half-planes: exact within `size` of their point)."""
    import dolfinx_forms as df
    from dolfinx_forms.mesh.cut_scene import half_plane

    kind = shape["type"]
    if kind == "circle":
        c, r = np.array(shape["centre"][:2]), shape["radius"]
        sd, bbox = df.Circle(tuple(c), r), np.array([c - r, c + r])
    elif kind == "ellipse":
        c, (a, b), t = np.array(shape["centre"][:2]), shape["axes"], math.radians(shape["angle"])
        sd = df.Ellipse(tuple(c), a, b, t)
        e = np.hypot([a * math.cos(t), a * math.sin(t)], [b * math.sin(t), b * math.cos(t)])
        bbox = np.array([c - e, c + e])
    elif kind == "box":
        bbox = np.array([shape["min"][:2], shape["max"][:2]], float)
        sd = df.Box(tuple(bbox[0]), tuple(bbox[1]))
    elif kind == "polygon":
        pts = np.array([p[:2] for p in shape["points"]], float)
        sd, bbox = df.Polygon(pts), np.array([pts.min(axis=0), pts.max(axis=0)])
    else:  # half_plane: the window bounds it
        p, n = np.array(shape["point"][:2], float), np.array(shape["normal"][:2], float)
        sd = half_plane(p, n, size)
        bbox = _clip_halfplane(np.asarray(window, float), p, n / np.linalg.norm(n))
        if bbox is None:
            raise _error("window", "does not meet the half-plane")
        return sd, bbox
    if window is not None:
        w = np.asarray(window, float)
        bbox = np.array([np.maximum(bbox[0], w[0]), np.minimum(bbox[1], w[1])])
        if np.any(bbox[0] >= bbox[1]):
            raise _error("window", f"does not meet the shape (bounding box {bbox.tolist()})")
    return sd, bbox


def body_shapes(spec):
    """Per body: (shape, bbox), errors keyed by the body."""
    size = 100 * max(_scale(spec), 1.0)
    out = []
    for i, b in enumerate(spec["bodies"]):
        for p in _points(b["shape"]) + ([] if b["window"] is None else b["window"]):
            if len(p) != 2:
                raise _error(f"bodies[{i}]", "scenes are 2D: points are [x, y]")
        try:
            out.append(shape_of(b["shape"], b["window"], size))
        except ValueError as e:
            raise _error(f"bodies[{i}].{getattr(e, 'key', 'shape')}", str(e).split(": ", 1)[-1])
    return out


def _points(shape):
    pts = [shape[k] for k in ("centre", "min", "max", "point", "normal") if k in shape]
    return pts + list(shape.get("points") or [])


def _scale(spec):
    d = spec["discretization"]
    boxes = [d["extent"]] if d.get("extent") else []
    boxes += [b["window"] for b in spec["bodies"] if b["window"]]
    for b in spec["bodies"]:
        pts = [p[:2] for p in _points(b["shape"]) if p is not b["shape"].get("normal")]
        boxes.append([np.min(pts, axis=0), np.max(pts, axis=0)])
    lo = np.min([np.asarray(b[0], float)[:2] for b in boxes], axis=0)
    hi = np.max([np.asarray(b[1], float)[:2] for b in boxes], axis=0)
    r = max(
        [b["shape"].get("radius", 0) for b in spec["bodies"]]
        + [max(b["shape"].get("axes", [0])) for b in spec["bodies"]]
    )
    return float(np.max(hi - lo) + 2 * r)


def _markers(spec, frames, tol):
    """boundary_markers for cut_scene / scene_from_gmsh; frames[i]: the (2, 2) box whose sides
    `side` names for body i."""
    from dolfinx_forms.mesh.scene import on_box_side

    names = [b["name"] for b in spec["bodies"]]
    markers = {}
    for tag, b in enumerate(spec["boundaries"], start=1):
        body = None if b["body"] is None else names.index(b["body"])
        if "side" in b:
            pred = on_box_side(*frames[body], b["side"], tol)
        else:
            bounds = [(k, b["box"][f"{c}_min"], b["box"][f"{c}_max"]) for k, c in enumerate("xy")]

            def pred(x, bounds=bounds):
                inside = np.ones(x.shape[1], dtype=bool)
                for k, lo, hi in bounds:
                    inside &= x[k] >= (-np.inf if lo is None else lo - tol)
                    inside &= x[k] <= (np.inf if hi is None else hi + tol)
                return inside

        markers[b["name"]] = (tag, pred) if body is None else (tag, pred, body)
    return markers


def _contact_box(spec, bboxes):
    """The union of the pairs' overlapping bounding boxes, inflated by band + h (or the given
    contact_box); None if no pair overlaps."""
    d, names = spec["discretization"], [b["name"] for b in spec["bodies"]]
    if d["contact_box"] is not None:
        return np.asarray(d["contact_box"], float)
    grow = (spec["solver"]["band"] or 2 * d["h"]) + d["h"]
    boxes = []
    for a, b in spec["pairs"]:
        bi, bj = bboxes[names.index(a)], bboxes[names.index(b)]
        lo, hi = np.maximum(bi[0], bj[0]) - grow, np.minimum(bi[1], bj[1]) + grow
        if np.all(lo < hi):
            boxes.append((lo, hi))
    if not boxes:
        return None
    return np.array([np.min([b[0] for b in boxes], axis=0), np.max([b[1] for b in boxes], axis=0)])


# --------------------------------------------------------------------------- cut
def _grid_lines(d, windows):
    """x and y lines of the background grid (see the module docstring)."""
    from dolfinx_forms.mesh.cut_scene import graded_lines

    h, ext, lines = d["h"], np.asarray(d["extent"], float), []
    key = "discretization.cells" if d["fine"] is None and d["cells"] else "discretization.h"
    for ax in range(2):
        a, b = ext[:, ax]
        if d["fine"] is None:
            n = d["cells"][ax] if d["cells"] else max(1, round((b - a) / h))
            _check_cells(key, n)  # before the lines are allocated
            lines.append(np.linspace(a, b, n + 1))
            continue
        req = sorted({w[k][ax] for w in windows for k in (0, 1) if a < w[k][ax] < b})
        f0, f1 = d["fine"][0][ax], d["fine"][1][ax]
        c0, c1 = h * math.floor(f0 / h + 1e-9), h * math.ceil(f1 / h - 1e-9)
        c0, c1 = (a, c1) if c0 < a else (c0, c1)
        c0, c1 = (c0, b) if c1 > b else (c0, c1)
        _check_cells(key, abs(c1 - c0) / h)  # the fine lines alone
        try:
            lines.append(
                graded_lines(
                    a, b, (min(c0, c1), max(c0, c1)), h, d["growth"], d["h_far"], required=req
                )
            )
        except ValueError as e:
            raise _error("discretization", f"{'xy'[ax]} lines: {e}") from None
    _check_cells(key, (len(lines[0]) - 1) * (len(lines[1]) - 1))
    return lines


def _check_cells(key, cells):
    """SpecError at `key` for more cells than a scene builder makes
    (dolfinx_forms.mesh.scene.MAX_CELLS)."""
    from dolfinx_forms.mesh.scene import check_cells

    try:
        check_cells("the scene", cells, "a larger h or fewer cells")
    except ValueError as e:
        raise _error(key, str(e)) from None


def _snap(lines, lo, hi, tol):
    """The smallest [line, line] interval holding [lo, hi] (clipped to the grid)."""
    i = np.searchsorted(lines, lo + tol, side="right") - 1
    j = np.searchsorted(lines, hi - tol, side="left")
    return lines[max(i, 0)], lines[min(j, len(lines) - 1)]


def _cut_scene(comm, spec):
    import dolfinx_forms as df

    from dolfinx_forms.mesh.cut_scene import CutBody, cut_scene

    d = spec["discretization"]
    frames = body_shapes(spec)
    explicit = [b["window"] for b in spec["bodies"] if b["window"] is not None]
    xl, yl = _grid_lines(d, explicit)
    tol = 1e-9 * max(xl[-1] - xl[0], yl[-1] - yl[0])
    margin = 10 * _scale(spec)
    bodies, windows = [], []
    for i, (b, (sd, bbox)) in enumerate(zip(spec["bodies"], frames)):
        if b["window"] is not None:
            w = np.asarray(b["window"], float)
            for ax, lines in enumerate((xl, yl)):
                off = [v for v in w[:, ax] if np.min(np.abs(lines - v)) > tol]
                if off:
                    why = (
                        "the grid is uniform"
                        if d["fine"] is None
                        else "inside `fine`, lines are multiples of h"
                    )
                    raise _error(
                        f"bodies[{i}].window", f"{'xy'[ax]} = {off[0]:g} is not a grid line ({why})"
                    )
        else:
            w = np.array(
                [_snap(xl, bbox[0][0], bbox[1][0], tol), _snap(yl, bbox[0][1], bbox[1][1], tol)]
            ).T
        if b["shape"]["type"] == "box":  # sides on the window are grid lines: push them out
            lo, hi = np.array(b["shape"]["min"][:2]), np.array(b["shape"]["max"][:2])
            lo = np.where(lo <= w[0] + tol, lo - margin, lo)
            hi = np.where(hi >= w[1] - tol, hi + margin, hi)
            sd = df.Box(tuple(lo), tuple(hi))
        bodies.append(CutBody(b["name"], i + 1, w, sd, bbox))
        windows.append(w)
    names = [b["name"] for b in spec["bodies"]]
    pairs = [(names.index(a), names.index(b)) for a, b in spec["pairs"]]
    markers = _markers(spec, windows, tol)
    try:
        return cut_scene(
            comm,
            xl,
            yl,
            bodies,
            markers,
            pairs,
            d["h"],
            contact_box=_contact_box(spec, [f[1] for f in frames]),
        )
    except ValueError as e:
        raise _error("bodies", str(e)) from None


# --------------------------------------------------------------------------- fitted (gmsh)
def _occ_body(occ, shape, window, size):
    """Rank 0: the OpenCASCADE surface of one body; returns its dim-tags."""
    kind = shape["type"]
    if kind == "circle":
        c, r = shape["centre"], shape["radius"]
        tags = [(2, occ.addDisk(c[0], c[1], 0.0, r, r))]
    elif kind == "ellipse":
        (c, (a, b)), t = (shape["centre"], shape["axes"]), math.radians(shape["angle"])
        if b > a:  # OCC wants the larger radius along x
            a, b, t = b, a, t + math.pi / 2
        tags = [(2, occ.addDisk(c[0], c[1], 0.0, a, b))]
        occ.rotate(tags, c[0], c[1], 0.0, 0.0, 0.0, 1.0, t)
    elif kind == "box":
        (x0, y0), (x1, y1) = shape["min"][:2], shape["max"][:2]
        tags = [(2, occ.addRectangle(x0, y0, 0.0, x1 - x0, y1 - y0))]
    else:
        if kind == "polygon":
            pts = [p[:2] for p in shape["points"]]
        else:  # a half-plane as a large square on its line
            p, n = np.array(shape["point"][:2], float), np.array(shape["normal"][:2], float)
            n, L = n / np.linalg.norm(n), size
            t = np.array([-n[1], n[0]])
            pts = [p - L * t, p + L * t, p + L * (t - 2 * n), p - L * (t + 2 * n)]
        ids = [occ.addPoint(float(q[0]), float(q[1]), 0.0) for q in pts]
        lines = [occ.addLine(ids[k], ids[(k + 1) % len(ids)]) for k in range(len(ids))]
        tags = [(2, occ.addPlaneSurface([occ.addCurveLoop(lines)]))]
    if window is not None:
        (x0, y0), (x1, y1) = window
        rect = [(2, occ.addRectangle(x0, y0, 0.0, x1 - x0, y1 - y0))]
        tags, _ = occ.intersect(tags, rect)
    return tags


def _structured(gmsh, surface, size, quads):
    """Rank 0: a transfinite (structured) mesh of a rectangle, about `size` per cell."""
    for _, c in gmsh.model.getBoundary([(2, surface)], oriented=False):
        x0, y0, _, x1, y1, _ = gmsh.model.getBoundingBox(1, c)
        gmsh.model.mesh.setTransfiniteCurve(c, max(1, round(max(x1 - x0, y1 - y0) / size)) + 1)
    gmsh.model.mesh.setTransfiniteSurface(surface)
    if quads:
        gmsh.model.mesh.setRecombine(2, surface)


def _fitted_scene(comm, spec):
    import dolfinx_forms as df

    from dolfinx_forms.mesh.scene import Body, gmsh_model, scene_from_gmsh

    d = spec["discretization"]
    h, quads = d["h"], d["cell"] == "quadrilateral"
    frames = body_shapes(spec)
    bodies = []
    for i, (b, (sd, bbox)) in enumerate(zip(spec["bodies"], frames)):
        if b["window"] is not None and b["shape"]["type"] != "half_plane":
            sd = df.Intersection([sd, df.Box(*(tuple(v[:2]) for v in b["window"]))])
        bodies.append(Body(b["name"], i + 1, sd, bbox))
    bboxes = [f[1] for f in frames]
    box = _contact_box(spec, bboxes)
    fine = np.asarray(d["fine"], float) if d["fine"] is not None else box
    if fine is None:
        fine = np.array([np.min(bboxes, axis=(0, 1)), np.max(bboxes, axis=(0, 1))])
    _check_cells("discretization.h", np.prod(np.ptp(fine, axis=0)) / h**2)  # the zone at h
    tol = 1e-8 * _scale(spec)
    names = [b["name"] for b in spec["bodies"]]
    pairs = [(names.index(a), names.index(b)) for a, b in spec["pairs"]]
    markers = _markers(spec, bboxes, tol)
    size = 100 * _scale(spec)
    with gmsh_model(comm, spec["name"]) as gmsh:
        if comm.rank == 0:
            occ = gmsh.model.occ
            surfaces = []
            for i, b in enumerate(spec["bodies"]):
                surfaces.append(_occ_body(occ, b["shape"], b["window"], size))
                if not surfaces[-1]:
                    raise _error(f"bodies[{i}].window", "does not meet the shape")
            occ.synchronize()
            hq, far = (2 * h, 2 * d["h_far"]) if quads else (h, d["h_far"])
            if d["structured"]:  # boxes: transfinite grids, spacing about h
                for b, tags in zip(spec["bodies"], surfaces):
                    if b["shape"]["type"] == "box" and b["window"] is None:
                        _structured(gmsh, tags[0][1], hq, quads)
            f = gmsh.model.mesh.field.add("Box")
            for k, v in dict(
                VIn=hq,
                VOut=far,
                XMin=fine[0][0],
                XMax=fine[1][0],
                YMin=fine[0][1],
                YMax=fine[1][1],
                Thickness=max(far - hq, 0.0) / d["slope"],
            ).items():
                gmsh.model.mesh.field.setNumber(f, k, float(v))
            gmsh.model.mesh.field.setAsBackgroundMesh(f)
            gmsh.option.setNumber("Mesh.RecombineAll", int(quads))
            gmsh.option.setNumber("Mesh.SubdivisionAlgorithm", int(quads))
            gmsh.model.mesh.generate(2)
        return scene_from_gmsh(comm, bodies, markers, pairs, h, contact_box=box)


def build_scene(comm, spec):
    """Collective: the Scene of a checked description (cut or fitted). SpecError for a
    description that the geometry refuses (window off the grid, a body without cells)."""
    kind = spec["discretization"]["kind"]
    return _cut_scene(comm, spec) if kind == "cut" else _fitted_scene(comm, spec)
