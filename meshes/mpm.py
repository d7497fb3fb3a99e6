"""Scenes of the implicit MPM on one uniform background grid (`grid_scene`, `uniform_lines`:
dolfinx_forms.mesh.grid_scene, re-exported here). The Brazilian-disc set-up (paper 5.3.1): a
disc between two rigid half-plane platens, with the checks of its demo's options; the nine discs
in four plates (5.2.1), with the D4 symmetry check of the answer (d4_symmetry_error).
"""

from __future__ import annotations

import numpy as np

import dolfinx_forms as df
from dolfinx_forms.fem.boundary import Dirichlet
from dolfinx_forms.geometry.obstacles import RigidObstacle
from dolfinx_forms.mesh.cut_scene import half_plane
from dolfinx_forms.mesh.grid_scene import grid_scene, uniform_lines  # noqa: F401  (re-exported)


def brazilian_disc(comm, R=10.0, h=0.2, step_displacement=0.02, steps=50, margin=None):
    """The Brazilian disc of the paper (5.3.1): a disc of radius R centred at the origin between
    a fixed lower platen (y < -R) and an upper one (y > R) moved down by step_displacement per
    step. Returns (grid lines, [MPMBody args], obstacles, build_scene). The grid covers the
    disc with `margin` (default 3 h + the total platen travel) and has a line at x = 0 (the
    symmetry line of the u_x = 0 condition)."""
    margin = 3 * h + step_displacement * steps if margin is None else margin
    xl = uniform_lines(-R - margin, R + margin, h)
    yl = uniform_lines(-R - margin, R + margin, h)
    top, bottom = disc_platens(R, step_displacement)
    zone = 0.25 * R + 4 * h  # where the contact zones can be: kept on rank 0
    box = np.array(
        [[[-zone, R - zone], [zone, R + margin]], [[-zone, -R - margin], [zone, -R + zone]]]
    )
    build = grid_scene(comm, xl, yl, [("disc", 1)], contact_box=box)
    return (xl, yl), ("disc", 1, df.Circle((0.0, 0.0), R)), [top, bottom], build


def disc_platens(R, step_displacement):
    """The rigid half planes y > R (moved down by step_displacement per step) and y < -R
    (fixed) about a disc of radius R centred at the origin: [top, bottom]."""
    ext = 100 * R
    top = RigidObstacle(
        "platen_top",
        half_plane((0.0, R), (0.0, -1.0), ext),
        bbox=[[-2 * R, R], [2 * R, 2 * R]],
        center=(0.0, R),
        translation=(0.0, -step_displacement),
    )
    bottom = RigidObstacle(
        "platen_bottom",
        half_plane((0.0, -R), (0.0, 1.0), ext),
        bbox=[[-2 * R, -2 * R], [2 * R, -R]],
        center=(0.0, -R),
    )
    return [top, bottom]


def check_brazilian_disc(R, h, steps, step_displacement):
    """ValueError (its message names the option) unless the grid has 10 to 4000 cells across
    the disc, the platens' total travel stays within R and one step within h/2."""
    if not h <= R / 5:
        raise ValueError(
            f"--h: must be in (0, R/5] = (0, {R / 5:g}] (at least 10 cells across), got {h}"
        )
    if not R / h <= 2000:
        raise ValueError(
            f"--h: must be >= R/2000 = {R / 2000:g} (grid of at most 4000^2 cells), got {h}"
        )
    if not steps * step_displacement <= R:
        raise ValueError(
            f"--step-displacement: steps x step must be <= R = {R:g} (the platens' travel: "
            f"half the diameter), got {steps * step_displacement:g}"
        )
    if not step_displacement <= 0.5 * h:
        raise ValueError(
            f"--step-displacement: must be <= h/2 = {0.5 * h:g} per step (contact band "
            f"and level-set advection), got {step_displacement}"
        )


