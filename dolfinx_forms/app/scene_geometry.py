"""Checks of a scene description's geometry, before anything is meshed: a polygon does not
cross itself, no two bodies overlap (identical bodies included), a cut scene's bodies lie on
its grid, and h resolves every body (at least two cells across). Each failure is a SpecError
naming the body (scene_spec.validate calls `check`)."""

import numpy as np

from dolfinx_forms.common import SpecError

SAMPLES = 96  # points per side of the sample grid of two bodies' common bounding box


def shapes(spec):
    """[(exact signed distance (< 0 inside), bounding box (2, 2))] of the bodies, each clipped
    by its window: the shapes the scene is built from (mesh.from_spec)."""
    import dolfinx_forms as df
    from dolfinx_forms.mesh.from_spec import body_shapes

    out = []
    for b, (sd, box) in zip(spec["bodies"], body_shapes(spec)):
        if b["window"] is not None:
            sd = df.Intersection([sd, df.Box(*(tuple(v[:2]) for v in b["window"]))])
        out.append((sd, box))
    return out


def check(spec):
    """SpecError for the first geometric fault of a validated description (module doc)."""
    bodies = spec["bodies"]
    for i, b in enumerate(bodies):
        if b["shape"]["type"] == "polygon":
            k = self_crossing(np.asarray(b["shape"]["points"], float)[:, :2])
            if k is not None:
                raise SpecError(
                    f"bodies[{i}].shape.points",
                    f"body {b['name']!r}: the polygon crosses itself (edges {k[0]} and {k[1]})",
                )
    sds, boxes = zip(*shapes(spec))
    d = spec["discretization"]
    h = d["h"]
    for i, (b, box) in enumerate(zip(bodies, boxes)):
        size = float(np.min(box[1] - box[0]))
        if size <= 0:
            raise SpecError(f"bodies[{i}]", f"body {b['name']!r} is empty (its window misses it)")
        if h > size / 2:
            raise SpecError(
                "discretization.h",
                f"must be at most half the smallest body's size: body {b['name']!r} is "
                f"{size:.4g} across, h = {h:g} (two cells across at least)",
            )
        ext = d.get("extent")
        if ext is not None:
            ext = np.asarray(ext, float)[:, :2]
            tol = 1e-9 * float(np.max(ext[1] - ext[0]))
            if np.any(box[0] < ext[0] - tol) or np.any(box[1] > ext[1] + tol):
                raise SpecError(
                    f"bodies[{i}]",
                    f"body {b['name']!r} ({box[0].tolist()} .. {box[1].tolist()}) lies partly "
                    f"outside the grid's extent {ext[0].tolist()} .. {ext[1].tolist()}",
                )
    for i in range(len(bodies)):
        for j in range(i + 1, len(bodies)):
            x = overlap_point(sds[i], sds[j], boxes[i], boxes[j], h)
            if x is not None:
                raise SpecError(
                    f"bodies[{j}]",
                    f"bodies {bodies[i]['name']!r} and {bodies[j]['name']!r} overlap (at "
                    f"({x[0]:.4g}, {x[1]:.4g})): bodies must be disjoint (they may touch)",
                )


