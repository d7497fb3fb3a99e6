"""The level sets follow the bodies (ILS-MPM section 3). After a converged step each body's
displacement increment is extended off the body along the normal (eq 20); then its level set
(`levelset_update`, reinitialised whenever |grad phi| drifts from 1 by more than reinit_drift):

- "advection" (the default): advected by it (eq 19, HJ-WENO5 + TVD-RK3, the paper's choice);
- "flow": advected by the velocity whose flow over the unit pseudo-time is the points' map
  x + du to second order (`flow_velocity`), not by du (whose flow is x + du + (du . grad)
  du / 2: first order, a rolling cylinder's level set lost 2.9 % of its area);
- "reference-map": rebuilt from the material points, phi(x) = phi_0(X(x)), phi_0 the body's
  initial shape and X(x) the reference position at x, the MLS fit (eqs 38-45, linear basis)
  of the points' reference positions X_p. This is the reference map technique of Eulerian
  solid mechanics (Kamrin, Rycroft & Nave 2012), with the map carried by the points instead
  of advected.

Advection follows the FE increment at the nodes, which resolves a contact's indentation, but
it accumulates its error over the steps and follows the extended increment, not the points:
over a granular deposit's hundreds of steps a grain's level set drifted from its points by up
to +20 % of its area (a tail grown into a gap next to its neighbours) and the run stopped.
The reference map cannot drift from the points: it is exact for any affine motion (rigid
motions included: the linear MLS basis reproduces them) at every step, whatever the number of
steps; but its fit smooths the increment over about h, which in nine_discs' quasi-static
steps of 1e-4 mm moved a contour by 7e-5 mm against advection and the largest force by 12 %.
So advection stays the default of the quasi-static scenes, and the reference map is the choice
where bodies travel far and long (a granular column: `demos/granular_column.py`'s default)."""

import numpy as np
from mpi4py import MPI
from scipy.spatial import cKDTree

from dolfinx_forms import _cpp
from dolfinx_forms.common import allreduce_array

# how the level sets follow the bodies (module docstring); the first is the default
LEVELSET_UPDATES = ("advection", "flow", "reference-map")


