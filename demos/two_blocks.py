#!/usr/bin/python3
"""Two blocks with friction (Tur, Fuenmayor & Wriggers 2009): a central stick zone between two
slip zones of opposite slip.

Physics. A short block [10,30]x[10,20] mm rests on a long block [0,40]x[0,10] mm (plane
strain, E = 1e5 MPa, nu = 0.3 for both, Coulomb friction mu = 1.0). The top of the upper
block is moved down by 1.6e-3 mm and held horizontally (u_x = 0 there); the bottom of the
lower block is clamped (u = 0: the restatement of the example in the ILS-MPM paper does not
give its support, clamping is our choice, recorded in metrics.json). The left and right sides
of the lower block carry the parabolic tractions of the paper, converted to N, mm, MPa with y
measured from the lower-left corner:
  p_x = 0.4 y (10 - y) MPa pushing inward (+x on the left side, -x on the right side),
  p_y = 1.0 y (10 - y) MPa upward on both sides
(the paper's 4e11 y(0.01 - y) Pa and 1e12 y(0.01 - y) Pa). The lateral squeeze shortens the
top of the lower block towards its centre while the upper block is held: the tangential
traction is antisymmetric, largest at the ends of the upper block, where the interface slips
first (in opposite directions) when friction is low enough. The displacement and
the side loads are ramped together over --steps load steps (lam: 0 -> 1).

The check. No closed-form solution exists; the paper (and Tur et al.) show a central stick
zone flanked by two slip zones whose slip has opposite sign, reached in 8 Newton iterations.
metrics.json reports the stick zone [x_l, x_r] (ends of the state == stick points), the slip
zones on each side, the sign of the committed plastic slip g_t^p on each side (t = (-n_y, n_x)
with n pointing from the lower to the upper block, i.e. t = -e_x on this flat interface: the
lower block moving inward gives g_t^p > 0 on the left, < 0 on the right), the Newton
iterations per load step, the reaction on the top of the upper block, the peak pressure, the
largest traction ratio max |p_t|/p_n (the friction coefficient below which slip starts) and
sigma_x along y = 5 mm (sigma_x_line.csv: the cellwise stress averaged at the vertices, as
y = 5 is a grid line of the gmsh meshes). tractions.csv holds p_n, p_t (= tau_t along t),
g_n, g_t^p and the state of the last load step ("slip": slipped during that step).

What we find. With the loads as restated (ramped together, one step) the interface does NOT
slip at mu = 1.0: max |p_t|/p_n = 0.73 at h = 0.2 (0.76 at h = 1, 0.72 at h = 0.1; 0.86 and
0.90 with eps0 = 0.1 and 0.01), reached at the ends of the upper block. The expected pattern
(central stick zone, two end slip zones of opposite slip) appears for mu below that ratio,
e.g. --mu 0.5: stick zone [12.2, 27.8] mm at h = 0.2, 8 Newton iterations.

Penalty. eps_n = eps_t = eps0 h / E (eq 51). Default eps0 = 1.0, the paper's value: at
mu = 0.5, h = 0.2 the stick zone is the same with eps0 = 1 and 0.1 ([12.21, 27.79] mm), the
reaction changes by 1.5 %, the mean interpenetration eps_n p is 1.4 % of the imposed
displacement (metrics: interface_compliance_ratio), and Newton needs 8 iterations (11 with
eps0 = 0.1; with eps0 = 0.01 it does not converge in 25 iterations even after 6 cut-backs).

Discretization. --discretization conforming (default): gmsh meshes of size h, quadrilaterals
(or --triangles). --discretization cut: both blocks are level sets on one uniform grid of Q1
quadrilaterals over [0, 40] x [0, 20] (x spacing h, y spacing 20/ny <= h with ny odd), so the
interface y = 10 cuts the middle of a cell row: that row is active in both blocks, each
integrating only its own half (ghost penalty on the faces of cut cells, --ghost-penalty), and
the side tractions are integrated up to y = 10 only; --quads/--triangles are ignored. The
contact points are those of the conforming path (they depend only on the bodies and h).
Cut (default ghost penalty 0.01) against gmsh quadrilaterals at equal h (relative L2):
sigma_x along y = 5 within 0.4 %; p_n within 0.3 %; p_t within 0.6 % at mu = 0.5 and
2.1-3.0 % at mu = 1 (h = 0.2 / 1), where the corner traction is not capped by friction: the
difference sits in the cell next to each corner of the upper block (stress singularity), and
away from the corners p_t agrees to 1 %. A ghost penalty of 0.1 roughly doubles these
differences near the corners. Gmsh triangles and quadrilaterals differ
by as much (p_n 1.3-2.1 %, p_t 1.8-7.8 %). Newton iterations as conforming (2 at mu = 1; at
mu = 0.5: 6 against 5 at h = 1, 8 at h = 0.2); stick zone [12.22, 27.78] mm at h = 0.2.

Method: level sets of both bodies on a fine structured grid over the pair's search box, the
intermediate contact surface (eqs 21-24), closest points (eq 25), penalty + Coulomb return
mapping with its consistent tangent (Algorithm 1, eq 48), Newton with load steps.
"""