def disc_column(comm, n=5, R=10.0, h=0.5, step_displacement=0.05, steps=20, margin=None):
    """n identical discs of radius R stacked on x = 0 (centres 2 R k, k = 0..n-1, touching)
    between a fixed lower platen (y < -R) and an upper one (y > (2 n - 1) R) moved down by
    step_displacement per step. Returns (grid lines, [(name, tag, shape)], obstacles,
    build_scene); body-body pairs come from the simulation's broad phase."""
    margin = 3 * h + step_displacement * steps if margin is None else margin
    top_y = (2 * n - 1) * R
    xl = uniform_lines(-R - margin, R + margin, h)
    yl = uniform_lines(-R - margin, top_y + margin, h)
    ext = 100 * n * R
    top = RigidObstacle(
        "platen_top",
        half_plane((0.0, top_y), (0.0, -1.0), ext),
        bbox=[[-2 * R, top_y], [2 * R, top_y + R]],
        center=(0.0, top_y),
        translation=(0.0, -step_displacement),
    )
    bottom = RigidObstacle(
        "platen_bottom",
        half_plane((0.0, -R), (0.0, 1.0), ext),
        bbox=[[-2 * R, -2 * R], [2 * R, -R]],
        center=(0.0, -R),
    )
    bodies = [(f"disc{k}", k + 1, df.Circle((0.0, 2 * R * k), R)) for k in range(n)]
    build = grid_scene(comm, xl, yl, [(b[0], b[1]) for b in bodies], contact_box=False)
    return (xl, yl), bodies, [top, bottom], build


def nine_discs(comm, R=1.7, plate=(1.0, 9.8), h=0.1, overlap=1e-3, margin=None):
    """Nine discs of radius R on a 3 x 3 lattice of spacing 2 R - overlap, confined by four
    deformable plates of thickness plate[0] and length plate[1] whose inner faces overlap the
    outer discs by `overlap` (paper 5.2.1: "the discs are compressed [by the fixed plates]
    since there are initial gaps": touching bodies whose contacts are all open at the first
    Newton iteration leave the discs free, so every contact starts closed). The plates' outer
    faces lie on grid lines (Dirichlet conditions on grid nodes there: `outer_faces`); the
    grid is symmetric under the square's symmetry group. Returns (grid lines,
    [(name, tag, shape)], build_scene, outer_faces {plate name: (axis, coordinate)})."""
    t, length = plate
    pitch = 2 * R - overlap
    inner = pitch + R - overlap
    R_grid = 3 * R  # the outer faces: 3 R + t, a grid line
    k = int(round((R_grid + t) / h))
    if abs(k * h - (R_grid + t)) > 1e-9 * (R_grid + t):
        raise ValueError(
            f"nine_discs: h must divide 3 R + thickness = {R_grid + t:g} (the plates' outer "
            f"faces lie on grid lines), got h = {h:g}"
        )
    margin = 3 * h if margin is None else margin
    n = k + int(np.ceil(margin / h))
    lines = h * np.arange(-n, n + 1, dtype=float)
    outer = lines[n + k]  # the grid line at 3 R + t, exactly
    bodies = [
        (f"disc{3 * j + i}", 3 * j + i + 1, df.Circle((pitch * (i - 1), pitch * (j - 1)), R))
        for j in range(3)
        for i in range(3)
    ]
    half = 0.5 * length
    plates = {
        "plate_left": (df.Box((-outer, -half), (-inner, half)), (0, -outer)),
        "plate_right": (df.Box((inner, -half), (outer, half)), (0, outer)),
        "plate_bottom": (df.Box((-half, -outer), (half, -inner)), (1, -outer)),
        "plate_top": (df.Box((-half, inner), (half, outer)), (1, outer)),
    }
    for m, (name, (shape, _)) in enumerate(plates.items()):
        bodies.append((name, 10 + m, shape))
    build = grid_scene(comm, lines, lines, [(b[0], b[1]) for b in bodies], contact_box=False)
    return (lines, lines), bodies, build, {name: face for name, (_, face) in plates.items()}


#: the symmetry group of the square (nine_discs): 4 rotations, 4 reflections
D4 = [
    np.array(m, float)
    for m in (
        [[1, 0], [0, 1]],
        [[0, -1], [1, 0]],
        [[-1, 0], [0, -1]],
        [[0, 1], [-1, 0]],
        [[-1, 0], [0, 1]],
        [[1, 0], [0, -1]],
        [[0, 1], [1, 0]],
        [[0, -1], [-1, 0]],
    )
]