def evolve(sim, problem, scene):
    """Extend du off each body (eq 20), then advect its level set (eq 19; by the flow velocity
    with "flow") or rebuild it from the points ("reference-map"); reinitialise on drift."""
    V = problem.V
    nx, ny = len(sim.xlines), len(sim.ylines)
    xdof = V.tabulate_dof_coordinates()[:, :2]
    i = np.rint((xdof[:, 0] - sim.xlines[0]) / sim.h).astype(np.int64)
    j = np.rint((xdof[:, 1] - sim.ylines[0]) / sim.h).astype(np.int64)
    owned = V.dofmap.index_map.size_local
    cell_dofs = V.dofmap.list.array.reshape(-1, 4)
    u = problem.u.x.array.reshape(-1, 2)
    out = dict(area_levelset={}, advection_substeps={}, reinitialized={}, gradient_drift={})
    sim.grid_increments = {}
    big = np.iinfo(np.int64).max
    nb = len(sim.bodies)
    # known: every node of the body's active cells. The FE increment on the outside nodes of
    # cut cells is the unfitted method's own (smooth, ghost-penalised) extension, second order
    # at the interface; the constant normal extension of eq 20 fills the rest of the grid.
    # (Extending from the inside nodes only would move the interface by du at a node up to h
    # inside: first order, and the level set would lag the material by ~ h grad(du) per step.)
    # A window of the grid around the body (its known nodes grown by 6 cells and the step's
    # largest motion): a grain costs its own size, not the grid's. Beyond it the level set
    # keeps its (positive, far-field) values. Each reduction serves all bodies at once.
    lo, hi, umax = np.full((nb, 2), big), np.full((nb, 2), -1), np.zeros(nb)
    body_dofs = []
    for k, b in enumerate(sim.bodies):
        dofs = np.unique(cell_dofs[scene.body_cells(b.tag)])
        dofs = dofs[dofs < owned]
        body_dofs.append(dofs)
        if len(dofs):
            lo[k], hi[k] = (i[dofs].min(), j[dofs].min()), (i[dofs].max(), j[dofs].max())
            umax[k] = np.abs(u[dofs]).max()
    lo, hi = allreduce_array(sim.comm, lo, MPI.MIN), allreduce_array(sim.comm, hi, MPI.MAX)
    umax = allreduce_array(sim.comm, umax, MPI.MAX)
    boxes, vs, knowns = [], [], []
    for k, (b, dofs) in enumerate(zip(sim.bodies, body_dofs)):
        m = 6 + int(np.ceil(umax[k] / sim.h))
        i0, i1 = max(lo[k, 0] - m, 0), min(hi[k, 0] + m, nx - 1)
        j0, j1 = max(lo[k, 1] - m, 0), min(hi[k, 1] + m, ny - 1)
        sim._grow(b.tag, (i0, i1, j0, j1))
        wx, wy = i1 - i0 + 1, j1 - j0 + 1
        at = (j[dofs] - j0) * wx + (i[dofs] - i0)
        v = np.zeros((wy * wx, 2))
        known = np.zeros(wy * wx, np.int8)
        v[at] = u[dofs]
        known[at] = 1
        boxes.append((i0, i1, j0, j1))
        vs.append(v)
        knowns.append(known)
    split = np.cumsum([len(k) for k in knowns])[:-1]
    vs = np.split(allreduce_array(sim.comm, np.concatenate(vs), MPI.SUM), split)
    knowns = np.split(allreduce_array(sim.comm, np.concatenate(knowns), MPI.MAX), split)
    for b, (i0, i1, j0, j1), v, known in zip(sim.bodies, boxes, vs, knowns):
        phi, (a0, _, b0, _) = sim.levelsets[b.tag], sim.windows[b.tag]
        wx, wy = i1 - i0 + 1, j1 - j0 + 1
        win = (slice(j0 - b0, j1 - b0 + 1), slice(i0 - a0, i1 - a0 + 1))  # in the body's window
        sub = sim.subgrid((i0, i1, j0, j1))
        values = phi.values  # the body's window, a copy
        v = _cpp.extend_normal(sub, np.ascontiguousarray(values[win]).ravel(), known, v)
        sim.grid_increments[b.name] = ((i0, i1, j0, j1), v.reshape(wy, wx, 2))
        if sim.levelset_update == "reference-map":
            new, r = reference_map(sub, sim.shapes[b.tag], sim.points[b.tag], sim.h), {}
        else:
            if sim.levelset_update == "flow":
                v = flow_velocity(sub, values[win], v.reshape(wy, wx, 2), known.reshape(wy, wx))
            r = _cpp.advect_levelset(_cpp.LevelSet(sub, values[win].ravel()), v, 1.0, 0.5)
            new = r["levelset"]
        # reinitialising moves the contour by O(h^3), which competes with a quasi-static
        # step's motion (1e-4 mm in nine_discs): only when |grad phi| has drifted
        drift = float(_cpp.levelset_gradient_drift(new, 3 * sim.h))
        redo = drift > sim.reinit_drift
        if redo:
            new = _cpp.reinitialize(new)
        area = float(_cpp.levelset_area(new))
        values[win] = new.values
        sim.levelsets[b.tag] = _cpp.LevelSet(phi.grid, values.ravel())
        out["area_levelset"][b.name] = area
        out["advection_substeps"][b.name] = int(r.get("substeps", 0))
        out["reinitialized"][b.name] = bool(redo)
        out["gradient_drift"][b.name] = drift
    return out