def check_mpm(spec):
    """SpecError for the first geometric fault of a validated multi-step description
    (mpm_spec.py): a self-crossing polygon; a body off the grid or narrower than 4 cells; two
    bodies, or a body and an obstacle, overlapping deeper than h/2 (the multi-step scenes start
    with shallow overlaps on purpose: they close the contacts of the first step)."""
    from dolfinx_forms.mesh.from_spec import shape_of

    h = spec["grid"]["h"]
    ext = np.asarray(spec["grid"]["extent"], float)[:, :2]
    things = [("bodies", b) for b in spec["bodies"]] + [("obstacles", o) for o in spec["obstacles"]]
    index = {"bodies": 0, "obstacles": 0}
    found = []
    for kind, b in things:
        i = index[kind]
        index[kind] += 1
        key = f"{kind}[{i}]"
        if b["shape"]["type"] == "polygon":
            k = self_crossing(np.asarray(b["shape"]["points"], float)[:, :2])
            if k is not None:
                raise SpecError(
                    f"{key}.shape.points",
                    f"{b['name']!r}: the polygon crosses itself (edges {k[0]} and {k[1]})",
                )
        try:
            sd, box = shape_of(b["shape"], ext + [[-h], [h]] if kind == "obstacles" else None)
        except SpecError:  # a half-plane that misses the grid
            raise SpecError(f"{key}.shape", f"{b['name']!r} does not meet the grid") from None
        if kind == "bodies":
            size = float(np.min(box[1] - box[0]))
            if h > size / 4:
                raise SpecError(
                    "grid.h",
                    f"must be at most a quarter of the smallest body's size: body {b['name']!r} "
                    f"is {size:.4g} across, h = {h:g} (four cells across at least)",
                )
            tol = 1e-9 * float(np.max(ext[1] - ext[0]))
            if np.any(box[0] < ext[0] + h - tol) or np.any(box[1] > ext[1] - h + tol):
                raise SpecError(
                    key,
                    f"body {b['name']!r} ({box[0].tolist()} .. {box[1].tolist()}) is not inside "
                    f"the grid's extent {ext[0].tolist()} .. {ext[1].tolist()} by one cell",
                )
        found.append((kind, b["name"], sd, box, key))
    for i, (ka, na, sa, ba, _) in enumerate(found):
        for kb, nb, sb, bb, key in found[i + 1 :]:
            if ka == "obstacles" and kb == "obstacles":
                continue  # rigid obstacles may overlap each other
            x = overlap_point(sa, sb, ba, bb, h, depth=0.5 * h)
            if x is not None:
                raise SpecError(
                    key,
                    f"{na!r} and {nb!r} overlap deeper than h/2 = {0.5 * h:g} (at "
                    f"({x[0]:.4g}, {x[1]:.4g})): start them touching or overlapping less",
                )


def overlap_point(sd_a, sd_b, box_a, box_b, h, depth=None):
    """A point inside both bodies deeper than `depth` (default 1e-3 h: they may touch), or
    None: sampled on a SAMPLES x SAMPLES grid of their common bounding box (sd: signed
    distances, < 0 inside)."""
    lo, hi = np.maximum(box_a[0], box_b[0]), np.minimum(box_a[1], box_b[1])
    if np.any(hi <= lo):
        return None
    s = (np.arange(SAMPLES) + 0.5) / SAMPLES
    X, Y = np.meshgrid(lo[0] + s * (hi[0] - lo[0]), lo[1] + s * (hi[1] - lo[1]))
    x = np.c_[X.ravel(), Y.ravel()]
    both = np.minimum(-np.asarray(sd_a(x)), -np.asarray(sd_b(x)))
    k = int(np.argmax(both))
    return x[k] if both[k] > (1e-3 * h if depth is None else depth) else None


def self_crossing(P):
    """(k, l) of two non-adjacent edges of the closed polygon P (n, 2) that cross, or None."""
    n = len(P)
    if n < 4:
        return None
    a, b = P, np.roll(P, -1, axis=0)  # edge k: a[k] -> b[k]

    def orient(p, q, r):
        return np.sign((q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1])
                       - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0]))  # fmt: skip

    for k in range(n):  # a loop over edges, vectorised over the others (polygons are small)
        l = np.arange(k + 2, n if k > 0 else n - 1)
        if not len(l):
            continue
        o1 = orient(a[k], b[k], a[l])
        o2 = orient(a[k], b[k], b[l])
        o3 = orient(a[l], b[l], a[k])
        o4 = orient(a[l], b[l], b[k])
        hit = (o1 * o2 < 0) & (o3 * o4 < 0)
        if hit.any():
            return k, int(l[np.argmax(hit)])
    return None