import sys
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI

from dolfinx_forms.cli import (DemoParser, add_discretization, bounded,
                               check_discretization, petsc_options)
from dolfinx_forms.output import atomic_output, finish, gather_points, plot_tractions
from dolfinx_forms.results import PhaseTimer, new_metrics
from dolfinx_forms.solver import (ContactProblem, ContactSolverError, Dirichlet,
                                  Traction, solver_metrics, zone_ends)
from meshes.cut import cut_counts, two_blocks_cut_scene
from meshes.two_blocks import two_blocks_scene

DEFAULTS = dict(h=0.2, E=1.0e5, nu=0.3, mu=1.0, displacement=1.6e-3, eps0=1.0, steps=1)
WIDTH, HEIGHT, WIDTH_UPPER = 40.0, 10.0, 20.0  # mm (Tur et al. 2009)
PX, PY = 0.4, 1.0  # side tractions p = P y (10 - y) MPa
LINE_Y = 5.0  # sigma_x is sampled along y = LINE_Y (mid-height of the lower block)


def parse(argv):
    p = DemoParser(prog="two_blocks.py", description=__doc__.split("\n\n")[0])
    p.add_out("results/two_blocks")
    add_discretization(p)
    p.add_argument("--h", type=bounded("--h", 0, 2.5, lo_open=True), default=DEFAULTS["h"],
                   help="mesh size of both blocks (mm; cut: grid spacing)")
    p.add_argument("--E", type=bounded("--E", 0, None, lo_open=True), default=DEFAULTS["E"],
                   help="Young's modulus of both blocks (MPa)")
    p.add_argument("--nu", type=bounded("--nu", -1, 0.5, lo_open=True, hi_open=True),
                   default=DEFAULTS["nu"])
    p.add_argument("--mu", type=bounded("--mu", 0, None), default=DEFAULTS["mu"],
                   help="Coulomb friction coefficient")
    p.add_argument("--displacement", type=bounded("--displacement", 0, None, lo_open=True),
                   default=DEFAULTS["displacement"], help="downward displacement of the top (mm)")
    p.add_argument("--eps0", type=bounded("--eps0", 0, None, lo_open=True),
                   default=DEFAULTS["eps0"],
                   help="penalty factor of eq 51: eps = eps0 h / E")
    p.add_argument("--steps", type=int, choices=range(1, 101), metavar="[1..100]",
                   default=DEFAULTS["steps"],
                   help="load steps (displacement and side loads together)")
    p.add_argument("--degree", type=int, choices=[1, 2], default=1)
    cells = p.add_mutually_exclusive_group()
    cells.add_argument("--quads", dest="quads", action="store_true", default=True,
                       help="quadrilateral cells (default; the cut grid is always quadrilateral)")
    cells.add_argument("--triangles", dest="quads", action="store_false",
                       help="triangular cells (conforming only; ignored with cut)")
    p.add_argument("--petsc", action="append", default=[], metavar="KEY=VALUE",
                   help="PETSc option for the linear solver (prefix ils_), repeatable")
    a = p.parse_args(argv)
    check_discretization(p, a)
    a.petsc = petsc_options(p, a.petsc)
    return a


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    comm = MPI.COMM_WORLD
    params = dict(vars(args), quads=args.quads or args.discretization == "cut",
                  width_lower=WIDTH, height=HEIGHT, width_upper=WIDTH_UPPER,
                  side_traction=f"p_x = {PX} y (10 - y) MPa inward, p_y = {PY} y (10 - y) MPa "
                                "upward on lower_left and lower_right",
                  supports="lower_bottom clamped (u = 0); upper_top u_x = 0, "
                           "u_y = -displacement; displacement and side loads ramped together")
    metrics = new_metrics("blocks", args.discretization, params)
    timer = PhaseTimer(metrics)

    with timer.phase("mesh"):
        if args.discretization == "cut":  # uniform grid; the interface y = HEIGHT is mid-cell
            scene = two_blocks_cut_scene(comm, h=args.h, width_lower=WIDTH, height=HEIGHT,
                                         width_upper=WIDTH_UPPER)
            metrics["mesh"]["cut_cells"] = cut_counts(scene)
        else:
            scene = two_blocks_scene(comm, h=args.h, quads=args.quads, width_lower=WIDTH,
                                     height=HEIGHT, width_upper=WIDTH_UPPER)
    y = ufl.SpatialCoordinate(scene.mesh)[1]
    prof = y * (HEIGHT - y)
    d = args.displacement
    problem = ContactProblem(
        scene, {b.tag: (args.E, args.nu) for b in scene.bodies}, mu=0.0, eps0=args.eps0,
        band=args.h, degree=args.degree, petsc_options=args.petsc, timer=timer,
        ghost_penalty=args.ghost_penalty,
        dirichlet=[Dirichlet("lower_bottom", None, 0.0),
                   Dirichlet("upper_top", 0, 0.0),
                   Dirichlet("upper_top", 1, lambda lam: -d * lam)],
        tractions=[Traction("lower_left", ufl.as_vector((PX * prof, PY * prof))),
                   Traction("lower_right", ufl.as_vector((-PX * prof, PY * prof)))])
    # Friction from the start, with zero committed plastic slip (u = 0 here)
    problem.set_friction(args.mu)
    try:
        problem.solve(args.steps, label="blocks")
    except ContactSolverError as e:
        sys.stderr.write(f"two_blocks.py: {e}\n")
        return 1

    reaction = problem.reaction("upper_top")
    pts = gather_points(problem)
    line = sigma_x_line(problem, LINE_Y, np.linspace(0.0, WIDTH, 161))
    metrics["mesh"].update(h_contact=scene.h_contact, num_dofs=problem.num_dofs,
                           num_cells=scene.mesh.topology.index_map(2).size_global)
    metrics["solver"] = solver_metrics(problem)
    if comm.rank == 0:
        evaluate(metrics, pts, reaction, problem)
        metrics["results"]["sigma_x_line"] = {
            "y": LINE_Y, "file": "sigma_x_line.csv",
            "min": float(np.min(line[:, 1])), "max": float(np.max(line[:, 1]))}
    timer.stop()
    with atomic_output(args.out, comm, force=args.force) as folder:
        if comm.rank == 0:
            np.savetxt(Path(folder) / "sigma_x_line.csv", line, delimiter=",", fmt="%.12e",
                       header="x,sigma_x", comments="")
        finish(folder, metrics, problem, pts,
               plot=(lambda path: plot(path, pts, metrics)) if comm.rank == 0 else None)
    if comm.rank == 0:
        r = metrics["results"]
        fmt = lambda z: "none" if z is None else f"[{z[0]:.3f}, {z[1]:.3f}]"  # noqa: E731
        print(f"two blocks: reaction on the top {r['reaction'][0]:.5g}, "
              f"{r['reaction'][1]:.5g} N/mm; "
              f"stick zone {fmt(r['stick_zone'])}, slip zones {fmt(r['slip_zone_left'])} "
              f"(slip sign {r['slip_sign_left']}) and {fmt(r['slip_zone_right'])} "
              f"(slip sign {r['slip_sign_right']}); max {r['max_newton_iterations']} Newton "
              f"iterations per step")
        print(f"results in {Path(args.out).resolve()}")
    return 0


