"""Hertz scene: a half-cylinder (or half-ellipse) resting on a block (plane strain), touching
at one point.

Geometry (any consistent units):
  body 0 "block"    (tag 1): rectangle [-width/2, width/2] x [-depth, 0]
  body 1 "cylinder" (tag 2): lower half-ellipse {(x/R)^2 + ((y-Ry)/Ry)^2 <= 1, y <= Ry}, semi-
                             axis R horizontal and Ry vertical (default Ry = R: the half-disc
                             of radius R); flat face y = Ry on top (width 2R), its arc touches
                             the block top at the origin, where its curvature radius is R^2/Ry.
Both outlines have a vertex at the origin (two distinct vertices, gap 0 there). The arc is a
gmsh circle arc (Ry = R) or ellipse arc (nodes exactly on the circle / ellipse). In the zone
|x|, |y| <= zone (both bodies) h is an upper bound: every edge of a cell inside the zone is
<= 1.05 h. Quads: the zone is a structured grid (spacing <= h, ~0.95 h, the origin a grid
vertex), the rest is meshed at 2h, recombined and subdivided (all quads); triangles:
unstructured with gmsh target ~0.75 h (mean edge ~0.75 h), shrunk and remeshed if an edge
exceeds 1.05 h.
Outside the zone the size grows linearly with slope 0.25 up to h_far (default
min(R, Ry, depth)/8). mesher="layers" (triangles only, no gmsh): nested layers around the
origin (meshes/layers.py), h / sqrt(2) apart on the zone (the block's cells halves of squares,
edges h / sqrt(2) and h), the spacing growing by 1 + growth per layer outside, up to h_far.
The zone must lie inside both bodies: zone < min(R, Ry, width/2, depth), and the arc below
y = zone at x = +-zone (ValueError otherwise, on every rank).
Boundaries (facet tags): block_bottom=1, block_sides=2, block_top=3, cylinder_top=4, cylinder_arc=5.
pairs = [(0, 1)]; the contact box [-1.5 zone, 1.5 zone]^2 (clipped to the scene) is on rank 0.
Run: /usr/bin/python3 -m meshes.hertz [--h 0.05] [--quads] [--R 10] [--Ry 6] [--layers]
     (from the repository root)
"""

from __future__ import annotations

import numpy as np

from dolfinx_forms.mesh.scene import (
    Body,
    Scene,
    extract_gmsh,
    gmsh_model,
    max_edge_in_box,
    scene_from_arrays,
    scene_from_gmsh,
    summary,
)

GROWTH = 0.25  # mesh size slope outside the zone
MESHERS = ("gmsh", "layers")


def hertz_contact_box(R=10.0, width=40.0, depth=20.0, zone=1.5, Ry=None, band=None, h=None):
    """The cells owned by rank 0, where the contact geometry is computed: the strip where the
    initial gap is at most `band` (the contact problem's, default the gap at x = 1.5 zone),
    |x| <= x_band and 0 <= y <= band, inflated by dolfinx_forms.mesh.scene.CONTACT_BOX_MARGIN h
    (default h: zone / 10) and clipped to the bounding box of the two bodies (Ry: the indenter's
    vertical semi-axis, default R). Only the strip: the fine zone below and above it goes to
    the other ranks (a square around the zone held 91 % of the dofs at a/20 on 2 ranks)."""
    from dolfinx_forms.mesh.scene import CONTACT_BOX_MARGIN

    top = R if Ry is None else Ry
    band = ellipse_sag(R, top, min(1.5 * zone, R)) if band is None else float(band)
    # the abscissa where the arc's gap reaches the band (the whole arc if above its height)
    x = R if band >= top else R * np.sqrt(1.0 - (1.0 - band / top) ** 2)
    d = CONTACT_BOX_MARGIN * (zone / 10 if h is None else h)
    return np.array(
        [[max(-x - d, -width / 2), max(-d, -depth)], [min(x + d, width / 2), min(band + d, top)]]
    )


