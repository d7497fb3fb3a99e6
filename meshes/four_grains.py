"""Four grains under isotropic compression (paper 5.2.3): the scene of demos/four_grains.py.

One seeded Fourier grain outline (meshes.grains.fourier_grain) is used four times, scaled,
rotated and translated, on a 2 x 2 arrangement inside four deformable plates:

    grain2 (upper left)   grain3 (upper right)
    grain0 (lower left)   grain1 (lower right)

Every contact starts closed with the same overlap (a grain whose contacts are all open at the
first Newton iteration is free and the step fails). The overlap of two grains is the
translation along their line of centres that separates them (found by bisection on the exact
polygon distance, meshes.grains.polygon_distance); with a plate it is the penetration across the
plate's inner face. Construction: grain0 fixes the left and bottom faces; grain1 (on the bottom
face) and grain2 (on the left face) slide towards grain0 until the overlap is reached and fix the
right and top faces; grain3 is then pinned in the upper-right corner by those two faces, and its
two contacts with grain1 and grain2 close the loop: two more conditions, met by solving for
grain3's scale and rotation (hybrid Powell from the given ones). Not every seed and set of scales
has a solution: grain3 must fit the corner left by the others (discs of scales 1, 0.8 and 0.9 need
a fourth of scale 1.1, so grain3 comes out about as large as grain0).
"""

from __future__ import annotations

import numpy as np

import dolfinx_forms as df

from .grains import fourier_grain, polygon, polygon_centroid, polygon_distance, rotate
from .mpm import grid_scene, uniform_lines

#: scale factors of the mean radius: lower left, lower right, upper left, upper right (initial
#: guess: it is solved for) and the rotations (radians); grain3's rotation is solved for too
SCALES = (1.0, 0.8, 0.9, 1.0)
ANGLES = (0.35, 2.1, 4.2, 0.8)
ELONGATION, ROUGHNESS = 0.15, 0.03


def _apart(A, B):
    # only whether the distance is > 0: a small cutoff skips the far edges (inf beyond it)
    return polygon_distance(A, B, cutoff=1e-2) > 0


def overlap(A, B, direction=None, tol=1e-13):
    """Translation of B along `direction` (default: A's centroid -> B's centroid) that separates
    it from A: > 0 when they overlap, < 0 (minus the approach to touch) when apart. Bisection on
    the exact polygon distance to tol (mm)."""
    u = polygon_centroid(B) - polygon_centroid(A) if direction is None else np.asarray(direction)
    u = u / np.linalg.norm(u)
    size = np.ptp(np.vstack([A, B]), axis=0).max()
    if _apart(A, B):  # apart at 0: find a t < 0 where they overlap
        lo, hi = -max(polygon_distance(A, B), 1e-9 * size), 0.0
        while _apart(A, B + lo * u):
            lo *= 2
            if lo < -size:
                raise ValueError("overlap: the polygons do not meet along the direction")
    else:
        lo, hi = 0.0, 1e-6 * size
        while not _apart(A, B + hi * u):
            hi *= 2
            if hi > size:
                raise ValueError("overlap: the polygons do not separate along the direction")
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if _apart(A, B + mid * u) else (mid, hi)
    return 0.5 * (lo + hi)


def _slide(A, B, axis, target, tol):
    """B moved along `axis` (towards A from its far side) so that overlap(A, B) = target."""
    from scipy.optimize import brentq

    e = np.eye(2)[axis]
    side = np.sign(polygon_centroid(B)[axis] - polygon_centroid(A)[axis])
    # from just touching along the axis (overlap(A, B, e) = t) outwards by 2 target
    t = overlap(A, B, side * e)
    f = lambda s: overlap(A, B + (t + s) * side * e) - target  # noqa: E731
    s = brentq(f, -4 * target - 1e-3, 2 * target + 1e-3, xtol=tol, rtol=4 * np.finfo(float).eps)
    return B + (t + s) * side * e