def sigma_x_line(problem, y, xs, body=0):
    """sigma_x (plane strain, MPa) in scene.bodies[body] at the points (xs, y); (n, 2) array
    [x, sigma_x] on rank 0 (None elsewhere). The stress is interpolated cellwise (DG/DQ 1)
    and averaged at the vertices (continuous P1/Q1): y = 5 is a grid line of the gmsh meshes,
    where the cellwise stress jumps, and point location on an edge finds one of its two
    cells or both depending on round-off. Only that body's cells are used: the bodies have
    their own vertices, and on a cut scene their cells overlap along the interface."""
    from dolfinx import fem, geometry, la

    mesh, scene = problem.mesh, problem.scene
    pts = np.column_stack([xs, np.full_like(xs, y), np.zeros_like(xs)])
    family = "DQ" if scene.cell_type == "quadrilateral" else "DG"
    sig = problem.stress((family, 1))  # the laws' stress, cellwise (DG/DQ 1) tensor
    Q = sig.function_space
    # vertex average over the body's owned cells (sums and counts added across ranks)
    V1 = fem.FunctionSpace(mesh, ("Lagrange", 1))
    n_owned = mesh.topology.index_map(mesh.topology.dim).size_local
    tags = scene.cell_tags
    mine = tags.indices[(tags.values == scene.bodies[body].tag) & (tags.indices < n_owned)]
    nv = V1.dofmap.dof_layout.num_dofs
    dq = Q.dofmap.list.array.reshape(-1, nv)[mine]
    cg = V1.dofmap.list.array.reshape(-1, nv)[mine]
    assert np.allclose(Q.tabulate_dof_coordinates()[dq], V1.tabulate_dof_coordinates()[cg])
    total, count = fem.Function(V1), fem.Function(V1)
    sxx = sig.x.array.reshape(-1, 4)[:, 0]  # blocked dofs: (xx, xy, yx, yy) per node
    total.x.array[:] = np.bincount(cg.ravel(), sxx[dq].ravel(), len(total.x.array))
    count.x.array[:] = np.bincount(cg.ravel(), None, len(count.x.array))
    for f in (total, count):
        f.x.scatter_reverse(la.ScatterMode.add)
    with np.errstate(invalid="ignore", divide="ignore"):
        total.x.array[:] /= count.x.array
    total.x.scatter_forward()
    tree = geometry.BoundingBoxTree(mesh, mesh.topology.dim, mine)
    hits = geometry.compute_colliding_cells(mesh, geometry.compute_collisions(tree, pts), pts)
    vals = np.full(len(xs), np.nan)
    for k in range(len(xs)):
        cells = hits.links(k)
        if len(cells):  # continuous: any cell holding the point gives the same value
            vals[k] = total.eval(pts[k:k + 1], cells[:1])[0]
    allv = mesh.comm.gather(vals, root=0)
    if mesh.comm.rank != 0:
        return None
    v = np.full(len(xs), np.nan)
    for a in allv:  # first rank that owns a cell containing the point
        v = np.where(np.isnan(v), a, v)
    return np.column_stack([xs, v])


