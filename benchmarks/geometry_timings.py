#!/usr/bin/python3
"""Throughput of the compiled point location and level-set advection (these were timing
prints in the tests): `CellLocator` build and locate on a 200 x 200 unit-square mesh
(triangles and quadrilaterals, 1e5 random points, and the same points sorted row by row),
beside DOLFINx's BoundingBoxTree; `advect_levelset` of a circle on a 250^2 grid by 0.1 h.
Minimum of 5 runs each. Writes benchmarks/results/geometry_timings.json and prints a table.

Run: /usr/bin/python3 benchmarks/geometry_timings.py
"""

import json
import time
from pathlib import Path

import dolfinx.geometry
import numpy as np
from dolfinx.mesh import CellType, create_unit_square
from mpi4py import MPI

from dolfinx_forms import _cpp

REPEATS = 5


def best(f):
    """The minimum wall time of REPEATS calls of f and its last result."""
    times = []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        r = f()
        times.append(time.perf_counter() - t0)
    return min(times), r


def location(cell_type, n=200, num_points=100_000):
    mesh = create_unit_square(MPI.COMM_SELF, n, n, cell_type)
    nverts = 3 if cell_type == CellType.triangle else 4
    x, cells = mesh.geometry.x, mesh.geometry.dofmap.array.reshape(-1, nverts)
    pts = np.random.default_rng(2).random((num_points, 2))
    build, loc = best(lambda: _cpp.CellLocator(x, cells))
    locate, _ = best(lambda: loc.locate(pts, 0.0))
    order = np.lexsort((pts[:, 0], np.floor(pts[:, 1] * n)))
    sorted_pts = np.ascontiguousarray(pts[order])
    locate_sorted, _ = best(lambda: loc.locate(sorted_pts, 0.0))
    p3 = np.c_[pts, np.zeros(len(pts))]
    tree_build, tree = best(lambda: dolfinx.geometry.BoundingBoxTree(mesh, 2))
    collide, _ = best(
        lambda: dolfinx.geometry.compute_colliding_cells(
            mesh, dolfinx.geometry.compute_collisions(tree, p3), p3
        )
    )
    return dict(
        case=f"locate {cell_type.name} {n}x{n}",
        cells=len(cells),
        points=num_points,
        locator_build_s=build,
        locate_s=locate,
        locate_sorted_s=locate_sorted,
        dolfinx_tree_build_s=tree_build,
        dolfinx_collisions_s=collide,
    )


def advection(n=250):
    g = _cpp.StructuredGrid.uniform([0.0, 0.0], [1.0, 1.0], [n, n])
    X = g.nodes()
    phi = _cpp.LevelSet(g, np.hypot(X[:, 0] - 0.4, X[:, 1] - 0.5) - 0.25)
    v = np.tile([0.1 / n, 0.05 / n], (X.shape[0], 1))
    t, res = best(lambda: _cpp.advect_levelset(phi, v))
    return dict(case=f"advect {n}x{n} by 0.1 h", substeps=res["substeps"], advect_s=t)


def main():
    rows = [location(c) for c in (CellType.triangle, CellType.quadrilateral)] + [advection()]
    for r in rows:
        cells = (f"{k} {v:.3g}" if isinstance(v, float) else f"{k} {v}" for k, v in r.items())
        print(", ".join(cells))
    out = Path(__file__).resolve().parent / "results"
    out.mkdir(exist_ok=True)
    (out / "geometry_timings.json").write_text(json.dumps(rows, indent=1))
    print(f"results in {out / 'geometry_timings.json'}")


if __name__ == "__main__":
    main()