def grain_outlines(radius=2.0, seed=1, overlap_=1e-3, n_vertices=128, tol=1e-12):
    """The four grain outlines [(n, 2)] and the plates' inner faces (x_left, x_right,
    y_bottom, y_top), centred on the origin, every contact overlapping by overlap_ (module
    docstring). Raises ValueError naming the seed when grain3 cannot close the loop."""
    from scipy.optimize import root

    base = fourier_grain(int(seed), 1.0, ELONGATION, ROUGHNESS, n_vertices=n_vertices)

    def grain(k, s=None, angle=None):  # scaled and rotated about its centroid, the origin
        s = SCALES[k] if s is None else s
        return rotate(radius * s * base, ANGLES[k] if angle is None else angle, about=(0, 0))

    ov = float(overlap_)
    g0 = grain(0)
    x_left, y_bottom = g0[:, 0].min() + ov, g0[:, 1].min() + ov
    g1 = grain(1)
    g1 = g1 + [g0[:, 0].max() - g1[:, 0].min(), y_bottom - ov - g1[:, 1].min()]
    g1 = _slide(g0, g1, 0, ov, tol)
    g2 = grain(2)
    g2 = g2 + [x_left - ov - g2[:, 0].min(), g0[:, 1].max() - g2[:, 1].min()]
    g2 = _slide(g0, g2, 1, ov, tol)
    x_right, y_top = g1[:, 0].max() - ov, g2[:, 1].max() - ov

    def corner(z):  # grain3 of scale z[0], rotation z[1], in the upper-right corner
        g = grain(3, z[0], z[1])
        return g + [x_right + ov - g[:, 0].max(), y_top + ov - g[:, 1].max()]

    def residual(z):
        try:
            g = corner(z)
            return [(overlap(g1, g) - ov) / ov, (overlap(g2, g) - ov) / ov]
        except ValueError:  # far from a solution: a large residual steers the solver back
            return [1e6, 1e6]

    # grain3's scale and rotation (hybrid Powell; the two overlaps are smooth in both while
    # the contact points stay on the same edges)
    z = root(residual, [SCALES[3], ANGLES[3]], method="hybr", options=dict(xtol=1e-13)).x
    err = np.abs(residual(z)).max() * ov
    if not (err < 1e-9 and 0.4 < z[0] < 1.5):
        raise ValueError(
            f"four_grains: seed {seed}: the upper-right grain does not close the 2 x 2 loop "
            f"(overlap error {err:.1e} mm, scale {z[0]:.3g}); try another seed"
        )
    g3 = corner(z)
    gs = [g0, g1, g2, g3]
    # the non-neighbours (diagonals) stay apart
    for i, j in ((0, 3), (1, 2)):
        if polygon_distance(gs[i], gs[j]) < 0.1 * radius:
            raise ValueError(
                f"four_grains: seed {seed}: grains {i} and {j} (diagonal) come within 0.1 radius"
            )
    c = np.array([0.5 * (x_left + x_right), 0.5 * (y_bottom + y_top)])
    faces = (x_left - c[0], x_right - c[0], y_bottom - c[1], y_top - c[1])
    return [g - c for g in gs], faces, float(z[0]), float(z[1])


def check_contact_zones(grains, faces, h, overlap, clearance):
    """Raise ValueError unless each grain's contact zone on a plate (its vertices within the
    contact band 2 h of the face) lies on the plate, which ends `clearance` short of the
    perpendicular plates' inner faces: a zone running off the plate's end meets its corner,
    where the closest-point projection onto the plate's level set can fail."""
    xl, xr, yb, yt = faces
    plates = (
        ("plate_left", 0, xl, (0, 2)),
        ("plate_right", 0, xr, (1, 3)),
        ("plate_bottom", 1, yb, (0, 1)),
        ("plate_top", 1, yt, (2, 3)),
    )
    for name, axis, face, ids in plates:
        lo, hi = (yb, yt) if axis == 0 else (xl, xr)
        for i in ids:
            near = grains[i][np.abs(grains[i][:, axis] - face) < 2 * h + overlap, 1 - axis]
            if near.min() < lo + clearance or near.max() > hi - clearance:
                raise ValueError(
                    f"four_grains: grain{i}'s contact zone (band 2 h = {2 * h:g}) runs off the "
                    f"end of {name}"
                )