def d4_symmetry_error(sim, rec, h):
    """Largest relative differences of the nine-disc scene's answer under D4: contact forces
    (by the contact's centre) and the stress at the material points (by position: their images
    within 1e-4 h; from step 2 on the points move with a field that is D4-symmetric only to the
    MLS projection's error). Returns (forces, stresses, largest distance of a contact centre's
    image to a centre, fraction of the points compared)."""
    from scipy.spatial import cKDTree

    act = [q for q in rec["pairs"] if q["normal_force"] > 0]
    c = np.array([[q["x"], q["y"]] for q in act])
    fn = np.array([q["normal_force"] for q in act])
    ft = np.abs([q["tangential_force"] for q in act])
    x = np.concatenate([p.x for p in sim.points.values()])
    s = np.concatenate([p.stress for p in sim.points.values()])
    S = np.stack([np.stack([s[:, 0], s[:, 2]], 1), np.stack([s[:, 2], s[:, 1]], 1)], 1)
    tc, tx = cKDTree(c), cKDTree(x)
    e_f = e_s = e_x = 0.0
    n_same = len(x)
    for G in D4:
        d, k = tc.query(c @ G.T)
        e_x = max(e_x, d.max())
        e_f = max(e_f, np.max(np.abs(fn[k] - fn)), np.max(np.abs(ft[k] - ft)))
        # stresses at the points whose image is a point: those of the interior cells' tensor
        # Gauss rule (the cut cells' sub-triangle rule is not D4-invariant)
        d, k = tx.query(x @ G.T)
        same = d < 1e-4 * h
        Sg = np.einsum("ab,nbc,dc->nad", G, S, G)
        e_s = max(e_s, np.max(np.abs(S[k[same]] - Sg[same]), initial=0.0))
        n_same = min(n_same, int(same.sum())) if G is not D4[0] else int(same.sum())
    return e_f / fn.max(), e_s / np.abs(S).max(), e_x, n_same / len(x)


def plate_face_conditions(faces, displacement):
    """Dirichlet conditions moving each plate's outer face (faces {name: (axis, coordinate)},
    a grid line) inward by `displacement` per step, normal component only (the face's
    tangential motion is free)."""
    return [
        Dirichlet(
            lambda x, a=axis, c=c: np.isclose(x[a], c, rtol=0, atol=1e-9 * abs(c)),
            axis,
            -np.sign(c) * displacement,
        )
        for axis, c in faces.values()
    ]


def plate_forces(record):
    """The four plates' compressive forces (positive inward) of an ImplicitMPM step record:
    the steps.csv columns force_left, force_right, force_bottom, force_top."""
    f = record["body_forces"]
    return dict(
        force_left=-f["plate_left"][0],
        force_right=f["plate_right"][0],
        force_bottom=-f["plate_bottom"][1],
        force_top=f["plate_top"][1],
    )


def block_between_platens(comm, width=2.0, height=2.0, h=0.1, compression=0.4, steps=20):
    """A width x height block centred at the origin between two frictionless rigid half-plane
    platens wider than it, the lower fixed (y < -height/2), the upper (y > height/2) moved down
    by compression x height / steps per step. Returns (grid lines, (name, tag, shape),
    obstacles, build_scene). The grid has lines at x = 0 (the u_x = 0 symmetry condition) and
    y = 0 (the mid-height width) and room for a lateral stretch of 2.5."""
    W, H = float(width), float(height)
    d = compression * H / steps
    xl = uniform_lines(-1.25 * W - 3 * h, 1.25 * W + 3 * h, h)
    yl = uniform_lines(-0.5 * H - 3 * h, 0.5 * H + 3 * h, h)
    ext, X = 100 * max(W, H), xl[-1] - xl[0]
    top = RigidObstacle(
        "platen_top",
        half_plane((0.0, 0.5 * H), (0.0, -1.0), ext),
        bbox=[[-X, 0.5 * H], [X, H]],
        center=(0.0, 0.5 * H),
        translation=(0.0, -d),
    )
    bottom = RigidObstacle(
        "platen_bottom",
        half_plane((0.0, -0.5 * H), (0.0, 1.0), ext),
        bbox=[[-X, -H], [X, -0.5 * H]],
        center=(0.0, -0.5 * H),
    )
    box = np.array([[[xl[0], yl[0]], [xl[-1], yl[-1]]]])  # one rank computes both contacts
    build = grid_scene(comm, xl, yl, [("block", 1)], contact_box=box)
    shape = df.Box([-0.5 * W, -0.5 * H], [0.5 * W, 0.5 * H])
    return (xl, yl), ("block", 1, shape), [top, bottom], build


