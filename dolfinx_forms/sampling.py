"""Point values of the solution: a stress component of one body along a line of points.

    xs = np.linspace(0.0, 40.0, 161)
    sx = stress_at_points(problem, np.column_stack([xs, np.full_like(xs, 5.0)]))  # sigma_xx

The stress is the laws' own output stress (`problem.stress`), interpolated cellwise (DG/DQ 1)
and averaged at the vertices into a continuous P1/Q1 field: a line along mesh edges (a grid
line of a structured or gmsh mesh) crosses cells whose cellwise stresses jump there, and point
location on an edge finds one of its two cells or both depending on round-off; the average is
the same from either side. Only the body's own cells are used: bodies have their own vertices,
and on a cut scene their cells overlap along the interface.
"""

import numpy as np

__all__ = ["stress_at_points"]


def stress_at_points(problem, points, component=(0, 0), body=0):
    """Stress component sigma_ij (component=(i, j)) of scene.bodies[body] at the points
    ((n, gdim) or (n, 3)); an (n,) array on rank 0 (NaN where no cell of the body holds the
    point), None on the other ranks. Collective."""
    from dolfinx import fem, geometry, la

    mesh, scene = problem.mesh, problem.scene
    tdim, gdim = mesh.topology.dim, mesh.geometry.dim
    pts = np.zeros((len(points), 3))
    pts[:, : np.shape(points)[1]] = points
    family = "DQ" if scene.cell_type == "quadrilateral" else "DG"
    sig = problem.stress((family, 1))
    Q = sig.function_space
    # vertex average over the body's owned cells (sums and counts added across ranks)
    V1 = fem.FunctionSpace(mesh, ("Lagrange", 1))
    n_owned = mesh.topology.index_map(tdim).size_local
    tags = scene.cell_tags
    mine = tags.indices[(tags.values == scene.bodies[body].tag) & (tags.indices < n_owned)]
    nv = V1.dofmap.dof_layout.num_dofs
    dq = Q.dofmap.list.array.reshape(-1, nv)[mine]
    cg = V1.dofmap.list.array.reshape(-1, nv)[mine]
    assert np.allclose(Q.tabulate_dof_coordinates()[dq], V1.tabulate_dof_coordinates()[cg])
    total, count = fem.Function(V1), fem.Function(V1)
    s_ij = sig.x.array.reshape(-1, gdim * gdim)[:, component[0] * gdim + component[1]]
    total.x.array[:] = np.bincount(cg.ravel(), s_ij[dq].ravel(), len(total.x.array))
    count.x.array[:] = np.bincount(cg.ravel(), None, len(count.x.array))
    for f in (total, count):
        f.x.scatter_reverse(la.ScatterMode.add)
    with np.errstate(invalid="ignore", divide="ignore"):
        total.x.array[:] /= count.x.array
    total.x.scatter_forward()
    tree = geometry.BoundingBoxTree(mesh, tdim, mine)
    hits = geometry.compute_colliding_cells(mesh, geometry.compute_collisions(tree, pts), pts)
    vals = np.full(len(pts), np.nan)
    for k in range(len(pts)):
        cells = hits.links(k)
        if len(cells):  # continuous: any cell holding the point gives the same value
            vals[k] = total.eval(pts[k : k + 1], cells[:1])[0]
    allv = mesh.comm.gather(vals, root=0)
    if mesh.comm.rank != 0:
        return None
    v = np.full(len(pts), np.nan)
    for a in allv:  # the first rank that owns a cell holding the point
        v = np.where(np.isnan(v), a, v)
    return v