def flow_velocity(grid, phi, du, known):
    """The steady velocity whose flow over the unit pseudo-time maps x to x + du(x) to second
    order in du: v = du - (du . grad) du / 2 (du (ny, nx, 2) on the uniform `grid`, extended
    off the body; `known` (ny, nx): the nodes where du is the FE increment; phi the level set).

    Eq 19 with v = du (the paper's choice) moves the level set by the flow map of du, which is
    x + du + (du . grad) du / 2 + O(du^3), not by the points' x + du: for a rotation by d theta
    per step the flow of du = (R - I) x is a rotation by sin d theta and a shrink by
    exp(cos d theta - 1), so a rolling cylinder's advected level set lost area d theta^2 per
    step (2.9 % by the end of the rolling demo, growing as t^3; 0.12 % with this v). The flow
    of a linear field A x is now exp(A - A^2 / 2) = I + A + O(A^3). A translation (du uniform)
    is unchanged. The correction is taken by central differences where a node and its four
    neighbours hold the FE increment, and extended along the normal (eq 20) from there (not
    differenced on the extension, whose gradient kinks on the diagonals of a corner).

    Not the default: on a synthetic homogeneous compression (8 steps of 3 % and -4 %) eq 19's
    level set over-predicts the area by 0.8-1.0 %, this one by 0.01-0.2 %; but in
    block_compression that over-prediction had hidden the block's corner error, whose force
    error at the defaults then grows from 1.2-1.8 % to 1.5-3.5 % (all four laws), with
    checkerboard warnings at the platens' edges."""
    h = grid.max_spacing
    gy, gx = np.gradient(du, h, axis=(0, 1))  # d du / dy, d du / dx
    corr = du[..., :1] * gx + du[..., 1:] * gy
    k = known.astype(bool)
    full = k.copy()
    full[1:-1, 1:-1] &= k[:-2, 1:-1] & k[2:, 1:-1] & k[1:-1, :-2] & k[1:-1, 2:]
    full[[0, -1], :] = full[:, [0, -1]] = False
    if not full.any():  # a body of a few cells: first order
        return du.reshape(-1, 2)
    corr = _cpp.extend_normal(
        grid, np.ascontiguousarray(phi).ravel(), full.ravel().astype(np.int8), corr.reshape(-1, 2)
    )
    return du.reshape(-1, 2) - 0.5 * corr


def reference_map(grid, shape, points, h, reach=3.0):
    """The level set phi(x) = phi_0(X(x)) of a body on `grid` (module docstring): a signed
    distance near the body where the motion is rigid (a stretch makes |grad phi| drift from 1,
    and `evolve` reinitialises past reinit_drift, as after advection).

    X at the grid nodes within `reach` h of a material point is the MLS fit of the points'
    reference positions: the cells the zero contour crosses and their neighbours (whose values
    the reinitialisation's C1 interpolant uses) lie within 3 h of the points, which are at most
    ~h/3 apart inside the body. Outside the body the fit extrapolates, so it must be well
    conditioned: a support holding only a few nearly collinear points (rcond 3e-8 in a deposit)
    mapped a node 2 h below a grain into its reference shape; the support is widened until
    rcond >= 1e-3. The nodes beyond `reach` are outside the body and get their distance to the
    nearest point (|grad| = 1, and a few h from the contour, where no contact looks). A safety
    net: a node more than h from every point is outside (phi >= its distance - h), whatever the
    fit says; the points fill the body at spacings far below h."""
    nodes = grid.nodes()
    d = cKDTree(points.x).query(nodes)[0]
    near = d < reach * h
    fit = _cpp.MLSProjector(points.x, h, rcond_min=1e-3, max_widenings=6)
    phi = d.copy()
    from dolfinx_forms.fem.cut import shape_values  # dolfinx: not at the descriptions' import

    X = fit.project(points.X, np.ascontiguousarray(nodes[near]))["values"]
    phi[near] = shape_values(shape, X, clamp=True)
    far = d > h
    phi[far] = np.maximum(phi[far], d[far] - h)
    return _cpp.LevelSet(grid, phi)
