"""Patch-test scene: two stacked structured blocks, interface on mesh lines.

Geometry (any units): body 0 "lower" (tag 1) = [0, width] x [0, height] with nx x ny cells,
body 1 "upper" (tag 2) = [0, width] x [height, 2 height] with nx_upper x ny cells (nx_upper
defaults to nx; a different value gives a non-matching interface). Defaults: [0,1]x[0,0.5]
and [0,1]x[0.5,1]. Quadrilaterals, or the same grids split into triangles with quads=False.
Boundaries: lower_bottom=1, lower_left=2, lower_right=3, lower_top=4, upper_bottom=5,
upper_left=6, upper_right=7, upper_top=8. pairs = [(0, 1)]; contact box = the interface
strip +- one cell; h_contact = width / min(nx, nx_upper).
Run: /usr/bin/python3 -m meshes.patch [--nx 4] [--ny 2] [--nx-upper 5] [--triangles]
"""

from __future__ import annotations

import numpy as np

from dolfinx_forms.mesh.scene import (
    Body,
    Scene,
    add_polygon,
    check_cells,
    gmsh_model,
    on_box_side,
    scene_from_gmsh,
    summary,
)

NAMES = ("lower", "upper")  # body 0, body 1


def patch_scene(comm, nx=4, ny=2, quads=True, width=1.0, height=0.5, nx_upper=None) -> Scene:
    import dolfinx_forms as df

    nx_upper = nx if nx_upper is None else nx_upper
    check_cells(
        "patch_scene", (nx + nx_upper) * ny if min(nx, nx_upper, ny) > 0 else 0, "fewer cells"
    )
    boxes = [
        np.array([[0.0, 0.0], [width, height]]),
        np.array([[0.0, height], [width, 2 * height]]),
    ]
    bodies = [Body(n, i + 1, df.Box(*b), b) for i, (n, b) in enumerate(zip(NAMES, boxes))]
    tol = 1e-8 * max(width, height)
    markers, tag = {}, 1
    for body, (name, (lo, hi)) in enumerate(zip(["lower", "upper"], boxes)):
        for s in ["bottom", "left", "right", "top"]:
            markers[f"{name}_{s}"] = (tag, on_box_side(lo, hi, [s], tol), body)
            tag += 1
    with gmsh_model(comm, "patch") as gmsh:
        if comm.rank == 0:
            for (lo, hi), n in zip(boxes, [(nx, ny), (nx_upper, ny)]):
                add_polygon(gmsh, [lo, (hi[0], lo[1]), hi, (lo[0], hi[1])], n=n, quads=quads)
            gmsh.model.geo.synchronize()
            gmsh.model.mesh.generate(2)
        hc = width / min(nx, nx_upper)  # facet length along the contact, coarser side
        box = np.array([[0.0, height - height / ny], [width, height + height / ny]])
        return scene_from_gmsh(comm, bodies, markers, [(0, 1)], hc, contact_box=box)


if __name__ == "__main__":
    import argparse

    from mpi4py import MPI

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nx", type=int, default=4)
    ap.add_argument("--ny", type=int, default=2)
    ap.add_argument("--nx-upper", type=int, default=None)
    ap.add_argument("--triangles", action="store_true")
    args = ap.parse_args()
    s = patch_scene(MPI.COMM_WORLD, args.nx, args.ny, not args.triangles, nx_upper=args.nx_upper)
    line = summary(s)
    if MPI.COMM_WORLD.rank == 0:
        print("patch:", line)


def patch_dirichlet(d, height=1.0):
    """The patch test's Dirichlet conditions on these boundary names (also those of
    meshes.cut.patch_cut_scene): bottom u_y = 0, top u_y = -d lam, and u_x = 0 at the left end
    of the bottom and of the top (one point per body: no rigid sliding)."""
    from dolfinx_forms.fem.boundary import Dirichlet

    def corner(y):
        return lambda x: np.isclose(x[0], 0.0) & np.isclose(x[1], y)

    return [
        Dirichlet("lower_bottom", 1, 0.0),
        Dirichlet("upper_top", 1, lambda lam: -d * lam),
        Dirichlet(corner(0.0), 0, 0.0),
        Dirichlet(corner(height), 0, 0.0),
    ]
