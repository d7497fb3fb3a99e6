"""Grain outlines for particle assemblies (issue 13, item 2), numpy only.

Shapes for the level-set bodies:
  disc, ellipse, polygon       exact signed-distance shapes (dolfinx_forms Circle, Ellipse,
                               Polygon; < 0 inside), for levelset_from_shape
  disc_outline, ellipse_outline  the same curves as closed counter-clockwise polygons
  fourier_grain                seeded sand-grain outline from Fourier descriptors,
                               r(theta) = R (1 + sum_{k>=2} a_k cos(k theta + phi_k)) with
                               a_2 = elongation and a_k ~ k^-decay (k >= 3) scaled to an RMS
                               radial roughness; star-shaped about its centroid
  pack_grains                  random sequential addition of given outlines in a rectangular
                               box with a minimum gap, broad phase (_cpp.candidate_pairs_between)
                               plus an exact polygon distance on the candidates
Polygon helpers: polygon_area (signed, > 0 counter-clockwise), polygon_centroid, polygon_bbox,
rotate, point_in_polygon, segment_distance, polygon_distance, min_separation.
Vertex arrays are (n, 2), closing edge implied (last vertex != first). A polygon outline becomes
a grid level set with dolfinx_forms.levelset_from_polyline(grid, vertices, band).
Run: /usr/bin/python3 -m meshes.grains [--n 25] [--seed 1]   (prints a packing summary)
"""

from __future__ import annotations

import numpy as np
from dolfinx_forms import _cpp

__all__ = [
    "disc",
    "ellipse",
    "polygon",
    "disc_outline",
    "ellipse_outline",
    "fourier_modes",
    "fourier_outline",
    "fourier_grain",
    "polygon_area",
    "polygon_centroid",
    "polygon_bbox",
    "rotate",
    "point_in_polygon",
    "segment_distance",
    "polygon_distance",
    "min_separation",
    "pack_grains",
]

#: Lower bound on r / R of a Fourier grain: sum_k |a_k| <= 1 - MIN_RADIUS_FRACTION.
MIN_RADIUS_FRACTION = 0.3