def evaluate(metrics, pts, reaction, problem):
    """Stick and slip zones, slip signs and pressures from the contact points (sorted by x)."""
    x, state, slip, p, w = pts["x"], pts["state"], pts["slip"], pts["p_n"], pts["w"]
    active = state != 0
    xl, xr = zone_ends(x, active, pts["gap_n"])
    sl, sr = zone_ends(x, state == 1)
    res = metrics["results"]

    def side(mask):
        a, b = zone_ends(x, mask)
        if a is None:
            return None, None, None
        s = np.sum(w[mask] * slip[mask])  # weighted plastic slip of the zone
        return [float(a), float(b)], int(np.sign(s)), float(np.max(np.abs(slip[mask])))

    centre = 0.5 * (sl + sr) if sl is not None else 0.5 * (x[0] + x[-1])
    left, sign_l, max_l = side((state == 2) & (x < centre))
    right, sign_r, max_r = side((state == 2) & (x > centre))
    iters = [s.iterations for s in problem.steps]
    res.update(
        reaction=[float(reaction[0]), float(reaction[1])],
        contact_half_width=None if xl is None else 0.5 * (xr - xl),
        contact_zone=None if xl is None else [float(xl), float(xr)],
        peak_pressure=float(p.max()) if p.size else None,
        contact_force=float(np.sum(w * p)),
        stick_half_width=None if sl is None else 0.5 * (sr - sl),
        stick_zone=None if sl is None else [float(sl), float(sr)],
        slip_zone_left=left, slip_zone_right=right,
        slip_sign_left=sign_l, slip_sign_right=sign_r,
        max_slip_left=max_l, max_slip_right=max_r,
        opposite_slip=None if sign_l is None or sign_r is None else bool(sign_l * sign_r < 0),
        num_points={"open": int(np.sum(state == 0)), "stick": int(np.sum(state == 1)),
                    "slip": int(np.sum(state == 2))},
        max_newton_iterations=int(max(iters)) if iters else None,
        # max |p_t|/p_n over the active points: the friction coefficient below which slip starts
        max_traction_ratio=float(np.max(np.abs(pts["p_t"][active]) / p[active]))
        if active.any() else None,
        # penalty compliance: interpenetration eps_n p at the mean pressure / imposed displacement
        interface_compliance_ratio=float(problem.eps_n * np.sum(w * p) / np.sum(w[active])
                                         / metrics["parameters"]["displacement"])
        if active.any() else None)


def plot(path, pts, metrics):
    r = metrics["results"]
    mu = metrics["parameters"]["mu"]
    curves = {"+- mu p_n (slip limit)": (np.r_[pts["x"], np.nan, pts["x"]],
                                          np.r_[mu * pts["p_n"], np.nan, -mu * pts["p_n"]])}
    if r["stick_zone"] is not None:  # mark the stick zone on the axis
        curves["stick zone"] = (np.array(r["stick_zone"]), np.zeros(2))
    plot_tractions(path, pts, curves,
                   title=f"two blocks (Tur et al. 2009), mu = {metrics['parameters']['mu']}, "
                         f"h = {metrics['mesh']['h_contact']:.3g} mm")


if __name__ == "__main__":
    sys.exit(main())
