"""Post-processing of a solved problem: a stress component along a line of points, and the
contact, stick and slip zones of an interface that runs along x.

    xs = np.linspace(0.0, 40.0, 161)
    sx = stress_at_points(problem, np.column_stack([xs, np.full_like(xs, 5.0)]))  # sigma_xx
    metrics["results"].update(contact_zones(gather_points(problem)))  # on rank 0

The stress is the laws' own output stress (`problem.stress`), interpolated cellwise (DG/DQ 1)
and averaged at the vertices into a continuous P1/Q1 field: a line along mesh edges (a grid
line of a structured or gmsh mesh) crosses cells whose cellwise stresses jump there, and point
location on an edge finds one of its two cells or both depending on round-off; the average is
the same from either side. Only the body's own cells are used: bodies have their own vertices,
and on a cut scene their cells overlap along the interface.
"""

import numpy as np

__all__ = ["stress_at_points", "contact_zones", "tangential_jumps"]


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


def contact_zones(pts):
    """Zones of the contact points along x (output.gather_points: sorted by x), None where a
    zone is empty: contact_zone [x_l, x_r] of the active points (ends at the zero of the gap)
    and its half-width, peak pressure, contact force (sum w p_n), stick_zone of the points in
    state stick and its half-width, the slip zones left and right of the stick zone's centre
    (points in state slip) with the sign of their weighted plastic slip (slip_sign_left/right),
    its largest magnitude (max_slip_left/right), opposite_slip, and the points per state."""
    from dolfinx_forms.solvers.problem import zone_ends

    x, state, slip, p, w = (pts[k] for k in ("x", "state", "slip", "p_n", "w"))
    xl, xr = zone_ends(x, state != 0, pts["gap_n"])
    sl, sr = zone_ends(x, state == 1)

    def side(mask):
        a, b = zone_ends(x, mask)
        if a is None:
            return None, None, None
        s = np.sum(w[mask] * slip[mask])  # weighted plastic slip of the zone
        return [float(a), float(b)], int(np.sign(s)), float(np.max(np.abs(slip[mask])))

    centre = 0.5 * (sl + sr) if sl is not None else 0.5 * (x[0] + x[-1]) if x.size else 0.0
    left, sign_l, max_l = side((state == 2) & (x < centre))
    right, sign_r, max_r = side((state == 2) & (x > centre))
    return dict(
        contact_half_width=None if xl is None else 0.5 * (xr - xl),
        contact_zone=None if xl is None else [float(xl), float(xr)],
        peak_pressure=float(p.max()) if p.size else None,
        contact_force=float(np.sum(w * p)),
        stick_half_width=None if sl is None else 0.5 * (sr - sl),
        stick_zone=None if sl is None else [float(sl), float(sr)],
        slip_zone_left=left,
        slip_zone_right=right,
        slip_sign_left=sign_l,
        slip_sign_right=sign_r,
        max_slip_left=max_l,
        max_slip_right=max_r,
        opposite_slip=None if sign_l is None or sign_r is None else bool(sign_l * sign_r < 0),
        num_points={n: int(np.sum(state == k)) for k, n in enumerate(("open", "stick", "slip"))},
    )


def tangential_jumps(problem):
    """The committed total tangential jump g_t (elastic + plastic) at the contact points of
    every pair: (x, g_t) on rank 0 (empty arrays elsewhere), in the order of the pairs."""
    local = [(g.points[:, 0], s["g_t"]) for g, s in zip(problem.pairs, problem.contact.committed)]
    every = [v for part in problem.comm.gather(local, root=0) or [] for v in part]
    return tuple(np.concatenate([v[i] for v in every] or [[]]) for i in (0, 1))
