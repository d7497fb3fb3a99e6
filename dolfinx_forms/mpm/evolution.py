"""The level sets follow the bodies (ILS-MPM section 3): after a converged step, each body's
displacement increment is extended off the body along the normal (eq 20), its level set is
advected by it (eq 19, HJ-WENO5 + TVD-RK3) and reinitialised when |grad phi| drifts from 1."""

import numpy as np
from mpi4py import MPI

from dolfinx_forms import _cpp
from dolfinx_forms.common import allreduce_array


def evolve(sim, problem, scene):
    """Extend du off each body (eq 20), advect its level set (eq 19), reinitialise on drift."""
    V = problem.V
    nx, ny = len(sim.xlines), len(sim.ylines)
    xdof = V.tabulate_dof_coordinates()[:, :2]
    i = np.rint((xdof[:, 0] - sim.xlines[0]) / sim.h).astype(np.int64)
    j = np.rint((xdof[:, 1] - sim.ylines[0]) / sim.h).astype(np.int64)
    node = i + nx * j
    owned = V.dofmap.index_map.size_local
    cell_dofs = V.dofmap.list.array.reshape(-1, 4)
    u = problem.u.x.array.reshape(-1, 2)
    out = dict(area_levelset={}, advection_substeps={}, reinitialized={}, gradient_drift={})
    nn = sim.grid.num_nodes
    sim.grid_increments = {}
    for b in sim.bodies:
        dofs = np.unique(cell_dofs[scene.cell_tags.find(b.tag)])
        dofs = dofs[dofs < owned]
        vel = np.zeros((nn, 2))
        has = np.zeros(nn, np.int8)
        vel[node[dofs]] = u[dofs]
        has[node[dofs]] = 1
        vel = allreduce_array(sim.comm, vel, MPI.SUM)
        has = allreduce_array(sim.comm, has, MPI.MAX)
        phi = sim.levelsets[b.tag]
        # known: every node of the body's active cells. The FE increment on the outside
        # nodes of cut cells is the unfitted method's own (smooth, ghost-penalised)
        # extension, second order at the interface; the constant normal extension of
        # eq 20 fills the rest of the grid. (Extending from the inside nodes only would move
        # the interface by du at a node up to h inside: first order, and the level set
        # would lag the material by ~ h grad(du) per step.)
        known = (has > 0).reshape(ny, nx)
        # a window of the grid around the body (its active nodes grown by 6 cells and the
        # step's largest motion): a grain costs its own size, not the grid's. Beyond it the
        # level set keeps its (positive, far-field) values.
        jj, ii = np.nonzero(known)
        m = 6 + int(np.ceil(np.abs(vel).max() / sim.h))
        i0, i1 = max(ii.min() - m, 0), min(ii.max() + m, nx - 1)
        j0, j1 = max(jj.min() - m, 0), min(jj.max() + m, ny - 1)
        win = (slice(j0, j1 + 1), slice(i0, i1 + 1))
        sub = _cpp.StructuredGrid(sim.xlines[i0 : i1 + 1], sim.ylines[j0 : j1 + 1])
        values = phi.values  # (ny, nx) copy
        v = vel.reshape(ny, nx, 2)[win].reshape(-1, 2)
        v = _cpp.extend_normal(
            sub,
            values[win].ravel(),
            known[win].ravel().astype(np.int8),
            np.ascontiguousarray(v),
        )
        full = np.zeros((ny, nx, 2))
        full[win] = v.reshape(j1 - j0 + 1, i1 - i0 + 1, 2)
        sim.grid_increments[b.name] = full.reshape(-1, 2)
        r = _cpp.advect_levelset(_cpp.LevelSet(sub, values[win].ravel()), v, 1.0, 0.5)
        new = r["levelset"]
        drift = float(_cpp.levelset_gradient_drift(new, 3 * sim.h))
        redo = drift > sim.reinit_drift
        if redo:
            new = _cpp.reinitialize(new)
        area = float(_cpp.levelset_area(new))
        values[win] = new.values
        sim.levelsets[b.tag] = _cpp.LevelSet(sim.grid, values.ravel())
        out["area_levelset"][b.name] = area
        out["advection_substeps"][b.name] = int(r["substeps"])
        out["reinitialized"][b.name] = bool(redo)
        out["gradient_drift"][b.name] = drift
    return out
