"""Structured-grid (cut-cell) scenes: the counterparts of the body-fitted gmsh scenes.

The geometry (bodies as level-set windows on one tensor-product grid, interior and cut cells,
ghost facets, boundaries) is dolfinx_forms/mesh/cut_scene.py's `cut_scene`; these are the
verification scenes built with it.
Generators (same body names/tags, boundary names, pairs and contact boxes as meshes/*.py):
  hertz_cut_scene       block window [-W, W] x [-depth, 0] (no cut cell), cylinder window
                        [-R, R] x [0, Ry] cut by Circle((0, R), R) (Ry = R, the default) or
                        Ellipse((0, Ry), R, Ry); graded grid, spacing h on [-zone, zone]^2
                        (zone rounded up to a multiple of h)
  patch_cut_scene       [0, width] x [0, height] split at y = interface (not a grid line)
  two_blocks_cut_scene  the two blocks, interface y = height mid-cell (ny odd)
  incline_cut_scene     the square cut by y = slope x + intercept
Run: /usr/bin/python3 -m meshes.cut [--scene hertz] [--h 0.05] [--n 5]  (from the repository root)
"""

from __future__ import annotations

import numpy as np

from dolfinx_forms.fem.cut import CUT
from dolfinx_forms.mesh.cut_scene import CutBody, cut_scene, graded_lines, half_plane
from dolfinx_forms.mesh.scene import Scene, check_cells, on_box_side, summary

from .hertz import check_mesh_size, hertz_contact_box

__all__ = [
    "hertz_cut_scene",
    "patch_cut_scene",
    "two_blocks_cut_scene",
    "incline_cut_scene",
    "cut_counts",
    "fitted_or_cut",
]


# --------------------------------------------------------------------------- generators
def _nothing(x):
    """Marker predicate for a cut (not grid-aligned) boundary: no facet."""
    return np.zeros(x.shape[1], dtype=bool)


def _window_markers(windows, specs, tol):
    """boundary_markers for cut_scene: specs [(name, body, window sides or None)] give name ->
    (tag 1, 2, ... in order, predicate, body); the predicate matches the given sides of the
    body's window (see on_box_side), None (a cut boundary, not grid aligned) matches nothing."""

    def pred(body, sides):
        return _nothing if sides is None else on_box_side(*windows[body], sides, tol)

    return {
        name: (tag, pred(body, sides), body)
        for tag, (name, body, sides) in enumerate(specs, start=1)
    }


def hertz_cut_scene(
    comm,
    R=10.0,
    width=40.0,
    depth=20.0,
    h=0.05,
    zone=1.5,
    h_far=None,
    growth=1.2,
    contact_box=None,
    Ry=None,
    band=None,
) -> Scene:
    """The Hertz scene of meshes/hertz.py on a graded grid (spacing h on [-z, z]^2, z = zone
    rounded up to a multiple of h); the block has no cut cell, the indenter (window
    [-R, R] x [0, Ry]) is cut by its circle, or by its ellipse of semi-axes R (horizontal) and Ry
    (vertical, default R). contact_box overrides hertz_contact_box(R, width, depth, zone, Ry,
    band, h) (band: the contact problem's)."""
    import dolfinx_forms as df

    from .hertz import indenter_shape

    Ry = R if Ry is None else float(Ry)
    check_mesh_size(R, width, depth, h, zone, Ry)
    W = width / 2
    k = zone / h
    z = zone if abs(k - round(k)) < 1e-9 else h * np.ceil(k)
    if not z < min(R, Ry, W, depth):
        raise ValueError(
            f"hertz_cut_scene: zone {z} (rounded up to a multiple of h) must be "
            f"< min(R, Ry, width/2, depth) = {min(R, Ry, W, depth)}"
        )
    h_far = max(h, min(R, Ry, depth) / 8 if h_far is None else h_far)
    xmax = max(W, R)
    xlines = graded_lines(-xmax, xmax, (-z, z), h, growth, h_far, required=[-W, -R, 0.0, R, W])
    ylines = graded_lines(-depth, Ry, (-z, z), h, growth, h_far, required=[0.0])
    m = max(R, W, depth)  # the block's cut box: the window with a margin, so no cell is cut
    block = np.array([[-W, -depth], [W, 0.0]])
    bodies = [
        CutBody("block", 1, block, df.Box(block[0] - m, block[1] + m), block),
        CutBody(
            "cylinder",
            2,
            np.array([[-R, 0.0], [R, Ry]]),
            indenter_shape(R, Ry),
            np.array([[-R, 0.0], [R, Ry]]),
        ),
    ]
    specs = [
        ("block_bottom", 0, ["bottom"]),
        ("block_sides", 0, ["left", "right"]),
        ("block_top", 0, ["top"]),
        ("cylinder_top", 1, ["top"]),
        ("cylinder_arc", 1, None),
    ]
    markers = _window_markers([b.window for b in bodies], specs, 1e-8 * max(R, Ry, width, depth))
    box = (
        hertz_contact_box(R, width, depth, zone, Ry, band, h)
        if contact_box is None
        else contact_box
    )
    return cut_scene(comm, xlines, ylines, bodies, markers, [(0, 1)], h, contact_box=box)