def mesh_size_bounds(R, width, depth, zone, Ry=None):
    """The mesh sizes h the Hertz scenes can mesh, (lo, hi): at least 1/2000 of the zone's
    half-width and 1e-5 of the largest body size (below, gmsh runs out of memory or aborts, the
    grid of the cut path likewise), at most half the zone. ValueError if the zone does not lie
    inside both bodies (zone < min(R, Ry, width/2, depth))."""
    Ry = R if Ry is None else Ry
    room = min(R, Ry, width / 2, depth)
    if not 0 < zone < room:
        raise ValueError(
            f"zone {zone:.4g} must lie inside both bodies: in (0, min(R, Ry, width/2, depth) = "
            f"{room:.4g})"
        )
    return max(zone / 2000, 1e-5 * max(R, Ry, width, depth)), zone / 2


def check_mesh_size(R, width, depth, h, zone, Ry=None):
    """ValueError unless h is within `mesh_size_bounds` (a library caller gets the message
    instead of a gmsh abort or a mesh of 1e14 cells)."""
    lo, hi = mesh_size_bounds(R, width, depth, zone, Ry)
    if not lo <= h <= hi:
        raise ValueError(
            f"h = {h:.4g} outside [{lo:.4g}, {hi:.4g}] (at least 1/2000 of the zone's half-width "
            f"{zone:.4g} and 1e-5 of the largest body size, at most half the zone)"
        )


# fmt: off
#: demos/hertz.py's options of the scene's sizes (cli.add_options rows), interpreted by
#: demo_sizes, demo_band and scene_sizes; a: the Hertz half-width of --load, --R, --E
SIZE_OPTIONS = [
    ("--band", "(0, inf)", None,
     "largest initial gap covered by the contact surface (default: the gap at x = 1.6 a)"),
    ("--width", "(0, inf)", None, "block width (default max(40, 40 a s), s = max(1, "
     "sqrt(a / (20 h))): the block grows as h falls below a/20)"),
    ("--depth", "(0, inf)", None, "block depth (default max(20, 20 a s))"),
    ("--zone", "[1, inf)", None, "half-width of the zone meshed at h, in units of the Hertz a "
     "(default 1.0 with the fast settings of path_defaults, else 1.2)"),
    ("--h-far", "(0, inf)", None,
     "mesh size far from the contact (default min(R / 2, depth / 2, 100 h), times 20 h / a "
     "below h = a/20, at least 20 h)"),
    ("--grading", "(0, inf)", None,
     "size growth away from the zone: slope (body-fitted: default 0.5 with --mesher layers, "
     "0.25 with gmsh) or ratio of neighbouring cells (cut, > 1, default 2)"),
]
#: and of its mesher, checked by demo_sizes
MESHER_OPTIONS = [
    ("--quads", bool, False, "quadrilateral cells"),
    ("--mesher", list(MESHERS), None,
     "body-fitted mesher: gmsh, or layers (triangles in layers around the contact point, "
     "no gmsh; the default for P1 triangles, else gmsh)"),
]
# fmt: on


def path_defaults(args, given):
    """The fastest accurate settings of demos/hertz.py, per path, for the options the command
    line `given` leaves out (benchmarks/work_precision.py: the time to GetFEM's p(x) error,
    0.24x GetFEM's body-fitted and 0.17x cut, against 0.64x and 0.54x with the previous
    defaults). Body-fitted P1 triangles: --mesher layers (no gmsh: its library load and
    meshing were most of a run), --zone 1.0 (the fine zone just covering the contact), --grading
    0.5; other body-fitted cells: gmsh, --zone 1.2, --grading 0.25. Cut: the augmented
    Lagrangian with the lumped projection (the closest pressure) and --zone 1.0 (with the
    penalty the error grows there: --zone 1.2). Sets the options in `args` in place."""
    from dolfinx_forms import defaults

    def unset(flag):
        return not any(t == flag or str(t).startswith(flag + "=") for t in given)

    if args.discretization == "cut":
        if unset("--enforcement") and unset("--multiplier-mass"):
            args.enforcement, args.multiplier_mass = "augmented", "lumped"
            if unset("--eps0"):  # eps0 sets the Uzawa loop's speed only: the fast one
                args.eps0 = defaults.TUNING.augmented_eps0
        fast = args.enforcement == "augmented"
    else:
        if args.mesher is None:
            args.mesher = "layers" if not args.quads and args.degree == 1 else "gmsh"
        fast = args.mesher == "layers"
        if args.grading is None and fast:
            args.grading = 0.5
    if args.zone is None:
        args.zone = 1.0 if fast else 1.2


