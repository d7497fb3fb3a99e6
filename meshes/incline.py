"""Inclined-interface scene: a square cut into two bodies by the line y = slope x + intercept.

Geometry (mm): the square [0, size]^2 (default 1000) split by y = slope*x + intercept
(default 0.2 x + 458.6, from (0, 458.6) to (1000, 658.6)) into
  body 0 "lower" (tag 1): the part below the line,
  body 1 "upper" (tag 2): the part above,
two separate polygons (own points and curves, duplicate nodes on the interface), unstructured
mesh of size h (triangles, or recombined quadrilaterals with quads=True). Shapes: Polygon.
Boundaries: lower_bottom=1, upper_top=2, lower_sides=3, upper_sides=4, lower_interface=5,
upper_interface=6. pairs = [(0, 1)]; contact box = a 2h band around the interface.
Run: /usr/bin/python3 -m meshes.incline [--h 25] [--quads]
"""

from __future__ import annotations

import numpy as np

from dolfinx_forms.mesh.scene import (
    Body,
    Scene,
    add_polygon,
    check_cells,
    gmsh_model,
    scene_from_gmsh,
    summary,
)


def incline_scene(comm, h=25.0, quads=False, size=1000.0, slope=0.2, intercept=458.6) -> Scene:
    import dolfinx_forms as df

    y0, y1 = intercept, slope * size + intercept
    assert 0 < y0 < size and 0 < y1 < size, "the line must cross both vertical sides"
    check_cells("incline_scene", 2 * (size / h) ** 2 if h > 0 else 0.0)
    polys = [
        np.array([[0, 0], [size, 0], [size, y1], [0, y0]]),
        np.array([[0, y0], [size, y1], [size, size], [0, size]]),
    ]
    bodies = [
        Body(name, i + 1, df.Polygon(p), np.array([p.min(axis=0), p.max(axis=0)]))
        for i, (name, p) in enumerate(zip(["lower", "upper"], polys))
    ]
    tol = 1e-8 * size

    def side(x):
        return np.isclose(x[0], 0.0, atol=tol) | np.isclose(x[0], size, atol=tol)

    def line(x):
        return np.abs(x[1] - slope * x[0] - intercept) < tol * np.hypot(1, slope)

    markers = {
        "lower_bottom": (1, lambda x: np.isclose(x[1], 0.0, atol=tol), 0),
        "upper_top": (2, lambda x: np.isclose(x[1], size, atol=tol), 1),
        "lower_sides": (3, side, 0),
        "upper_sides": (4, side, 1),
        "lower_interface": (5, line, 0),
        "upper_interface": (6, line, 1),
    }
    with gmsh_model(comm, "incline") as gmsh:
        if comm.rank == 0:
            for p in polys:
                add_polygon(gmsh, p)
            gmsh.model.geo.synchronize()
            # quads: blossom may leave triangles, so mesh at 2h, recombine, subdivide (all quads)
            f = gmsh.model.mesh.field.add("MathEval")
            gmsh.model.mesh.field.setString(f, "F", repr(float(2 * h if quads else h)))
            gmsh.model.mesh.field.setAsBackgroundMesh(f)
            gmsh.option.setNumber("Mesh.RecombineAll", int(quads))
            gmsh.option.setNumber("Mesh.SubdivisionAlgorithm", int(quads))
            gmsh.model.mesh.generate(2)
        box = np.array([[0.0, min(y0, y1) - 2 * h], [size, max(y0, y1) + 2 * h]])
        return scene_from_gmsh(comm, bodies, markers, [(0, 1)], h, contact_box=box)


#: the supports of demos/inclined_interface.py: --supports help, and what metrics.json records
SUPPORTS_HELP = (
    "uniaxial: u_x of the uniform uniaxial state on top and bottom; held: top u_x = 0, bottom on "
    "rollers with its middle point fixed"
)
SUPPORTS = {
    "uniaxial": "top: u_y = -d, u_x = e_xx (x - 500); bottom: u_y = 0, u_x = e_xx (x - 500); "
    "sides free (e_xx: lateral strain of the uniform uniaxial state, penalty compliance included)",
    "held": "top: u_y = -d, u_x = 0; bottom: u_y = 0 (rollers), u_x = 0 at the bottom vertex "
    "nearest to (500, 0); sides free",
}


def bottom_vertex(mesh, x0):
    """The marker of the vertex on the bottom y = 0 nearest to (x0, 0) (the held supports'
    fixed point of demos/inclined_interface.py)."""
    from dolfinx_forms.fem.boundary import nearest_vertex_marker

    return nearest_vertex_marker(mesh, (x0, 0.0), lambda x: np.isclose(x[1], 0.0))


if __name__ == "__main__":
    import argparse

    from mpi4py import MPI

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--h", type=float, default=25.0)
    ap.add_argument("--quads", action="store_true")
    args = ap.parse_args()
    line = summary(incline_scene(MPI.COMM_WORLD, h=args.h, quads=args.quads))
    if MPI.COMM_WORLD.rank == 0:
        print("incline:", line)
