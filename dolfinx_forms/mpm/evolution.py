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
    owned = V.dofmap.index_map.size_local
    cell_dofs = V.dofmap.list.array.reshape(-1, 4)
    u = problem.u.x.array.reshape(-1, 2)
    out = dict(area_levelset={}, advection_substeps={}, reinitialized={}, gradient_drift={})
    sim.grid_increments = {}
    big = np.iinfo(np.int64).max
    for b in sim.bodies:
        dofs = np.unique(cell_dofs[scene.cell_tags.find(b.tag)])
        dofs = dofs[dofs < owned]
        ib, jb = i[dofs], j[dofs]
        # known: every node of the body's active cells. The FE increment on the outside
        # nodes of cut cells is the unfitted method's own (smooth, ghost-penalised)
        # extension, second order at the interface; the constant normal extension of
        # eq 20 fills the rest of the grid. (Extending from the inside nodes only would move
        # the interface by du at a node up to h inside: first order, and the level set
        # would lag the material by ~ h grad(du) per step.)
        # A window of the grid around the body (its known nodes grown by 6 cells and the
        # step's largest motion): a grain costs its own size, not the grid's. Beyond it the
        # level set keeps its (positive, far-field) values.
        n = len(dofs) > 0
        lo = allreduce_array(
            sim.comm, np.array([ib.min() if n else big, jb.min() if n else big]), MPI.MIN
        )
        hi = allreduce_array(
            sim.comm, np.array([ib.max() if n else -1, jb.max() if n else -1]), MPI.MAX
        )
        umax = sim.comm.allreduce(float(np.abs(u[dofs]).max()) if n else 0.0, op=MPI.MAX)
        m = 6 + int(np.ceil(umax / sim.h))
        i0, i1 = max(lo[0] - m, 0), min(hi[0] + m, nx - 1)
        j0, j1 = max(lo[1] - m, 0), min(hi[1] + m, ny - 1)
        sim._grow(b.tag, (i0, i1, j0, j1))
        phi, (a0, _, b0, _) = sim.levelsets[b.tag], sim.windows[b.tag]
        wx, wy = i1 - i0 + 1, j1 - j0 + 1
        at = (jb - j0) * wx + (ib - i0)
        v = np.zeros((wy * wx, 2))
        known = np.zeros(wy * wx, np.int8)
        v[at] = u[dofs]
        known[at] = 1
        v = allreduce_array(sim.comm, v, MPI.SUM)
        known = allreduce_array(sim.comm, known, MPI.MAX)
        win = (slice(j0 - b0, j1 - b0 + 1), slice(i0 - a0, i1 - a0 + 1))  # in the body's window
        sub = sim.subgrid((i0, i1, j0, j1))
        values = phi.values  # the body's window, a copy
        v = _cpp.extend_normal(sub, np.ascontiguousarray(values[win]).ravel(), known, v)
        sim.grid_increments[b.name] = ((i0, i1, j0, j1), v.reshape(wy, wx, 2))
        r = _cpp.advect_levelset(_cpp.LevelSet(sub, values[win].ravel()), v, 1.0, 0.5)
        new = r["levelset"]
        drift = float(_cpp.levelset_gradient_drift(new, 3 * sim.h))
        redo = drift > sim.reinit_drift
        if redo:
            new = _cpp.reinitialize(new)
        area = float(_cpp.levelset_area(new))
        values[win] = new.values
        sim.levelsets[b.tag] = _cpp.LevelSet(phi.grid, values.ravel())
        out["area_levelset"][b.name] = area
        out["advection_substeps"][b.name] = int(r["substeps"])
        out["reinitialized"][b.name] = bool(redo)
        out["gradient_drift"][b.name] = drift
    return out