def demo_sizes(args, hertz_a):
    """demos/hertz.py's mesher options checked (the layers: body-fitted triangles only; a cut
    grid's growth ratio --grading > 1), then its sizes that default from the Hertz half-width
    hertz_a (--h a/20, --width max(40, 40 a s), --depth max(20, 20 a s) with s =
    `block_growth`; --zone in units of a)
    and what the scenes can mesh: the zone inside both bodies, h within mesh_size_bounds.
    Returns (width, depth, h); a ValueError names the option to change."""
    a, cut = args, args.discretization == "cut"
    if a.mesher not in (None, "gmsh") and (cut or a.quads):
        raise ValueError(
            f"--mesher {a.mesher}: body-fitted triangles only (not with --quads or cut)"
        )
    if a.grading is not None and cut and not a.grading > 1:
        raise ValueError(f"--grading: the cut grid's growth ratio must be > 1, got {a.grading:g}")
    given = "--h" if a.h is not None else "--R, --load, --E (h = a/20 of the Hertz a)"
    h = a.h or hertz_a / 20
    grow = block_growth(hertz_a, h)
    width = a.width or max(40.0, 40 * hertz_a * grow)
    depth = a.depth or max(20.0, 20 * hertz_a * grow)
    zone = a.zone * hertz_a
    room = {"--R": a.R, "--width": width / 2, "--depth": depth}
    name = min(room, key=room.get)
    if not zone < room[name]:
        raise ValueError(
            f"{name}: the zone meshed at h, {a.zone:g} a = {zone:.4g} (a = {hertz_a:.4g}, the "
            f"Hertz half-width of --load, --R, --E), must lie inside both bodies: "
            f"below {name.lstrip('-')}{'/2' if name == '--width' else ''} = {room[name]:.4g}"
        )
    lo, hi = mesh_size_bounds(a.R, width, depth, zone)  # cells and grading gmsh can do
    if not lo <= h <= hi:
        raise ValueError(
            f"{given}: h = {h:.4g} outside [{lo:.4g}, {hi:.4g}] (at least 1/2000 of the "
            f"zone's half-width {zone:.4g} and 1e-5 of the largest body size "
            f"{max(a.R, width, depth):.4g}, at most half the zone; a small load needs "
            "smaller --R, --width, --depth)"
        )
    return width, depth, h


# demos/hertz.py's bulk, chosen so that its error falls with the contact's instead of
# flooring it (the augmented Lagrangian, which adds no compliance, shows the floor; the penalty's
# compliance partly cancels it), while h = a/20 and coarser keep the fast meshes of
# `path_defaults`: far cells at most FAR_CELLS h down to a/20, FAR_CELLS h (20 h / a) below,
# at least FAR_CELLS_MIN h (`far_cell_size`), and the block 40 a x 20 a growing as
# sqrt(a / (20 h)) below a/20 (`block_growth`; its finite size is an O((a / depth)^2) error
# against the half-space). At R = 40, a/80, augmented, body-fitted, p(x): 0.383 % with far
# cells of 100 h and the a/20 block, 0.222 / 0.210 % with 20 h / 10 h, 0.167 % with 20 h and the
# grown block, 0.177 % with this rule (187k dofs against 110k); a/20 -> a/80 then falls at rate
# 1.22 body-fitted, 0.95 cut, against 0.64 and 0.81 before (docs/demos/convergence_study.md).
FAR_CELLS, FAR_CELLS_MIN = 100, 20


