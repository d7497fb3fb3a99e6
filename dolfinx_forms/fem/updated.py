"""A body-fitted mesh that follows the material: updated Lagrangian steps with contact rebuilt on
the current configuration (the body-fitted reference of the finite-strain MPM).

The single-step paths build their contact geometry once, in the reference configuration
(`contact_set`): right while the contact zone and its normals move little. A disc crushed to
40 % of its diameter is not such a case. Here each load step is one `ContactProblem` on the
mesh as it is at the step's start, Omega_n:

* the bulk residual is the MPM's (`mpm.finite_strain.UpdatedLaw`: R = int_{Omega_n} (1 / det
  F_n) tau(F, f, h_n) f^-T : grad v with f = I + grad du, F = f F_n), F_n and the history h_n
  at the quadrature points of the body-fitted cells (`Quadrature` Functions, no projection:
  the points are material points, since the mesh moves with the P1 displacement);
* each body's contact shape is the polygon of its current boundary (the mesh's boundary
  vertices, exact for P1 cells), so closest points, normals and the intermediate surface
  (eqs 21-25) are those of the deformed body; rigid obstacles keep their own poses;
* after the step: F_n <- f F_n and h_n <- the law's `history_update` at every quadrature point
  (the law's own UFL), the mesh nodes move by du, the obstacles advance.

Only P1 (triangles) and Q1 (quadrilaterals) on first-order geometry: then moving the nodes by du
moves every quadrature point by du, exactly.
"""

from __future__ import annotations

import basix
import numpy as np
import ufl
from dolfinx import fem

from dolfinx_forms import _cpp
from dolfinx_forms.fem import jit_memo
from dolfinx_forms.fem.history import CELLS
from dolfinx_forms.fem.laws import as_law, law_key
from dolfinx_forms.mpm import records
from dolfinx_forms.mpm.finite_strain import UpdatedLaw
from dolfinx_forms.solvers.newton import quasi_static
from dolfinx_forms.solvers.options import options
from dolfinx_forms.solvers.problem import ContactProblem


def boundary_loops(mesh, cell_tags, tag):
    """The closed loops of body `tag`'s boundary, in order, the same on every rank (each rank's
    boundary facets gathered, their nodes matched by their coordinates now): a list of (local
    geometry-node index (n,), -1 where this rank does not hold the node; coordinates (n, 2))."""
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim - 1, tdim)
    mesh.topology.create_connectivity(tdim - 1, 0)
    f2c, f2v = mesh.topology.connectivity(tdim - 1, tdim), mesh.topology.connectivity(tdim - 1, 0)
    fmap = mesh.topology.index_map(tdim - 1)
    x = mesh.geometry.x[:, :2]
    # vertex -> geometry node: first-order cells list their vertices and nodes in one order
    vmap = mesh.topology.index_map(0)
    v2g = np.full(vmap.size_local + vmap.num_ghosts, -1)
    v2g[mesh.topology.connectivity(tdim, 0).array] = mesh.geometry.dofmap.array
    ncells = mesh.topology.index_map(tdim).size_local + mesh.topology.index_map(tdim).num_ghosts
    tags = np.zeros(ncells, np.int32)
    tags[cell_tags.indices] = cell_tags.values
    edges = []
    for f in range(fmap.size_local):
        cells = f2c.links(f)
        if len(cells) == 1 and tags[cells[0]] == tag:
            edges.append(x[v2g[f2v.links(f)]].ravel())
    edges = np.concatenate(mesh.comm.allgather(np.array(edges).reshape(-1, 4)))
    ends = edges.reshape(-1, 2, 2)
    points, ids = np.unique(np.round(ends.reshape(-1, 2), 12), axis=0, return_inverse=True)
    ids = ids.reshape(-1, 2)
    nbr = {}
    for a, b in ids:
        nbr.setdefault(a, []).append(b)
        nbr.setdefault(b, []).append(a)
    if any(len(v) != 2 for v in nbr.values()):
        raise ValueError(f"body {tag}: its boundary is not a set of closed loops")
    seen, loops = np.zeros(len(points), bool), []
    for start in range(len(points)):
        if seen[start]:
            continue
        loop, prev, cur = [start], -1, start
        seen[start] = True
        while True:
            a, b = nbr[cur]
            nxt = a if a != prev else b
            if nxt == start:
                break
            loop.append(nxt)
            seen[nxt] = True
            prev, cur = cur, nxt
        loops.append(np.array(loop))
    # local node of each loop point (reference coordinates match exactly: the same mesh)
    local = {tuple(np.round(p, 12)): i for i, p in enumerate(x)}
    return [
        (np.array([local.get(tuple(points[k]), -1) for k in loop]), points[loop]) for loop in loops
    ]


