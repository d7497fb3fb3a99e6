"""Two-blocks scene (Tur, Fuenmayor & Wriggers 2009, as restated): a short block on a long one.

Geometry (mm):
  body 0 "lower" (tag 1): [0, width_lower] x [0, height]            (default [0, 40] x [0, 10])
  body 1 "upper" (tag 2): [c - width_upper/2, c + width_upper/2] x [height, 2 height],
                          c = width_lower/2                          (default [10, 30] x [10, 20])
The interface is y = height; both meshes are uniform with size h (structured transfinite grids,
quadrilaterals, or the same grids split into triangles with quads=False), so the interface
nodes coincide but are distinct vertices.
Boundaries: lower_bottom=1, lower_left=2, lower_right=3, lower_top=4, upper_top=5,
upper_bottom=6, upper_sides=7. pairs = [(0, 1)]; contact box = the upper block's bottom strip.
Run: /usr/bin/python3 -m meshes.two_blocks [--h 0.2] [--triangles]
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


def two_blocks_scene(
    comm, h=0.2, quads=True, width_lower=40.0, height=10.0, width_upper=20.0
) -> Scene:
    import dolfinx_forms as df

    check_cells("two_blocks_scene", height * (width_lower + width_upper) / h**2 if h > 0 else 0)
    c = width_lower / 2
    boxes = [
        np.array([[0.0, 0.0], [width_lower, height]]),
        np.array([[c - width_upper / 2, height], [c + width_upper / 2, 2 * height]]),
    ]
    bodies = [Body(n, i + 1, df.Box(*b), b) for i, (n, b) in enumerate(zip(NAMES, boxes))]
    tol = 1e-8 * width_lower
    (l0, l1), (u0, u1) = boxes
    markers = {
        "lower_bottom": (1, on_box_side(l0, l1, ["bottom"], tol), 0),
        "lower_left": (2, on_box_side(l0, l1, ["left"], tol), 0),
        "lower_right": (3, on_box_side(l0, l1, ["right"], tol), 0),
        "lower_top": (4, on_box_side(l0, l1, ["top"], tol), 0),
        "upper_top": (5, on_box_side(u0, u1, ["top"], tol), 1),
        "upper_bottom": (6, on_box_side(u0, u1, ["bottom"], tol), 1),
        "upper_sides": (7, on_box_side(u0, u1, ["left", "right"], tol), 1),
    }
    with gmsh_model(comm, "two_blocks") as gmsh:
        if comm.rank == 0:
            for lo, hi in boxes:
                n = np.maximum(1, np.round((hi - lo) / h)).astype(int)
                add_polygon(gmsh, [lo, (hi[0], lo[1]), hi, (lo[0], hi[1])], n=n, quads=quads)
            gmsh.model.geo.synchronize()
            gmsh.model.mesh.generate(2)
        box = np.array([[u0[0], height - 2 * h], [u1[0], height + 2 * h]])
        return scene_from_gmsh(comm, bodies, markers, [(0, 1)], h, contact_box=box)


if __name__ == "__main__":
    import argparse

    from mpi4py import MPI

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--h", type=float, default=0.2)
    ap.add_argument("--triangles", action="store_true")
    args = ap.parse_args()
    line = summary(two_blocks_scene(MPI.COMM_WORLD, h=args.h, quads=not args.triangles))
    if MPI.COMM_WORLD.rank == 0:
        print("two_blocks:", line)