def _vertices(v, name="vertices") -> np.ndarray:
    v = np.asarray(v, dtype=float)
    if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 3:
        raise ValueError(f"{name}: expected an array of shape (n, 2), n >= 3, got {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"{name}: non-finite coordinates")
    return v


def _point(p, name) -> np.ndarray:
    p = np.asarray(p, dtype=float)
    if p.shape != (2,) or not np.all(np.isfinite(p)):
        raise ValueError(f"{name}: expected 2 finite coordinates, got {p!r}")
    return p


def _positive(x, name) -> float:
    x = float(x)
    if not (np.isfinite(x) and x > 0):
        raise ValueError(f"{name}: expected a finite value > 0, got {x}")
    return x


# ---------------------------------------------------------------------------------------------
# Analytic shapes and their outlines


def disc(center, R):
    """Disc of radius R: exact signed distance (dolfinx_forms.Circle)."""
    return _cpp.Circle(tuple(_point(center, "center")), _positive(R, "R"))


def ellipse(center, a, b, angle=0.0):
    """Ellipse with semi-axes a (along angle) and b: exact signed distance (Ellipse)."""
    return _cpp.Ellipse(
        tuple(_point(center, "center")), _positive(a, "a"), _positive(b, "b"), float(angle)
    )


def polygon(vertices):
    """Closed polygon: exact signed distance (dolfinx_forms.Polygon), either orientation."""
    return _cpp.Polygon(_vertices(vertices))


def disc_outline(center, R, n_vertices=64) -> np.ndarray:
    """Counter-clockwise regular n-gon inscribed in the circle (center, R)."""
    return ellipse_outline(center, R, R, 0.0, n_vertices)


def ellipse_outline(center, a, b, angle=0.0, n_vertices=64) -> np.ndarray:
    """Counter-clockwise polygon with vertices on the ellipse at uniform parameter steps."""
    c = _point(center, "center")
    a, b = _positive(a, "a"), _positive(b, "b")
    if int(n_vertices) < 3:
        raise ValueError(f"n_vertices: expected >= 3, got {n_vertices}")
    t = 2 * np.pi * np.arange(int(n_vertices)) / int(n_vertices)
    return rotate(np.column_stack([a * np.cos(t), b * np.sin(t)]), angle, about=(0.0, 0.0)) + c


# ---------------------------------------------------------------------------------------------
# Polygon helpers


def polygon_area(vertices) -> float:
    """Signed area (shoelace): > 0 for counter-clockwise vertices."""
    v = _vertices(vertices)
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def polygon_centroid(vertices) -> np.ndarray:
    """Area centroid of a simple polygon (either orientation)."""
    v = _vertices(vertices)
    # Relative to the first vertex: no cancellation for polygons far from the origin.
    o = v[0]
    x, y = v[:, 0] - o[0], v[:, 1] - o[1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = 0.5 * cross.sum()
    if area == 0:
        raise ValueError("vertices: polygon of zero area has no centroid")
    return o + np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / (6 * area)


def polygon_bbox(vertices) -> np.ndarray:
    """Bounding box [[xmin, ymin], [xmax, ymax]] (the broad phase's (2, 2) box layout)."""
    v = _vertices(vertices)
    return np.array([v.min(axis=0), v.max(axis=0)])


def rotate(vertices, angle, about=None) -> np.ndarray:
    """Vertices rotated counter-clockwise by angle about a point (default: the centroid)."""
    v = np.asarray(vertices, dtype=float)
    c = polygon_centroid(v) if about is None else _point(about, "about")
    cs, sn = np.cos(angle), np.sin(angle)
    d = v - c
    return c + np.column_stack([cs * d[:, 0] - sn * d[:, 1], sn * d[:, 0] + cs * d[:, 1]])


def point_in_polygon(points, vertices) -> np.ndarray:
    """Crossing-number test, vectorised over points (m, 2) x edges: bool (m,).

    Points exactly on an edge may go either way; the callers first exclude boundary contact
    with segment_distance.
    """
    p = np.atleast_2d(np.asarray(points, dtype=float))
    v = _vertices(vertices)
    a, b = v, np.roll(v, -1, axis=0)
    py = p[:, 1:2]
    straddle = (a[None, :, 1] > py) != (b[None, :, 1] > py)
    dy = np.where(straddle, b[None, :, 1] - a[None, :, 1], 1.0)  # no 0/0 off the straddles
    x_cross = a[None, :, 0] + (py - a[None, :, 1]) * (b[None, :, 0] - a[None, :, 0]) / dy
    return (np.count_nonzero(straddle & (p[:, 0:1] < x_cross), axis=1) % 2) == 1


def _cross(u, v):
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def _point_segment(p, s0, s1):
    dx, dy = s1[..., 0] - s0[..., 0], s1[..., 1] - s0[..., 1]
    px, py = p[..., 0] - s0[..., 0], p[..., 1] - s0[..., 1]
    dd = dx * dx + dy * dy
    t = np.clip((px * dx + py * dy) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
    return np.hypot(px - t * dx, py - t * dy)


def segment_distance(a0, a1, b0, b1) -> np.ndarray:
    """Distance between segments [a0, a1] and [b0, b1], broadcast over leading axes (..., 2).

    Zero when they cross; otherwise the closest pair involves an endpoint of one segment, so
    the minimum of the four endpoint-to-segment distances is exact (touching and collinear
    overlaps give 0 through it).
    """
    a0, a1, b0, b1 = (np.asarray(x, dtype=float) for x in (a0, a1, b0, b1))
    d = np.minimum(
        np.minimum(_point_segment(a0, b0, b1), _point_segment(a1, b0, b1)),
        np.minimum(_point_segment(b0, a0, a1), _point_segment(b1, a0, a1)),
    )
    da, db = a1 - a0, b1 - b0
    crossing = (_cross(da, b0 - a0) * _cross(da, b1 - a0) < 0) & (
        _cross(db, a0 - b0) * _cross(db, a1 - b0) < 0
    )
    return np.where(crossing, 0.0, d)


def polygon_distance(P, Q, cutoff=np.inf) -> float:
    """Euclidean distance between two closed polygons; 0 when they touch, cross or nest.

    Exact below cutoff; a distance >= cutoff may be returned as inf (only the edges within
    cutoff of the other polygon's bounding box are compared, which keeps a packing check cheap).
    """
    P, Q = _vertices(P, "P"), _vertices(Q, "Q")
    # A vertex of one inside the other: they overlap (whether or not the boundaries cross).
    if point_in_polygon(P[:1], Q)[0] or point_in_polygon(Q[:1], P)[0]:
        return 0.0

    def near_edges(A, B):
        A1 = np.roll(A, -1, axis=0)
        lo, hi = B.min(axis=0) - cutoff, B.max(axis=0) + cutoff
        keep = np.all(np.minimum(A, A1) <= hi, axis=1) & np.all(np.maximum(A, A1) >= lo, axis=1)
        return A[keep], A1[keep]

    (p0, p1), (q0, q1) = near_edges(P, Q), near_edges(Q, P)
    if len(p0) == 0 or len(q0) == 0:
        return np.inf
    # Otherwise disjoint or crossing boundaries (distance 0 through segment_distance).
    return float(segment_distance(p0[:, None], p1[:, None], q0[None], q1[None]).min())


def min_separation(polygons, cutoff) -> float:
    """Smallest polygon_distance over the pairs closer than cutoff (inf if none), found by the
    broad phase on the bounding boxes inflated by cutoff / 2 (boxes of a pair closer than
    cutoff are closer than cutoff along each axis, so no such pair is missed)."""
    boxes = np.array([polygon_bbox(p) for p in polygons]).reshape(-1, 4)
    d = np.inf
    for i, j in _cpp.candidate_pairs(boxes, inflate=0.5 * float(cutoff)):
        d = min(d, polygon_distance(polygons[i], polygons[j], cutoff))
    return d


# ---------------------------------------------------------------------------------------------
# Fourier-descriptor grains


def fourier_modes(rng, elongation=0.0, roughness=0.0, n_modes=16, decay=2.0):
    """Amplitudes a_k and phases phi_k, k = 0..n_modes (a_0 = a_1 = 0), of a Fourier grain.

    a_2 = elongation with phi_2 = 0 (long axis along x; rotate to orient). For k >= 3,
    a_k = c k^-decay u_k, u_k ~ U(0.5, 1.5), phi_k ~ U(0, 2 pi), with c such that the RMS of
    the k >= 3 part of r / R - 1 over theta, sqrt(sum a_k^2 / 2), equals roughness. k = 1 is a
    translation and is left out. If elongation + sum_{k>=3} a_k > 1 - MIN_RADIUS_FRACTION the
    k >= 3 amplitudes are scaled down to meet it, so r >= 0.3 R everywhere (the roughness is
    then smaller than asked). The draws do not depend on elongation or roughness: one seed
    gives the same mode pattern at every elongation.
    """
    rng = np.random.default_rng(rng)
    n_modes = int(n_modes)
    if n_modes < 2:
        raise ValueError(f"n_modes: expected >= 2, got {n_modes}")
    budget = 1.0 - MIN_RADIUS_FRACTION
    if not (np.isfinite(elongation) and 0.0 <= elongation < budget):
        raise ValueError(f"elongation: expected 0 <= elongation < {budget}, got {elongation}")
    if not (np.isfinite(roughness) and roughness >= 0.0):
        raise ValueError(f"roughness: expected a finite value >= 0, got {roughness}")
    if not (np.isfinite(decay) and decay >= 0.0):
        raise ValueError(f"decay: expected a finite value >= 0, got {decay}")
    a = np.zeros(n_modes + 1)
    phi = np.zeros(n_modes + 1)
    a[2] = elongation
    k = np.arange(3, n_modes + 1)
    raw = k ** (-float(decay)) * rng.uniform(0.5, 1.5, size=k.size)
    phi[3:] = rng.uniform(0.0, 2 * np.pi, size=k.size)
    if k.size and roughness > 0:
        a[3:] = raw * roughness / np.sqrt(0.5 * np.sum(raw**2))
        total = a[3:].sum()
        if elongation + total > budget:
            a[3:] *= (budget - elongation) / total
    return a, phi


def fourier_outline(radius, amplitudes, phases, n_vertices=128) -> np.ndarray:
    """Counter-clockwise vertices r(theta_i) (cos, sin)(theta_i), theta_i = 2 pi i / n, with
    r = R (1 + sum_k a_k cos(k theta + phi_k)); polar origin at (0, 0).

    For 2 K < n (K the highest mode) the polygon's area is exactly
    (n / 2) sin(2 pi / n) R^2 (1 + sum_k a_k^2 cos(2 pi k / n) / 2)."""
    R = _positive(radius, "radius")
    a, phi = np.asarray(amplitudes, dtype=float), np.asarray(phases, dtype=float)
    n = int(n_vertices)
    if a.shape != phi.shape or a.ndim != 1:
        raise ValueError("amplitudes, phases: expected two 1D arrays of the same length")
    if n <= 2 * (a.size - 1) or n < 3:
        raise ValueError(f"n_vertices: expected > 2 n_modes = {2 * (a.size - 1)}, got {n}")
    theta = 2 * np.pi * np.arange(n) / n
    k = np.arange(a.size)
    r = R * (1.0 + (a[:, None] * np.cos(k[:, None] * theta[None] + phi[:, None]))[1:].sum(0))
    if r.min() <= 0:
        raise ValueError("amplitudes: r(theta) <= 0 somewhere; the outline is not star-shaped")
    return np.column_stack([r * np.cos(theta), r * np.sin(theta)])


def _star_shaped_about(v, c) -> bool:
    """Every edge turns counter-clockwise seen from c: each ray from c crosses the outline once."""
    d = v - c
    return bool(np.all(_cross(d, np.roll(d, -1, axis=0)) > 0))


def fourier_grain(
    rng,
    radius,
    elongation=0.0,
    roughness=0.0,
    n_modes=16,
    n_vertices=128,
    decay=2.0,
    center=(0.0, 0.0),
    return_modes=False,
):
    """Seeded sand-grain outline (see fourier_modes for the spectrum), centroid at `center`.

    rng: an int seed or a numpy Generator (reproducible from the seed). Returns the (n, 2)
    counter-clockwise vertices, or (vertices, amplitudes, phases) with return_modes. The
    polygon is star-shaped about the polar origin (r > 0.3 R at monotone angles); if it is not
    star-shaped about its centroid (possible for a rough, very elongated grain), the k >= 3
    amplitudes are scaled by 0.8 until it is (the returned amplitudes are the ones used).
    """
    a, phi = fourier_modes(rng, elongation, roughness, n_modes, decay)
    for _ in range(60):
        v = fourier_outline(radius, a, phi, n_vertices)
        c = polygon_centroid(v)
        if _star_shaped_about(v, c):
            break
        a[3:] *= 0.8
    else:  # pragma: no cover - a pure k = 2 outline is centrally symmetric about the origin
        raise RuntimeError("fourier_grain: no star-shaped outline about the centroid")
    v = v - c + _point(center, "center")
    return (v, a, phi) if return_modes else v


# ---------------------------------------------------------------------------------------------
# Packing


def pack_grains(outlines, box, gap=0.0, rng=None, max_tries=1000, wall_gap=None):
    """Random sequential addition of the given outlines, each rotated by a random angle and
    translated to a random position in box = [[x0, y0], [x1, y1]].

    No two grains end up closer than gap (distance > 0 when gap = 0), and every grain keeps
    wall_gap (default gap) from the box sides. Grains are placed largest first (fewer failed
    tries) and returned in input order. Each trial is checked against the placed grains whose
    boxes, inflated by gap / 2, overlap its box (_cpp.candidate_pairs_between), with the exact
    polygon_distance. Raises ValueError naming the box when the total area exceeds the box or
    a grain is not placed after max_tries trials.
    """
    rng = np.random.default_rng(rng)
    bx = np.asarray(box, dtype=float)
    if bx.shape != (2, 2) or not np.all(np.isfinite(bx)) or np.any(bx[1] <= bx[0]):
        raise ValueError(f"box: expected [[x0, y0], [x1, y1]] with x1 > x0, y1 > y0, got {box!r}")
    gap = float(gap)
    if not (np.isfinite(gap) and gap >= 0):
        raise ValueError(f"gap: expected a finite value >= 0, got {gap}")
    wall_gap = gap if wall_gap is None else float(wall_gap)
    if not (np.isfinite(wall_gap) and wall_gap >= 0):
        raise ValueError(f"wall_gap: expected a finite value >= 0, got {wall_gap}")
    if int(max_tries) < 1:
        raise ValueError(f"max_tries: expected >= 1, got {max_tries}")
    local = []
    for i, v in enumerate(outlines):
        v = _vertices(v, f"outlines[{i}]")
        local.append(v - polygon_centroid(v))
    areas = np.array([abs(polygon_area(v)) for v in local])
    box_area = float(np.prod(bx[1] - bx[0]))
    if areas.sum() > box_area:
        raise ValueError(
            f"box {bx.tolist()}: area {box_area:.4g} is smaller than the grains' {areas.sum():.4g}"
        )
    lo_box, hi_box = bx[0] + wall_gap, bx[1] - wall_gap

    placed = [None] * len(local)
    boxes = np.empty((0, 4))
    ids = []  # grain index of each row of boxes
    for i in np.argsort(-areas, kind="stable"):
        for _ in range(int(max_tries)):
            w = rotate(local[i], rng.uniform(0.0, 2 * np.pi), about=(0.0, 0.0))
            lo = lo_box - w.min(axis=0)
            hi = hi_box - w.max(axis=0)
            if np.any(hi < lo):
                continue  # this orientation does not fit between the walls
            trial = w + rng.uniform(lo, hi)
            tb = polygon_bbox(trial).reshape(1, 4)
            cand = _cpp.candidate_pairs_between(tb, boxes, inflate=0.5 * gap)[:, 1]
            if all(
                (d := polygon_distance(trial, placed[ids[j]], gap)) >= gap and d > 0 for j in cand
            ):
                break
        else:
            raise ValueError(
                f"box {bx.tolist()}: grain {i} ({len(ids)} of {len(local)} placed) does not fit "
                f"with gap {gap} after {max_tries} tries (area fraction "
                f"{areas.sum() / box_area:.2f}); use a larger box, a smaller gap or more tries"
            )
        placed[i] = trial
        boxes = np.vstack([boxes, tb])
        ids.append(i)
    return placed


def lattice_boxes(n, rng):
    """(n, 2, 2) bounding boxes of grains of radius 0.35-0.5 on a jittered unit lattice in a
    square, in random order: the broad phase's test and benchmark input (n a square)."""
    m = int(round(np.sqrt(n)))
    ij = np.stack(np.meshgrid(np.arange(m), np.arange(m)), -1).reshape(-1, 2).astype(float)
    c = ij + rng.uniform(-0.05, 0.05, size=ij.shape)
    r = rng.uniform(0.35, 0.5, size=(len(c), 1))
    b = np.stack([c - r, c + r], axis=1)
    return b[rng.permutation(len(b))]


def _main(argv=None):
    import argparse
    import time

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, default=25, help="number of grains")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--fraction", type=float, default=0.4, help="target area fraction")
    args = p.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    grains = [
        fourier_grain(rng, 1.0, rng.uniform(0.0, 0.3), rng.uniform(0.0, 0.05))
        for _ in range(args.n)
    ]
    side = np.sqrt(sum(polygon_area(g) for g in grains) / args.fraction)
    t0 = time.perf_counter()
    packed = pack_grains(grains, [[0, 0], [side, side]], gap=0.05, rng=rng)
    dt = time.perf_counter() - t0
    print(
        f"{args.n} grains in a {side:.3f} square box, gap 0.05: packed in {dt:.2f} s, "
        f"min separation {min_separation(packed, 0.5):.4f}"
    )


if __name__ == "__main__":
    _main()