def far_cell_size(hertz_a, h):
    """The largest cell of the default bulk: FAR_CELLS h down to h = a/20, then shrinking like
    h^2 (FAR_CELLS h (20 h / a)), so that the far cells' stiffening falls with h (with far
    cells of a fixed multiple of h it floors the error: 100 h at a/80, 0.38 % against 0.18 %),
    down to FAR_CELLS_MIN h (from a/100: at a/80, 20 h and 10 h differ by 0.012 %, while the
    far cells' number, the block's area ~ 1/h over their size squared, would grow like h^-5
    instead of h^-3)."""
    return max(FAR_CELLS_MIN, FAR_CELLS * min(1.0, 20.0 * h / hertz_a)) * h


def block_growth(hertz_a, h):
    """The factor s >= 1 of the default block (40 a s x 20 a s): 1 down to h = a/20, then
    sqrt(a / (20 h)), so that the block's finite-size error, O((a / depth)^2), falls like h."""
    return max(1.0, float(np.sqrt(hertz_a / (20.0 * h))))


def demo_band(p, hertz_a):
    """The largest initial gap Gamma_c covers for the parameters p of demos/hertz.py: --band,
    default the gap at x = 1.6 a."""
    return p["band"] or (1.6 * hertz_a) ** 2 / (2 * p["R"])


def scene_sizes(p, hertz_a):
    """The size keywords of hertz_scene (cut: meshes.cut.hertz_cut_scene) for the parameters p
    of demos/hertz.py: the zone meshed at h, the band (rank 0 holds the cells of Gamma_c) and
    the defaults of h_far and growth."""
    cut = p["discretization"] == "cut"
    zone, band = p["zone"] * hertz_a, demo_band(p, hertz_a)
    # the far field coarsens with h, so that its error falls with h's (fixed h_far: a floor)
    h_far = p["h_far"] or min(p["R"] / 2, p["depth"] / 2, far_cell_size(hertz_a, p["h"]))
    # body-fitted slope 0.5 instead: the same error at a/20 but a floor of 0.55 % from a/40
    growth = p["grading"] or (2.0 if cut else 0.25)
    size = {k: p[k] for k in ("R", "width", "depth", "h")}
    return dict(size, zone=zone, band=band, h_far=h_far, growth=growth)


def ellipse_sag(R, Ry, x):
    """Height of the arc above its lowest point at abscissa x: Ry (1 - sqrt(1 - (x/R)^2)) (the
    initial gap to the block top; R - sqrt(R^2 - x^2) for the circle Ry = R)."""
    if Ry == R:
        return R - np.sqrt(R * R - x * x)
    return Ry * (1 - np.sqrt(1 - (x / R) ** 2))


def _arc_length(R, Ry, x):
    """Length of the arc from its lowest point to abscissa x (0 <= x < R)."""
    t1 = np.arcsin(x / R)  # parameter of (R sin t, Ry (1 - cos t))
    if Ry == R:
        return R * t1
    s, w = np.polynomial.legendre.leggauss(64)
    t = 0.5 * t1 * (s + 1)
    return 0.5 * t1 * float(np.sum(w * np.hypot(R * np.cos(t), Ry * np.sin(t))))