def patch_cut_scene(comm, n=5, width=1.0, height=1.0, interface=0.5, nx=None) -> Scene:
    """Patch test on a uniform grid: n cells over the height, nx (default round(n width /
    height)) across; lower body [0, width] x [0, interface], upper [0, width] x [interface,
    height]; `interface` must not be a grid line (ValueError): the test wants cut cells. The
    default n = 5 keeps the gmsh patch's interface 0.5 mid-cell."""
    nx = max(1, round(n * width / height)) if nx is None else int(nx)
    check_cells("patch_cut_scene", nx * n if n > 0 else 0, "fewer cells")
    xlines, ylines = np.linspace(0.0, width, nx + 1), np.linspace(0.0, height, n + 1)
    hy = height / n
    k = interface / hy
    if not 0 < interface < height or abs(k - round(k)) < 1e-9:
        raise ValueError(
            f"patch_cut_scene: interface={interface} must lie strictly inside "
            f"(0, {height}) and not on a grid line (spacing {hy})"
        )
    above, below = ylines[int(np.ceil(k))], ylines[int(np.floor(k))]
    windows = [np.array([[0.0, 0.0], [width, above]]), np.array([[0.0, below], [width, height]])]
    ext = 100 * max(width, height)
    bodies = [
        CutBody(
            "lower",
            1,
            windows[0],
            half_plane((0.0, interface), (0.0, 1.0), ext),
            np.array([[0.0, 0.0], [width, interface]]),
        ),
        CutBody(
            "upper",
            2,
            windows[1],
            half_plane((0.0, interface), (0.0, -1.0), ext),
            np.array([[0.0, interface], [width, height]]),
        ),
    ]
    specs = [
        (f"{name}_{side}", body, None if side == cut else [side])
        for body, (name, cut) in enumerate([("lower", "top"), ("upper", "bottom")])
        for side in ("bottom", "left", "right", "top")
    ]
    markers = _window_markers(windows, specs, 1e-8 * max(width, height))
    box = np.array([[0.0, interface - hy], [width, interface + hy]])
    return cut_scene(
        comm, xlines, ylines, bodies, markers, [(0, 1)], max(width / nx, hy), contact_box=box
    )