class UpdatedLagrangian:
    """Bodies of a body-fitted `scene` (P1/Q1) over load steps on a moving mesh (module
    docstring). laws: {tag: finite-strain Law}; obstacles, dirichlet: as `ContactProblem`
    (Dirichlet values are one step's increments); degree: quadrature degree of F_n and the
    history; reactions: boundary names whose support reactions each step records;
    problem_kw: `solvers.options` keywords (mu, eps0, enforcement, ...). A step's results are
    in `record` (taken before the commit: afterwards the step's problem sees the new mesh)."""

    def __init__(self, scene, laws, *, obstacles=(), dirichlet=(), degree=2, reactions=(),
                 timer=None, log=print, **problem_kw):  # fmt: skip
        jit_memo.install()  # new forms every step: FFCx's answers kept in memory
        self.scene, self.mesh, self.comm = scene, scene.mesh, scene.mesh.comm
        if self.mesh.geometry.cmap.degree != 1:
            raise ValueError("UpdatedLagrangian: first-order geometry only")
        if problem_kw.get("degree", 1) != 1:
            raise ValueError("UpdatedLagrangian: degree 1 (P1/Q1) only: the mesh moves with du")
        self.laws = {int(t): as_law(w) for t, w in laws.items()}
        for t, w in self.laws.items():
            if not w.finite_strain:
                raise ValueError(f"body {t}: UpdatedLagrangian needs a finite-strain law")
        self.obstacles, self.dirichlet = list(obstacles), list(dirichlet)
        self.degree, self.timer, self.log = int(degree), timer, log
        self.reactions = list(reactions)
        options(**problem_kw)  # an unknown option fails here
        # Newton halves a step that raises the residual across a change of the active set, as
        # on the MPM's quasi-static steps (unless the caller's NewtonOptions set rise_limit):
        # the same soft plastic zone under a changing contact set. J2's disc crush wandered at
        # 60-280 from 4011 in a whole platen move (h = 0.5) and was given 8 load steps a move;
        # now it takes whole moves with no cut-back (docs/demos/disc_crush.md)
        self.problem_kw = quasi_static(problem_kw)
        d = self.d = self.mesh.geometry.dim
        cell = self.mesh.ufl_cell()

        def space(dim):
            e = ufl.VectorElement("Quadrature", cell, self.degree, dim=dim, quad_scheme="default")
            return fem.FunctionSpace(self.mesh, e)

        self.Fn = fem.Function(space(d * d), name="F_n")
        self.Fn.x.array.reshape(-1, d * d)[:] = np.eye(d).ravel()
        # one history Function and one UpdatedLaw per distinct law: one kernel for all its bodies
        self.history, self.updated, shared = {}, {}, {}
        for t, w in self.laws.items():
            key = law_key(w)
            if key not in shared:
                k = w.history_size
                h = fem.Function(space(k), name="history") if k else None
                if k:
                    h.x.array.reshape(-1, k)[:] = np.asarray(w.initial_history, float)
                shared[key] = (h, UpdatedLaw(w, self.Fn, h, self.degree))
            self.history[t], self.updated[t] = shared[key]
        self.qpoints = basix.make_quadrature(CELLS[cell.cellname()], self.degree)[0]
        tdim = self.mesh.topology.dim
        imap = self.mesh.topology.index_map(tdim)
        self.cells = np.arange(imap.size_local + imap.num_ghosts, dtype=np.int32)
        self.loops = {
            b.tag: boundary_loops(self.mesh, scene.cell_tags, b.tag) for b in scene.bodies
        }
        self.step_count, self.problem, self._commit = 0, None, {}
        self.h, self.friction, self.record = scene.h_contact, {}, {}  # records.transfer_friction
        self.update_shapes()

    # ------------------------------------------------------------------ geometry
    def update_shapes(self):
        """Each body's contact shape: the polygon of its current boundary (one loop: the outer
        boundary; bodies with holes are not handled)."""
        x = self.mesh.geometry.x[:, :2]
        for b in self.scene.bodies:
            loops = self.loops[b.tag]
            if len(loops) != 1:
                raise ValueError(f"body {b.name!r}: one boundary loop expected, got {len(loops)}")
            nodes, ref = loops[0]
            pos = np.full((len(nodes), 2), np.nan)
            pos[nodes >= 0] = x[nodes[nodes >= 0]]
            # each node's position from a rank that holds it (the lowest)
            allpos = np.stack(self.comm.allgather(pos))
            have = ~np.isnan(allpos[..., 0])
            first = np.argmax(have, axis=0)
            cur = allpos[first, np.arange(len(nodes))]
            b.shape = _cpp.Polygon(np.ascontiguousarray(cur))
            b.bbox = np.array([cur.min(axis=0), cur.max(axis=0)])

    # ------------------------------------------------------------------ one step
    def step(self, label=None, substeps=1):
        """One load step: solve for du on the current mesh, commit F_n and the history, move
        the mesh and the obstacles; `substeps` load steps on the step's mesh (Newton's own
        cut-back halves them further where it fails). Returns the step's ContactProblem (kept
        until the next step); its forces are in `record`: after the commit its residual is on
        the new mesh."""
        problem = ContactProblem(self.scene, self.updated, dirichlet=self.dirichlet,
                                 obstacles=self.obstacles, timer=self.timer, log=self.log,
                                 **options(**self.problem_kw))  # fmt: skip
        keys = problem.contact.names(self.scene)
        try:
            records.transfer_friction(self, problem, keys)
            label = label or f"updated Lagrangian step {self.step_count + 1}"
            problem.solve(int(substeps), 1.0, label=label)
        except Exception:
            problem.destroy()
            raise
        self.record = self._record(problem, keys)
        # the friction history of the next step: its points follow their obstacle's motion
        # (a sticking point moves with it; the next step's points are matched within h)
        self.friction = records.friction_record(problem, keys)
        motion = {ob.name: ob for ob in self.obstacles}
        for key, (x, *rest) in list(self.friction.items()):
            if key[1] in motion:
                x = x + motion[key[1]].step_displacement(x, 1.0)
            self.friction[key] = (x, *rest)
        self.commit(problem.u)
        for ob in self.obstacles:
            ob.advance(1.0)
        if self.problem is not None:
            self.problem.destroy()
        self.problem = problem
        self.step_count += 1
        return problem

    def _record(self, problem, keys):
        """{obstacle: dict(fx, fy, moment, half_width)}: the force on each obstacle and half
        the extent in x of its active contact zone; {boundary: reaction} (all ranks)."""
        cs, out = problem.contact, {}
        for k, (g, s) in enumerate(zip(cs.pairs, cs.committed)):
            if g.obstacle is not None and s is not None:
                out[keys[k][1]] = records.half_width(g, s)
        widths = {k: v for d in self.comm.allgather(out) for k, v in d.items()}
        rec = records.obstacle_forces(problem, self.obstacles)
        for name, r in rec.items():
            r["half_width"] = widths.get(name, 0.0)
        for name in self.reactions:
            rec[name] = problem.reaction(name).tolist()
        return rec

    def commit(self, du):
        """F_n <- (I + grad du) F_n and h_n <- history_update at every quadrature point, then
        the nodes move by du (first-order geometry: node i of a cell is dof i of P1/Q1)."""
        d, dd = self.d, self.d * self.d
        nq = len(self.qpoints)  # explicit shapes: a rank may hold no cells
        dofs_F = self.Fn.function_space.dofmap.list.array.reshape(len(self.cells), nq)
        newF = self.Fn.x.array.reshape(-1, dd).copy()
        for t, law in self.updated.items():
            cells = self.scene.body_cells(t).astype(np.int32)
            if len(cells) == 0:  # none of this body on this rank
                continue
            key = id(law)
            if self._commit.get(key, (None,))[0] is not du:
                F, f, _ = law.kinematics(du)
                parts = [F[i, j] for i in range(d) for j in range(d)]
                h = self.history[t]
                if h is not None:
                    new = law.law.on(self.mesh).history_update(F, f, h)
                    parts += [new[i] for i in range(law.law.history_size)]
                self._commit[key] = (du, fem.Expression(ufl.as_vector(parts), self.qpoints))
            vals = self._commit[key][1].eval(cells).reshape(len(cells), nq, -1)
            newF[dofs_F[cells].ravel()] = vals[:, :, :dd].reshape(-1, dd)
            h = self.history[t]
            if h is not None:
                k = law.law.history_size
                hd = h.function_space.dofmap.list.array.reshape(len(self.cells), nq)
                h.x.array.reshape(-1, k)[hd[cells].ravel()] = vals[:, :, dd:].reshape(-1, k)
        self.Fn.x.array[:] = newF.ravel()
        # move the nodes: geometry node of cell c, local i <-> dof of V of cell c, local i
        V = du.function_space
        bs = V.dofmap.index_map_bs
        nv = V.dofmap.dof_layout.num_dofs
        gmap = self.mesh.geometry.dofmap.array.reshape(len(self.cells), nv)
        vmap = V.dofmap.list.array.reshape(len(self.cells), nv)
        u = du.x.array.reshape(-1, bs)
        self.mesh.geometry.x[gmap.ravel(), :d] += u[vmap.ravel()]
        self.update_shapes()
