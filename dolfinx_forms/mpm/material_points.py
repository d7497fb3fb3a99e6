"""Material points of the implicit MPM (sections 3.1 and 4.4 of the seed paper).

A body's material points carry position x, reference volume vol0 (mass / density: constant, so
mass is conserved exactly), current volume vol and Cauchy stress [s_xx, s_yy, s_xy]. They are
seeded at integration points with positive weights: the 3x3 Gauss points of interior cells and
the points of the sub-triangle rule of the inside polygon of cut cells (`_cpp.cut_quadrature`,
the polygon the cut integration uses), so that the volumes sum to the body's discrete area.

After a converged step (displacement increment du on the step's grid) each point moves with the
FE interpolant in the cell that holds it and updates its stress by the objective
small-strain increment (stated choice: Jaumann rate, first order in the step)

    sigma <- sigma + C : d_eps + dW sigma - sigma dW,   d_eps = sym grad du, dW = skew grad du,

with C the body's linear law (`law_tangent`), and vol <- vol det(I + grad du). A rigid rotation
therefore rotates the stress instead of creating it, and a rigid translation leaves everything
but x unchanged (exactly: grad du = 0 there up to round-off).

The arrays of a body's points are replaced at each update, never written in place: a snapshot
of the state (`ImplicitMPM.snapshot`) shares them (`MaterialPoints.shared`).

Parallel: the points of every body are replicated on all ranks (seeded from the owned cells
and gathered); the increment at a point is taken from the rank that owns its grid cell.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import basix
import numpy as np
import ufl
from dolfinx import fem, mesh as dmesh
from mpi4py import MPI

from dolfinx_forms import _cpp
from dolfinx_forms.common import allreduce_array
from dolfinx_forms.fem.cut import CUT, shape_values
from dolfinx_forms.geometry.pairs import grid_locator

DEGREE = 4  # 3x3 Gauss points per cell: the cut cells' rule (cut.CutIntegration)


@dataclass
class MaterialPoints:
    """The material points of one body (see the module docstring)."""

    tag: int
    x: np.ndarray  # (n, 2)
    vol0: np.ndarray  # (n,)
    vol: np.ndarray  # (n,)
    stress: np.ndarray  # (n, 3) Cauchy [xx, yy, xy]
    F: np.ndarray = None  # (n, 2, 2) deformation gradient (identity when seeded)
    history: np.ndarray = None  # (n, k) the law's history (finite_strain.py)
    v: np.ndarray = None  # (n, 2) velocity (dynamics.py; zero when seeded)
    a: np.ndarray = None  # (n, 2) acceleration
    X: np.ndarray = None  # (n, 2) reference position (x when seeded): the reference map

    def __post_init__(self):
        if self.v is None:
            self.v = np.zeros_like(self.x)
        if self.a is None:
            self.a = np.zeros_like(self.x)
        if self.F is None:
            self.F = np.tile(np.eye(2), (len(self.vol0), 1, 1))
        if self.history is None:
            self.history = np.zeros((len(self.vol0), 0))
        if self.X is None:
            self.X = self.x.copy()

    def __len__(self):
        return len(self.vol0)

    def shared(self):
        """Another MaterialPoints over the same arrays. A step replaces these arrays (`update`,
        `update_finite`, the dynamics' kinematics) and never writes into them, so a snapshot
        of the points needs no copy (400 grains: 153 MB a step on each rank)."""
        return dataclasses.replace(self)


def law_tangent(law):
    """The constant Voigt matrix C (3, 3) of a linear small-strain law, [s_xx, s_yy, s_xy] =
    C [e_xx, e_yy, 2 e_xy], evaluated from the law's own UFL stress (one expression for the
    stress everywhere) on a one-cell mesh. ValueError for a nonlinear law."""
    if not law.linear:
        raise ValueError(
            f"{type(law).__name__}: the MPM stress update needs a linear small-strain law "
            "(C : d_eps); nonlinear laws are not supported on the multi-step path"
        )
    m = dmesh.create_unit_square(MPI.COMM_SELF, 1, 1, dmesh.CellType.quadrilateral)
    x = ufl.SpatialCoordinate(m)
    C = np.zeros((3, 3))
    point = np.array([[0.5, 0.5]])
    law = law.on(m)
    for k, G in enumerate(([[1, 0], [0, 0]], [[0, 0], [0, 1]], [[0, 0.5], [0.5, 0]])):
        u = ufl.as_matrix(G) * x
        s = fem.Expression(law.stress(u), point).eval(np.array([0], np.int32)).reshape(2, 2)
        C[:, k] = s[0, 0], s[1, 1], s[0, 1]
    return C


def _cell_frames(scene, cells):
    """Origin (n, 2) and edge lengths (n, 2) of axis-aligned grid cells (DOLFINx vertex order
    (0,0), (1,0), (0,1), (1,1))."""
    g = scene.mesh.geometry.dofmap.array.reshape(-1, 4)[cells]
    x = scene.mesh.geometry.x[g][:, :, :2]
    return x[:, 0], np.stack([x[:, 1, 0] - x[:, 0, 0], x[:, 2, 1] - x[:, 0, 1]], axis=1)


def quadrature_points(scene, cells, degree=DEGREE):
    """Physical coordinates (len(cells), nq, 2) of the reference Gauss points of `degree` in
    each cell: the points of a `Quadrature` element of that degree."""
    X, _ = basix.make_quadrature(basix.CellType.quadrilateral, degree)
    o, e = _cell_frames(scene, cells)
    return o[:, None, :] + X[None, :, :] * e[:, None, :]


def _canonical(scene, cells):
    """Corner (n, 2), extents (n, 2) and the permutation (n, 4) that puts each cell's vertices
    in tensor order (x-fastest) by their coordinates: the same points for a cell whatever the
    vertex order of its partition (1 and 2 ranks seed identical points)."""
    g = scene.mesh.geometry.dofmap.array.reshape(-1, 4)[cells]
    x = scene.mesh.geometry.x[g][:, :, :2]
    lo, hi = x.min(axis=1), x.max(axis=1)
    key = (x[:, :, 0] > 0.5 * (lo + hi)[:, None, 0]) + 2 * (
        x[:, :, 1] > 0.5 * (lo + hi)[:, None, 1]
    )
    return lo, hi - lo, np.argsort(key, axis=1)


def seed(scene, integration, tag):
    """Material points of body `tag` at the positive integration points of its active cells
    (owned cells of every rank, gathered), zero stress."""
    comm = scene.mesh.comm
    owned = scene.mesh.topology.index_map(2).size_local
    cells = scene.body_cells(tag)
    cells = cells[cells < owned]
    kind = integration.kind[cells]
    X, w = basix.make_quadrature(basix.CellType.quadrilateral, DEGREE)
    inner = cells[kind != CUT]
    o, e, _ = _canonical(scene, inner)
    xs = [(o[:, None, :] + X[None] * e[:, None, :]).reshape(-1, 2)]
    vs = [(w[None, :] * np.prod(e, axis=1)[:, None]).ravel()]
    cut = cells[kind == CUT]
    if len(cut):
        o, e, perm = _canonical(scene, cut)
        # phi at the exact vertex coordinates (not the dof coordinates, which carry round-off
        # that differs with the partition and flips the sign of phi at a vertex on the contour)
        g = scene.mesh.geometry.dofmap.array.reshape(-1, 4)[cut]
        xv = np.take_along_axis(g, perm, axis=1).ravel()
        phi = shape_values(scene.cut.levelsets[tag], scene.mesh.geometry.x[xv, :2]).reshape(-1, 4)
        q = _cpp.cut_quadrature(np.ascontiguousarray(phi), 2)
        owner = np.repeat(np.arange(len(cut)), np.diff(q["offsets"]))
        # sub-triangles of zero area (a contour through a vertex) carry no mass: no point
        keep = q["weights"] > 1e-12
        xs.append((o[owner] + q["points"] * e[owner])[keep])
        vs.append((q["weights"] * np.prod(e, axis=1)[owner])[keep])
    x = np.concatenate(comm.allgather(np.concatenate(xs)))
    vol = np.concatenate(comm.allgather(np.concatenate(vs)))
    return MaterialPoints(int(tag), x, vol.copy(), vol.copy(), np.zeros((len(vol), 3)))


# a cut cell holding less than this share of its area inside the body: its outer nodes are
# held by the ghost penalty alone, so the gradient there is not the body's. The points in it
# take the field of the cell one spacing inward (extrapolated): on the 100-grain column the
# points in slivers of 0.5-1.5 % against a wall reached det F 0.005 beside 2.3 (issue 31)
SLIVER = 0.1


def displacement_at(problem, tag, points, max_distance):
    """Displacement (n, 2) and its gradient (n, 2, 2) of problem.u at points of body `tag`
    (replicated on all ranks), from the rank owning each point's cell. A point outside the
    body's active cells (its level set moved past it by O(h^2)) takes the nearest active cell
    within max_distance (extrapolated); a point in a sliver (a cut cell less than SLIVER
    inside) takes the cell of the point max_distance inward along -grad phi (extrapolated).
    Returns (u, grad u, number of points outside); RuntimeError if a point is further than
    max_distance from every cell."""
    scene, V = problem.scene, problem.V
    comm = scene.mesh.comm
    loc = grid_locator(scene, tag, 1, owned_only=True)
    cells, X, outside, chosen = _locate(loc, comm, points, max_distance)
    lost = np.flatnonzero(chosen == comm.size)
    if len(lost):
        raise RuntimeError(
            f"material point {points[lost[0]]} of body {tag} is not within {max_distance:g} of "
            "an active cell of its body (the level set and the points have parted)"
        )
    n_out = comm.allreduce(int(np.sum(outside[chosen == comm.rank] > 0)), op=MPI.SUM)
    fraction = getattr(problem.integration, "fraction", None)
    if fraction is not None:
        thin = np.zeros(len(points), np.int32)
        mine = np.flatnonzero(chosen == comm.rank)
        thin[mine] = fraction[cells[mine]] < SLIVER
        thin = np.flatnonzero(allreduce_array(comm, thin, MPI.MAX))
        if len(thin):
            _, grad = scene.cut.levelsets[tag].evaluate(points[thin])
            n = grad / np.maximum(np.linalg.norm(grad, axis=1), 1e-300)[:, None]
            inward = points[thin] - max_distance * n
            c2, X2, _, ch2 = _locate(loc, comm, inward, max_distance)
            found = ch2 < comm.size  # else the sliver's own cell stays
            cells[thin[found]], X[thin[found]] = c2[found], X2[found]
            chosen[thin[found]] = ch2[found]
            here = found & (ch2 == comm.rank)
            e = _cell_frames(scene, c2[here])[1]
            X[thin[here]] += (points[thin[here]] - inward[here]) / e  # the point's own X
    take = np.flatnonzero(chosen == comm.rank)
    val = np.zeros((len(points), 6))
    if len(take):
        dofs = V.dofmap.list.array.reshape(-1, 4)[cells[take]]
        # the cells' edge lengths, gathered once per cell (many points share one)
        used, at = np.unique(cells[take], return_inverse=True)
        e = _cell_frames(scene, used)[1][at]
        r = _cpp.q1_evaluate(problem.u.x.array.reshape(-1, 2), dofs, X[take], e)
        # columns 2..: du_x/dx, du_x/dy, du_y/dx, du_y/dy
        val[take, :2], val[take, 2:] = r["values"], r["grad"].reshape(-1, 4)
    val = allreduce_array(comm, val, MPI.SUM)
    grad = val[:, 2:].reshape(-1, 2, 2)  # grad[:, c, d] = du_c / dx_d
    return val[:, :2], grad, n_out


def _locate(loc, comm, points, max_distance):
    """(cells, X, outside, chosen): each rank's best owned cell of each point and the rank
    whose cell is used, the nearest over the ranks (ties: the lowest rank; comm.size: none
    within max_distance): the same cell as on one rank whatever the partition."""
    cells, X, outside = loc.locate(points, max_distance)
    best = allreduce_array(comm, outside, MPI.MIN)
    mine = (cells >= 0) & (outside == best)
    chosen = allreduce_array(comm, np.where(mine, comm.rank, comm.size).astype(np.int32), MPI.MIN)
    return cells, X, outside, chosen


def update(points, du, grad, C):
    """Move the points by du and update stress, F and volume (module docstring); in place."""
    e = np.stack([grad[:, 0, 0], grad[:, 1, 1], grad[:, 0, 1] + grad[:, 1, 0]], axis=1)
    s = points.stress
    w = 0.5 * (grad[:, 0, 1] - grad[:, 1, 0])  # dW = [[0, w], [-w, 0]]
    rot = np.stack([2 * w * s[:, 2], -2 * w * s[:, 2], w * (s[:, 1] - s[:, 0])], axis=1)
    points.stress = s + e @ C.T + rot
    points.x = points.x + du
    f = np.eye(2)[None] + grad
    points.F = f @ points.F
    points.vol = points.vol * det2(f)


def update_finite(points, du, grad, point_law):
    """Finite strain (finite_strain.py): F <- f F_n, stress and history from the law at F,
    vol = vol0 det F; in place."""
    f = np.eye(2)[None] + grad
    points.stress, points.history = point_law(points.F, f, points.history)
    points.F = f @ points.F
    points.x = points.x + du
    points.vol = points.vol0 * det2(points.F)


def det2(F):
    """det of (n, 2, 2) matrices (closed form)."""
    return F[:, 0, 0] * F[:, 1, 1] - F[:, 0, 1] * F[:, 1, 0]