def two_blocks_cut_scene(comm, h=0.2, width_lower=40.0, height=10.0, width_upper=20.0) -> Scene:
    """The two blocks of meshes/two_blocks.py on a uniform grid: x lines through 0, c -+
    width_upper/2, width_lower (spacing <= about h), ny = the smallest odd integer >= 2 height / h
    cells over [0, 2 height], so the interface y = height is mid-cell."""
    check_cells("two_blocks_cut_scene", 2 * height * width_lower / h**2 if h > 0 else 0)
    c = width_lower / 2
    req = np.array([0.0, c - width_upper / 2, c + width_upper / 2, width_lower])
    gap = np.diff(np.unique(req))
    gap = gap[gap > 0].min()
    hx = gap / max(1, round(gap / h))
    xlines = graded_lines(0.0, width_lower, (0.0, width_lower), hx, required=req)
    ny = int(np.ceil(2 * height / h - 1e-9))
    ny += 1 - ny % 2
    ylines = np.linspace(0.0, 2 * height, ny + 1)
    above, below = ylines[(ny + 1) // 2], ylines[(ny - 1) // 2]
    u0, u1 = req[1:3]
    windows = [
        np.array([[0.0, 0.0], [width_lower, above]]),
        np.array([[u0, below], [u1, 2 * height]]),
    ]
    ext = 100 * max(width_lower, 2 * height)
    bodies = [
        CutBody(
            "lower",
            1,
            windows[0],
            half_plane((0.0, height), (0.0, 1.0), ext),
            np.array([[0.0, 0.0], [width_lower, height]]),
        ),
        CutBody(
            "upper",
            2,
            windows[1],
            half_plane((0.0, height), (0.0, -1.0), ext),
            np.array([[u0, height], [u1, 2 * height]]),
        ),
    ]
    specs = [
        ("lower_bottom", 0, ["bottom"]),
        ("lower_left", 0, ["left"]),
        ("lower_right", 0, ["right"]),
        ("lower_top", 0, None),
        ("upper_top", 1, ["top"]),
        ("upper_bottom", 1, None),
        ("upper_sides", 1, ["left", "right"]),
    ]
    markers = _window_markers(windows, specs, 1e-8 * width_lower)
    box = np.array([[u0, height - 2 * h], [u1, height + 2 * h]])
    return cut_scene(
        comm, xlines, ylines, bodies, markers, [(0, 1)], max(hx, ylines[1]), contact_box=box
    )


def incline_cut_scene(comm, h=25.0, size=1000.0, slope=0.2, intercept=458.6) -> Scene:
    """The square of meshes/incline.py on a uniform n x n grid, n = round(size / h); both
    windows are the whole square, cut by half-planes below / above y = slope x + intercept."""
    y0, y1 = intercept, slope * size + intercept
    if not (0 < y0 < size and 0 < y1 < size):
        raise ValueError("incline_cut_scene: the line must cross both vertical sides")
    check_cells("incline_cut_scene", (size / h) ** 2 if h > 0 else 0)
    n = max(1, round(size / h))
    lines = np.linspace(0.0, size, n + 1)
    square = np.array([[0.0, 0.0], [size, size]])
    up = np.array([-slope, 1.0])
    polys = [
        np.array([[0, 0], [size, 0], [size, y1], [0, y0]]),
        np.array([[0, y0], [size, y1], [size, size], [0, size]]),
    ]
    bodies = [
        CutBody(
            name,
            i + 1,
            square,
            half_plane((0.0, intercept), sign * up, 100 * size),
            np.array([p.min(axis=0), p.max(axis=0)], float),
        )
        for i, (name, sign, p) in enumerate(zip(["lower", "upper"], [1, -1], polys))
    ]
    specs = [
        ("lower_bottom", 0, ["bottom"]),
        ("upper_top", 1, ["top"]),
        ("lower_sides", 0, ["left", "right"]),
        ("upper_sides", 1, ["left", "right"]),
        ("lower_interface", 0, None),
        ("upper_interface", 1, None),
    ]
    markers = _window_markers([square, square], specs, 1e-8 * size)
    box = np.array([[0.0, min(y0, y1) - 2 * h], [size, max(y0, y1) + 2 * h]])
    return cut_scene(comm, lines, lines, bodies, markers, [(0, 1)], size / n, contact_box=box)


def cut_counts(scene: Scene) -> dict[str, int]:
    """Collective: global number of cut cells per body name."""
    owned = scene.cell_tags.indices < scene.mesh.topology.index_map(2).size_local
    cut = scene.cut.kind_tags.values == CUT
    tags = scene.cell_tags.values
    return {
        b.name: scene.mesh.comm.allreduce(int(np.sum(owned & cut & (tags == b.tag))))
        for b in scene.bodies
    }


def fitted_or_cut(run, fitted, cut, h, quads, **geometry):
    """A demo's scene by its --discretization, timed as the "mesh" phase: conforming,
    fitted(comm, h=h, quads=quads, **geometry) (gmsh); cut, cut(comm, h=h, **geometry) on one
    uniform grid, its cut cells per body in metrics["mesh"]["cut_cells"]."""
    with run.phase("mesh"):
        if run.params["discretization"] == "conforming":
            return fitted(run.comm, h=h, quads=quads, **geometry)
        scene = cut(run.comm, h=h, **geometry)
        run.metrics["mesh"]["cut_cells"] = cut_counts(scene)
        return scene


if __name__ == "__main__":
    import argparse

    from mpi4py import MPI

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", choices=["hertz", "patch", "two_blocks", "incline"], default="hertz")
    ap.add_argument(
        "--h",
        type=float,
        default=None,
        help="grid spacing (hertz, two_blocks, incline; default: theirs)",
    )
    ap.add_argument("--n", type=int, default=5, help="patch: cells over the height")
    args = ap.parse_args()
    comm = MPI.COMM_WORLD
    if args.scene == "patch":
        s = patch_cut_scene(comm, n=args.n)
    else:
        make = {
            "hertz": hertz_cut_scene,
            "two_blocks": two_blocks_cut_scene,
            "incline": incline_cut_scene,
        }[args.scene]
        s = make(comm) if args.h is None else make(comm, h=args.h)
    line, counts = summary(s), cut_counts(s)
    if comm.rank == 0:
        print(f"{args.scene} (cut):", line)
        print("cut cells:", ", ".join(f"{k}: {v}" for k, v in counts.items()))