def _build(gmsh, R, W, depth, z, h, h_far, quads, Ry=None, growth=GROWTH):
    """Rank 0: both bodies, each split into a zone part (|x|, |y| <= z) and the rest (shared
    curves inside a body only), then meshed. quads: the zone parts are structured (transfinite)
    grids with edges <= h, the rest is recombined. Triangles: unstructured everywhere.
    Ry: vertical semi-axis of the indenter (default R, the circle)."""
    Ry = R if Ry is None else Ry
    geo = gmsh.model.geo
    assert 0 < z < min(R, Ry, W, depth), "zone must lie inside both bodies"
    sag = ellipse_sag(R, Ry, z)  # defined for |z| < R only
    assert sag < z, "zone must lie inside both bodies"
    # quads: blossom may leave a few triangles, so mesh at 2h and subdivide every cell (all quads,
    # the structured zone stays structured): zone curves get n/2 cells before subdivision
    hq = 2 * h if quads else h
    n_x = int(np.ceil(_arc_length(R, Ry, z) / hq))  # cells along each half (x < 0, x > 0)
    n_y = int(np.ceil(z / hq))  # cells across the zone's height: z (block), z - sag .. z (cylinder)

    def pts(*xy):
        return [geo.addPoint(x, y, 0.0) for x, y in xy]

    def lines(p, closed=True):
        n = len(p) if closed else len(p) - 1
        return [geo.addLine(p[i], p[(i + 1) % len(p)]) for i in range(n)]

    def surface(curves, zone=False):  # zone parts: 4-sided, structured when quads
        s = geo.addPlaneSurface([geo.addCurveLoop(curves)])
        if quads and zone:
            geo.mesh.setTransfiniteSurface(s)
            geo.mesh.setRecombine(2, s)

    # block: the zone [-z, z] x [-z, 0] as two squares left/right of x = 0, and the rest
    b0, b1, b2, b3 = pts((-W, -depth), (W, -depth), (W, 0), (z, 0))
    o, b5, b6 = pts((0, 0), (-z, 0), (-W, 0))
    zl, zm, zr = pts((-z, -z), (0, -z), (z, -z))
    bot, right, tr, down, zb_r, zb_l, up, tl, left = lines([b0, b1, b2, b3, zr, zm, zl, b5, b6])
    top_r, top_l = lines([b3, o, b5], closed=False)
    mid = geo.addLine(zm, o)
    surface([bot, right, tr, down, zb_r, zb_l, up, tl, left])
    surface([-zb_r, -down, top_r, -mid], True)
    surface([-zb_l, mid, top_l, -up], True)
    # cylinder: the zone part {|x| <= z, y <= z} above the arc (two halves), and the rest
    c, a, pl, o2, pr, b, ztl, ztm, ztr = pts(
        (0, Ry), (-R, Ry), (-z, sag), (0, 0), (z, sag), (R, Ry), (-z, z), (0, z), (z, z)
    )
    if Ry == R:
        arcs = [geo.addCircleArc(p, c, q) for p, q in [(a, pl), (pl, o2), (o2, pr), (pr, b)]]
    else:  # the major-axis point: (R, Ry) on the horizontal axis, else the origin (vertical)
        major = b if R > Ry else o2
        arcs = [
            geo.addEllipseArc(p, c, major, q) for p, q in [(a, pl), (pl, o2), (o2, pr), (pr, b)]
        ]
    side_l, zt_l, zt_r, side_r = lines([pl, ztl, ztm, ztr, pr], closed=False)
    top, cmid = geo.addLine(b, a), geo.addLine(o2, ztm)
    surface([arcs[0], side_l, zt_l, zt_r, side_r, arcs[3], top])
    surface([arcs[1], cmid, -zt_l, -side_l], True)
    surface([arcs[2], -side_r, -zt_r, -cmid], True)
    if quads:
        for line in [zb_r, zb_l, top_r, top_l, arcs[1], arcs[2], zt_l, zt_r]:
            geo.mesh.setTransfiniteCurve(line, n_x + 1)
        for line in [down, mid, up, side_l, cmid, side_r]:
            geo.mesh.setTransfiniteCurve(line, n_y + 1)
    geo.synchronize()

    f = gmsh.model.mesh.field.add("Box")
    for k, v in dict(VOut=h_far * hq / h, XMin=-z, XMax=z, YMin=-z, YMax=z).items():
        gmsh.model.mesh.field.setNumber(f, k, v)
    gmsh.model.mesh.field.setAsBackgroundMesh(f)
    gmsh.option.setNumber("Mesh.RecombineAll", int(quads))
    gmsh.option.setNumber("Mesh.SubdivisionAlgorithm", int(quads))
    # Unstructured triangle edges scatter up to ~1.35x gmsh's target size: aim at 0.75 h and
    # shrink further (remesh) until the longest edge of the zone's cells is <= 1.05 h.
    fac = 1.0 if quads else 0.75
    for attempt in range(5):
        if attempt:
            gmsh.model.mesh.clear()
        gmsh.model.mesh.field.setNumber(f, "VIn", fac * hq)
        gmsh.model.mesh.field.setNumber(f, "Thickness", (h_far - fac * h) * hq / h / growth)
        gmsh.model.mesh.generate(2)
        _, x, cells = extract_gmsh(gmsh)
        ratio = max_edge_in_box(x, cells, [[-z, -z], [z, z]]) / h
        if ratio <= 1.05:
            break
        fac /= ratio
    else:
        raise RuntimeError(f"hertz: longest edge in the zone is {ratio:.3f} h after 5 meshings")