def check_block(width, height, h, compression, steps):
    """ValueError (its message names the option) unless the grid has 8 to 2000 cells across
    the block's smaller side and one step moves the platen by at most h."""
    side = min(width, height)
    if not side / 2000 <= h <= side / 8:
        raise ValueError(
            f"--h: must be in [{side / 2000:g}, {side / 8:g}] (8 to 2000 cells across the "
            f"block's smaller side), got {h}"
        )
    if not compression * height / steps <= h * (1 + 1e-12):
        raise ValueError(
            f"--steps: the platen must move at most h per step (contact band and level-set "
            f"advection): need steps >= {int(np.ceil(compression * height / h - 1e-9))}, "
            f"got {steps}"
        )


def width_at(levelset, y):
    """The extent of the zero contour of a grid level set along its grid line through y
    (outermost sign changes, linear between nodes)."""
    xlines, ylines = np.asarray(levelset.grid.x), np.asarray(levelset.grid.y)
    j = int(np.argmin(np.abs(ylines - y)))
    phi = np.asarray(levelset.values).reshape(len(ylines), len(xlines))[j]
    inside = np.flatnonzero(phi <= 0)
    if len(inside) == 0:
        return 0.0
    i0, i1 = inside[0], inside[-1]
    xl = np.asarray(xlines)
    left = (
        xl[i0]
        if i0 == 0
        else xl[i0 - 1] + (xl[i0] - xl[i0 - 1]) * phi[i0 - 1] / (phi[i0 - 1] - phi[i0])
    )
    right = (
        xl[i1]
        if i1 == len(xl) - 1
        else xl[i1] + (xl[i1 + 1] - xl[i1]) * phi[i1] / (phi[i1] - phi[i1 + 1])
    )
    return float(right - left)


def flat_punch(comm, a=1.0, h=0.05, radius=7.0):
    """A rigid flat punch of half-width a (a box [-a, a] x [0, 2a], sharp corners: its exact
    signed distance) on an elastic half-space modelled as the half-disc y < 0 of radius
    `radius` a, whose arc is fixed (the grid nodes within 3h/4 of it). Returns (grid lines,
    (name, tag, shape), punch, fixed-arc Dirichlet, build_scene). The half-disc's top lies
    mid-way between grid lines (y lines at (k + 1/2) h); x lines at k h."""
    R = radius * a
    xl = uniform_lines(-R - 3 * h, R + 3 * h, h)
    yl = uniform_lines(-R - 3 * h, 2 * a, h) + 0.5 * h
    shape = df.Intersection([df.Circle((0.0, 0.0), R), half_plane((0, 0), (0, 1), 100 * R)])
    punch = RigidObstacle(
        "punch", df.Box([-a, 0.0], [a, 2 * a]), bbox=[[-a, 0.0], [a, 2 * a]], center=(0.0, 0.0)
    )
    fixed = Dirichlet(lambda x: x[0] ** 2 + x[1] ** 2 >= (R - 0.75 * h) ** 2, None, 0.0)
    box = np.array([[[-2 * a, -a], [2 * a, 2 * a]]])  # the contact zone, on one rank
    build = grid_scene(comm, xl, yl, [("halfspace", 1)], contact_box=box)
    return (xl, yl), ("halfspace", 1, shape), punch, fixed, build


def cylinder_on_floor(comm, R=1.0, h=0.1, travel=2.0, drop=0.0, name="cylinder"):
    """A cylinder of radius R `drop` above a rigid floor (the half-plane y < 0; drop 0: resting
    on it, touching at the origin) with room to roll `travel` along +x. The incline is the floor
    with gravity turned by theta (the rolling demo's frame: x along the incline). Returns (grid
    lines, (name, tag, shape), floor, build_scene); the floor lies mid-way between grid lines."""
    xl = uniform_lines(-R - 3 * h, R + travel + 3 * h, h)
    yl = uniform_lines(-3 * h, 2 * R + drop + 3 * h, h) + 0.5 * h
    far = 100 * (R + travel)
    floor = RigidObstacle(
        "floor", half_plane((0.0, 0.0), (0.0, 1.0), far), bbox=[[-far, -R], [far, 0.0]]
    )
    box = np.array([[[xl[0], yl[0]], [xl[-1], yl[-1]]]])  # the contact, on one rank
    build = grid_scene(comm, xl, yl, [(name, 1)], contact_box=box)
    return (xl, yl), (name, 1, df.Circle((0.0, R + drop), R)), floor, build