def four_grains(
    comm,
    h=0.1,
    radius=2.0,
    seed=1,
    overlap=1e-3,
    thickness=1.0,
    clearance=0.25,
    margin=None,
    outlines=None,
):
    """The four grains (grain_outlines) and four plates of thickness `thickness` (rounded up so
    their outer faces lie on grid lines: Dirichlet conditions act on grid nodes there, the
    `outer_faces`). Each plate spans the gap between the two perpendicular plates' inner faces
    less `clearance` at both ends (the plates never touch each other). outlines: the result of
    grain_outlines (recomputed if None). Returns (grid lines, [(name, tag, shape)],
    build_scene, outer_faces {plate name: (axis, coordinate)})."""
    gs, (xl, xr, yb, yt), *_ = outlines or grain_outlines(radius, seed, overlap)
    margin = 3 * h if margin is None else margin
    lines = uniform_lines(min(xl, yb) - thickness - margin, max(xr, yt) + thickness + margin, h)

    # the outer faces: the grid lines at least `thickness` beyond the inner faces
    def line(v, outward):
        i = (v - lines[0]) / h
        return lines[int(np.floor(i + 1e-9) if outward < 0 else np.ceil(i - 1e-9))]

    o_l, o_r = line(xl - thickness, -1), line(xr + thickness, 1)
    o_b, o_t = line(yb - thickness, -1), line(yt + thickness, 1)
    plates = {
        "plate_left": (df.Box((o_l, yb + clearance), (xl, yt - clearance)), (0, o_l)),
        "plate_right": (df.Box((xr, yb + clearance), (o_r, yt - clearance)), (0, o_r)),
        "plate_bottom": (df.Box((xl + clearance, o_b), (xr - clearance, yb)), (1, o_b)),
        "plate_top": (df.Box((xl + clearance, yt), (xr - clearance, o_t)), (1, o_t)),
    }
    check_contact_zones(gs, (xl, xr, yb, yt), h, overlap, clearance)
    bodies = [(f"grain{i}", i + 1, polygon(g)) for i, g in enumerate(gs)]
    for m, (name, (shape, _)) in enumerate(plates.items()):
        bodies.append((name, 10 + m, shape))
    build = grid_scene(comm, lines, lines, [(b[0], b[1]) for b in bodies], contact_box=False)
    return (lines, lines), bodies, build, {name: face for name, (_, face) in plates.items()}


def checked_outlines(radius, seed, h, overlap, clearance, travel):
    """The options of demos/four_grains.py checked, then grain_outlines(radius, seed, overlap)
    (numpy only, ~0.5 s: before any output); a ValueError names the option: seed in [0, 2^31),
    5 <= radius/h <= 200, overlap <= h/2, the plates' total travel <= 0.05 radius, a seed
    whose arrangement closes, contact zones on the plates (check_contact_zones)."""
    if not 0 <= seed < 2**31:
        raise ValueError(f"--seed: must be in [0, 2^31), got {seed}")
    if not 5 <= radius / h <= 200:
        raise ValueError(f"--h: must give 5 <= radius/h <= 200 (radius {radius:g}), got {h}")
    if not overlap <= 0.5 * h:
        raise ValueError(f"--overlap: must be in (0, h/2] = (0, {0.5 * h:g}], got {overlap}")
    if not travel <= 0.05 * radius:
        raise ValueError(
            f"--displacement: steps x displacement must be <= 0.05 radius = {0.05 * radius:g}"
        )
    try:
        outlines = grain_outlines(radius, seed, overlap)
    except ValueError as e:
        raise ValueError(f"--seed: {e}") from None
    try:
        check_contact_zones(*outlines[:2], h, overlap, clearance)
    except ValueError as e:
        raise ValueError(f"--h: {e}") from None
    return outlines