def _layer_points(r, X_end, Y_end, z, bottom):
    """Layers (K, 5, 2) of one body on the layer radii r (0 ... r_end): the U of half-width X
    and height Y, X = Y = r on the zone (r <= z), then blended linearly to the body's X_end and
    Y_end at r_end; bottom(X): the ends' height (the body's boundary), the arms rise (Y > 0) or
    fall (Y < 0: the block below the origin) from there."""
    f = np.clip((r - z) / (r[-1] - z), 0.0, 1.0)
    X = np.where(r <= z, r, z + f * (X_end - z))
    Y = np.where(r <= z, r, z + f * (abs(Y_end) - z)) * np.sign(Y_end)
    b, o = bottom(X), np.zeros_like(X)
    return np.stack(
        [np.column_stack(q) for q in ((-X, b), (-X, Y), (o, Y), (X, Y), (X, b))], axis=1
    )


def _layers(R, Ry, W, depth, z, h, h_far, growth):
    """Rank 0: both bodies as nested layers around the origin (meshes/layers.py): spacing
    h / sqrt(2) on the zone (the grid's diagonals h), growing by the ratio 1 + growth per layer
    up to h_far. Returns x (n, 2), triangles (m, 3) int64."""
    from dolfinx_forms.mesh.cut_scene import graded_lines
    from .layers import layer_mesh

    s = h / np.sqrt(2)
    z = s * np.ceil(z / s - 1e-9)  # the zone: whole layers of spacing s

    def body(X_end, Y_end, bottom):
        r = graded_lines(0.0, max(X_end, abs(Y_end)), (0.0, z), s, 1 + growth, h_far)
        spacing = np.maximum(np.gradient(r), s)
        return layer_mesh(_layer_points(r, X_end, Y_end, z, bottom), spacing)

    xb, tb = body(W, -depth, np.zeros_like)
    xc, tc = body(R, Ry, lambda X: ellipse_sag(R, Ry, np.minimum(X, R)))
    return np.concatenate([xb, xc]), np.concatenate([tb, tc + len(xb)]).astype(np.int64)


def indenter_shape(R, Ry):
    """The indenter's full ellipse (circle if Ry == R) centred at (0, Ry): a dolfinx_forms
    shape, < 0 inside, its signed distance exact."""
    import dolfinx_forms as df

    return df.Circle((0.0, R), R) if Ry == R else df.Ellipse((0.0, Ry), R, Ry)


def hertz_scene(
    comm,
    R=10.0,
    width=40.0,
    depth=20.0,
    h=0.05,
    zone=1.5,
    h_far=None,
    quads=False,
    contact_box=None,
    Ry=None,
    growth=GROWTH,
    band=None,
    mesher="gmsh",
) -> Scene:
    """The Hertz scene (see the module docstring): a half-ellipse of semi-axes R (horizontal)
    and Ry (vertical, default R: the half-cylinder) on the block; contact_box overrides
    hertz_contact_box(R, width, depth, zone, Ry, band, h) (band: the contact problem's).
    mesher: "gmsh" or "layers" (triangles without gmsh, see `MESHERS`)."""
    import dolfinx_forms as df

    Ry = R if Ry is None else float(Ry)
    check_mesh_size(R, width, depth, h, zone, Ry)
    if mesher not in MESHERS:
        raise ValueError(f"mesher {mesher!r} not in {MESHERS}")
    if not ellipse_sag(R, Ry, zone) < zone:  # the corner (zone, zone) outside the indenter
        raise ValueError(
            f"zone {zone:.4g} must lie inside both bodies: the indenter's arc at x = zone is at "
            f"y = {ellipse_sag(R, Ry, zone):.4g}, above y = zone (use a smaller zone or Ry)"
        )
    if mesher == "layers" and quads:
        raise ValueError("mesher 'layers' makes triangles only (quads: mesher 'gmsh')")
    h_far = max(h, min(R, Ry, depth) / 8 if h_far is None else h_far)
    W = width / 2
    bodies = [
        Body("block", 1, df.Box((-W, -depth), (W, 0.0)), np.array([[-W, -depth], [W, 0.0]])),
        Body(
            "cylinder",
            2,
            df.Intersection([indenter_shape(R, Ry), df.Box((-R - 1, -1.0), (R + 1, Ry))]),
            np.array([[-R, 0.0], [R, Ry]]),
        ),
    ]
    tol = 1e-8 * max(R, Ry, width, depth)
    if Ry == R:

        def on_arc(x):
            return np.abs(np.hypot(x[0], x[1] - R) - R) < tol

    else:  # |algebraic distance| scaled by the smaller semi-axis (<= the true distance)

        def on_arc(x):
            return np.abs(np.hypot(x[0] / R, (x[1] - Ry) / Ry) - 1) * min(R, Ry) < tol

    markers = {
        "block_bottom": (1, lambda x: np.isclose(x[1], -depth, atol=tol), 0),
        "block_sides": (2, lambda x: np.isclose(np.abs(x[0]), W, atol=tol), 0),
        "block_top": (3, lambda x: np.isclose(x[1], 0.0, atol=tol), 0),
        "cylinder_top": (4, lambda x: np.isclose(x[1], Ry, atol=tol), 1),
        "cylinder_arc": (5, on_arc, 1),
    }
    box = contact_box
    if box is None:
        box = hertz_contact_box(R, width, depth, zone, Ry, band, h)
    if mesher == "layers":
        x, cells = (
            _layers(R, Ry, W, depth, zone, h, h_far, growth)
            if comm.rank == 0
            else (np.zeros((0, 2)), np.zeros((0, 3), np.int64))
        )
        return scene_from_arrays(comm, x, cells, "triangle", bodies, markers, [(0, 1)], h, box)
    with gmsh_model(comm, "hertz") as gmsh:
        if comm.rank == 0:
            _build(gmsh, R, W, depth, zone, h, h_far, quads, Ry, growth)
        return scene_from_gmsh(comm, bodies, markers, [(0, 1)], h, contact_box=box)


if __name__ == "__main__":
    import argparse

    from mpi4py import MPI

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--h", type=float, default=0.05)
    ap.add_argument("--quads", action="store_true")
    ap.add_argument("--R", type=float, default=10.0, help="horizontal semi-axis")
    ap.add_argument("--Ry", type=float, default=None, help="vertical semi-axis (default R)")
    ap.add_argument("--layers", action="store_true", help="mesher 'layers' (no gmsh)")
    args = ap.parse_args()
    mesher = "layers" if args.layers else "gmsh"
    scene = hertz_scene(
        MPI.COMM_WORLD, R=args.R, h=args.h, quads=args.quads, Ry=args.Ry, mesher=mesher
    )
    line = summary(scene)
    if MPI.COMM_WORLD.rank == 0:
        print("hertz:", line)
