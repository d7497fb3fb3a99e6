#!/usr/bin/python3
"""Frictional sliding on an inclined interface (Annavarapu et al. 2014): slips iff mu < tan theta.

Physics. The square [0,1000]^2 mm is cut by the line y = 0.2 x + 458.6 (tan theta = 0.2) into
a lower and an upper body (plane strain, E = 1000 MPa, nu = 0.3), compressed from the top by
u_y = -1 mm. Under a uniform uniaxial vertical stress sigma_yy = -s (sigma_xx = tau_xy = 0)
the traction on the interface is vertical, t = (0, -s cos theta), so everywhere on it
  p_n = s cos^2 theta,  |tau_t| = s sin theta cos theta,  |tau_t| / p_n = tan theta = 0.2,
and Coulomb friction holds the interface iff mu >= tan theta. The top must not be free
horizontally (the upper body would slide away rigidly once mu < tan theta), and the supports
must not disturb the uniform state, so we prescribe on the top AND on the bottom the
horizontal displacement of that uniform state (default --supports uniaxial):
  top:    u_y = -d,  u_x = e_xx (x - 500)      bottom: u_y = 0,  u_x = e_xx (x - 500)
  sides:  free
with e_xx = nu (1 + nu) s / E the lateral (Poisson) strain of the uniaxial state and s the
stress that the imposed shortening d produces *including the penalty compliance* of the
interface (the penalty springs add a uniform jump g = eps_n tau_n n + eps_t tau_t t), so the
bonded penalised problem has exactly this uniform state. Sticking, the discrete solution is
this state up to the contact quadrature error (the Gauss points of the level-set contour
segments straddle the kinks of the shape functions at element edges): interior p_n within
7e-4 and tau_t within 2e-3 (relative L2) at the defaults, 2e-5 and 1.5e-4 with --gauss 5
--grid-refine 16. Below mu = tan theta the interface slips everywhere, restrained only by the
elastic shear of the bodies between the interface and the prescribed top and bottom.
--supports held instead holds the top at u_x = 0 and puts the bottom on rollers (u_y = 0,
u_x = 0 at the bottom vertex nearest to x = 500): the bonded traction ratio is then not
uniform (0.193-0.213 in the interior at h = 25, 0.192-0.211 at h = 100), and mu = 0.21 slips
at about a quarter of the points (interior plastic slip 1e-3 mm), so 0.19 and 0.21 are not
cleanly separated. (With the bottom-left corner fixed instead of the middle, mu = 0.21 slips
everywhere.)

The check. metrics.json reports the committed plastic slip g_t^p (the tangential jump that
remains: `slip` in tractions.csv) and the total tangential jump g_t along the interface, the
fraction of slipping points, the traction ratio |tau_t|/p_n, and the verdict `slips`.
Threshold: the interface slips if the plastic slip exceeds 1e-6 d (1e-6 mm) at a contact
point farther than one mesh size h from the free sides x = 0 and x = 1000. Sticking points
have exactly zero plastic slip (it is only created by the slip branch of the return mapping),
slipping ones ~5e-2 d at mu = 0.19, so any tolerance between round-off and ~1e-2 d gives
the same verdict; 1e-6 d keeps it scale-free. The end margin is needed because the
contact normals are wrong near the two points where the interface meets the free sides: there
both bodies' level sets are the distance to the same end point, so the intermediate level set
phi_int is degenerate outside the square and the normals of the first three level-set cells
(0.75 h) are off by up to 2.7 degrees. Even the bonded uniform state then shows |tau_t|/p_n
between 0.17 and 0.25 at those few points, which therefore slip at mu = 0.21 (6 points, 2 %
at h = 25, reported as `end_slip_points`; the amplitude does not decrease with h, the width
does). When the interface sticks (--supports uniaxial), pressure and shear errors against the
uniform state are reported (interior points). Default mu = 0.19: the slipping case.

Discretization. --discretization conforming (default): gmsh meshes of size h, triangles (or
--quads). --discretization cut: both bodies live on one uniform n x n grid of Q1
quadrilaterals over the square (n = round(1000 / h)), the lower one below and the upper one
above the interface, which cuts the grid cells (48 cut cells per body at h = 25, 12 at
h = 100; ghost penalty on their faces, --ghost-penalty); --quads/--triangles are ignored.
Same verdicts as conforming at h = 25 and 100: mu = 0.19 slips at every point, mu = 0.21
sticks away from the sides (the same 6 end points slip); sticking, the uniform state is
recovered with interior p_n within 3e-5 and tau_t within 2e-3 (relative L2) at the defaults.
Newton: 4 iterations at mu = 0.19 and 5 at mu = 0.21 (conforming 3 and 4) at h = 25. The cut
shapes add contact points of negligible weight (~1e-11 mm, in pairs) where the interface
passes through nodes of the level-set grid (366 points instead of 320 at h = 25); their
tractions are those of their neighbours, so they do not change the verdicts or errors.

Method: level sets of both bodies on a fine structured grid over the pair's search box, the
intermediate contact surface (eqs 21-24), closest points (eq 25), penalty + Coulomb return
mapping with its consistent tangent (Algorithm 1, eq 48), Newton with load steps.
"""

import sys
from pathlib import Path

import numpy as np
from mpi4py import MPI

from dolfinx_forms.cli import (DemoParser, add_discretization, bounded,
                               check_discretization, petsc_options)
from dolfinx_forms.output import atomic_output, finish, gather_points, plot_tractions
from dolfinx_forms.results import PhaseTimer, new_metrics
from dolfinx_forms.solver import (ContactProblem, ContactSolverError, Dirichlet,
                                  solver_metrics)
from meshes.cut import cut_counts, incline_cut_scene
from meshes.incline import incline_scene

SIZE, SLOPE, INTERCEPT = 1000.0, 0.2, 458.6  # mm; interface y = SLOPE x + INTERCEPT
X0 = SIZE / 2  # u_x = 0 at x = X0 on top and bottom (uniaxial supports)
SLIP_TOL = 1e-6  # plastic slip threshold, relative to the imposed displacement


def parse(argv):
    p = DemoParser(prog="inclined_interface.py", description=__doc__.split("\n\n")[0])
    p.add_out("results/inclined_interface")
    add_discretization(p)
    p.add_argument("--h", type=bounded("--h", 0, 250, lo_open=True), default=25.0,
                   help="mesh size (mm; cut: grid spacing 1000 / round(1000 / h))")
    p.add_argument("--mu", type=bounded("--mu", 0, None), default=0.19,
                   help="Coulomb friction coefficient (tan theta = 0.2)")
    p.add_argument("--E", type=bounded("--E", 0, None, lo_open=True), default=1000.0,
                   help="Young's modulus of both bodies (MPa)")
    p.add_argument("--nu", type=bounded("--nu", -1, 0.5, lo_open=True, hi_open=True), default=0.3)
    p.add_argument("--displacement", type=bounded("--displacement", 0, None, lo_open=True),
                   default=1.0, help="downward displacement of the top (mm)")
    p.add_argument("--eps0", type=bounded("--eps0", 0, None, lo_open=True), default=1.0,
                   help="penalty factor of eq 51: eps = eps0 h / E")
    p.add_argument("--supports", choices=["uniaxial", "held"], default="uniaxial",
                   help="uniaxial: u_x of the uniform uniaxial state on top and bottom; "
                        "held: top u_x = 0, bottom on rollers with its middle point fixed")
    p.add_argument("--steps", type=int, choices=range(1, 101), metavar="[1..100]", default=1,
                   help="load steps")
    p.add_argument("--grid-refine", type=int, choices=range(1, 17), metavar="[1..16]", default=4,
                   help="level-set grid cells per mesh size h")
    p.add_argument("--gauss", type=int, choices=range(1, 6), metavar="[1..5]", default=2,
                   help="Gauss points per contact-surface segment")
    p.add_argument("--degree", type=int, choices=[1, 2], default=1)
    cells = p.add_mutually_exclusive_group()
    cells.add_argument("--quads", dest="quads", action="store_true", default=False,
                       help="quadrilateral cells (the cut grid is always quadrilateral)")
    cells.add_argument("--triangles", dest="quads", action="store_false",
                       help="triangular cells (default; conforming only, ignored with cut)")
    p.add_argument("--petsc", action="append", default=[], metavar="KEY=VALUE",
                   help="PETSc option for the linear solver (prefix ils_), repeatable")
    a = p.parse_args(argv)
    check_discretization(p, a)
    a.petsc = petsc_options(p, a.petsc)
    return a


def interface_frame():
    """Unit normal n (lower -> upper) and tangent t = (-n_y, n_x) of the interface."""
    n = np.array([-SLOPE, 1.0]) / np.hypot(1.0, SLOPE)
    return n, np.array([-n[1], n[0]])


def uniform_state(E, nu, d, eps_n, eps_t):
    """Uniaxial stress s (sigma_yy = -s) of the bonded *penalised* problem and the interface
    tractions. The penalty jump is g = eps_n tau_n n + eps_t tau_t t = s * g1; the top moves
    by -d = -s (1 - nu^2) SIZE / E + s g1_y."""
    n, t = interface_frame()
    tv = np.array([0.0, -1.0]) * n[1]  # (tau_n n + tau_t t) per unit s: (0, -cos theta)
    tau_n, tau_t = tv @ n, tv @ t
    g1 = eps_n * tau_n * n + eps_t * tau_t * t
    s = d / ((1 - nu**2) * SIZE / E - g1[1])
    return dict(s=s, exx=nu * (1 + nu) * s / E, gx=s * g1[0], p_n=-s * tau_n, tau_t=s * tau_t,
                ratio=abs(tau_t / tau_n))


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    comm = MPI.COMM_WORLD
    d = args.displacement
    supports = {"uniaxial": "top: u_y = -d, u_x = e_xx (x - 500); bottom: u_y = 0, "
                            "u_x = e_xx (x - 500); sides free (e_xx: lateral strain of the "
                            "uniform uniaxial state, penalty compliance included)",
                "held": "top: u_y = -d, u_x = 0; bottom: u_y = 0 (rollers), u_x = 0 at the bottom "
                        "vertex nearest to (500, 0); sides free"}[args.supports]
    params = dict(vars(args), quads=args.quads or args.discretization == "cut",
                  size=SIZE, slope=SLOPE, intercept=INTERCEPT,
                  boundary_conditions=supports,
                  slip_threshold=f"max |g_t^p| > {SLIP_TOL:g} d at points farther than h "
                                 "from the sides x = 0, x = size")
    metrics = new_metrics("incline", args.discretization, params)
    timer = PhaseTimer(metrics)

    with timer.phase("mesh"):
        if args.discretization == "cut":  # uniform grid, both bodies cut by the interface
            scene = incline_cut_scene(comm, h=args.h, size=SIZE, slope=SLOPE,
                                      intercept=INTERCEPT)
            metrics["mesh"]["cut_cells"] = cut_counts(scene)
        else:
            scene = incline_scene(comm, h=args.h, quads=args.quads, size=SIZE, slope=SLOPE,
                                  intercept=INTERCEPT)
    top_x, bottom_x = Dirichlet("upper_top", 0, 0.0), Dirichlet("lower_bottom", 0, 0.0)
    dirichlet = [Dirichlet("upper_top", 1, lambda lam: -d * lam),
                 Dirichlet("lower_bottom", 1, 0.0)]
    if args.supports == "uniaxial":
        dirichlet += [top_x, bottom_x]
    else:
        xm = bottom_node_near(scene, X0)
        dirichlet += [top_x, Dirichlet(lambda x: np.isclose(x[0], xm) & np.isclose(x[1], 0.0),
                                       0, 0.0)]
    problem = ContactProblem(
        scene, {b.tag: (args.E, args.nu) for b in scene.bodies}, mu=0.0, eps0=args.eps0,
        band=args.h, degree=args.degree, petsc_options=args.petsc, timer=timer,
        dirichlet=dirichlet, grid_refine=args.grid_refine, num_gauss=args.gauss,
        ghost_penalty=args.ghost_penalty)
    ref = uniform_state(args.E, args.nu, d, problem.eps_n, problem.eps_t)
    if args.supports == "uniaxial":
        set_linear_values(problem, top_x, ref["exx"], ref["gx"])
        set_linear_values(problem, bottom_x, ref["exx"], 0.0)
    # Friction from the start, with zero committed plastic slip (u = 0 here)
    problem.set_friction(args.mu)
    try:
        problem.solve(args.steps, label="incline")
    except ContactSolverError as e:
        sys.stderr.write(f"inclined_interface.py: {e}\n")
        return 1
    g_t = tangential_jump(problem)

    reaction = problem.reaction("upper_top")
    pts = gather_points(problem)
    metrics["mesh"].update(h_contact=scene.h_contact, num_dofs=problem.num_dofs,
                           num_cells=scene.mesh.topology.index_map(2).size_global)
    metrics["solver"] = solver_metrics(problem)
    if comm.rank == 0:
        evaluate(metrics, pts, g_t, reaction, ref, args)
    timer.stop()
    with atomic_output(args.out, comm, force=args.force) as folder:
        finish(folder, metrics, problem, pts,
               plot=(lambda path: plot(Path(path).parent, pts, g_t, metrics, ref, args))
               if comm.rank == 0 else None)
    if comm.rank == 0:
        r = metrics["results"]
        print(f"inclined interface: mu = {args.mu:g} (tan theta = {SLOPE:g}): "
              f"{'SLIPS' if r['slips'] else 'sticks'}; max plastic slip "
              f"{r['max_plastic_slip']:.4g} mm "
              f"({r['max_plastic_slip_interior']:.4g} mm away from the sides), slipping points "
              f"{r['slip_fraction']:.1%}, |tau_t|/p_n in [{r['traction_ratio_min']:.4f}, "
              f"{r['traction_ratio_max']:.4f}] (interior)")
        print(f"results in {Path(args.out).resolve()}")
    return 0


def bottom_node_near(scene, x0):
    """x of the mesh vertex on the bottom y = 0 nearest to x = x0 (same on all ranks)."""
    X = scene.mesh.geometry.x
    xb = X[np.isclose(X[:, 1], 0.0), 0]
    k = np.argmin(np.abs(xb - x0)) if xb.size else None
    mine = (abs(xb[k] - x0), xb[k]) if k is not None else (np.inf, np.nan)
    return min(scene.mesh.comm.allgather(mine))[1]


def set_linear_values(problem, cond, slope, offset):
    """Make a Dirichlet condition on component 0 prescribe u_x = lam (slope (x - X0) + offset).

    The solver stores one value per condition (`x[dofs] = d.at(lam)`); a callable returning an
    array aligned with the condition's dofs gives a value per dof."""
    k = next(i for i, c in enumerate(problem.dirichlet) if c is cond)
    xs = problem.V.tabulate_dof_coordinates()[problem.bc_dofs[k] // problem.bs, 0]
    vals = slope * (xs - X0) + offset
    cond.value = lambda lam: lam * vals


def tangential_jump(problem):
    """(x, g_t): the total tangential jump at this rank's contact points, last accepted step."""
    cat = lambda a: np.concatenate(a) if a else np.zeros(0)  # noqa: E731
    return (cat([g.points[:, 0] for g in problem.pairs]),
            cat([s["g_t"] for s in problem.contact.committed]))


def evaluate(metrics, pts, g_t, reaction, ref, args):
    """Slip verdict, jumps, traction ratio and (sticking, uniaxial supports) errors."""
    x, state, slip, p, q, w = (pts[k] for k in ("x", "state", "slip", "p_n", "p_t", "w"))
    active = state != 0
    interior = active & (x > args.h) & (x < SIZE - args.h)
    ratio = np.abs(q[active]) / p[active]
    ratio_i = np.abs(q[interior]) / p[interior]
    tol = SLIP_TOL * args.displacement
    gi = np.abs(slip[interior])
    slips = bool(gi.size and gi.max() > tol)
    gt_x, gt_all = g_t  # total tangential jump (elastic + plastic) and its points' x
    gt_in = np.abs(gt_all[(gt_x > args.h) & (gt_x < SIZE - args.h)])
    res = metrics["results"]
    res.update(
        reaction=[float(v) for v in reaction],
        contact_half_width=None,  # the whole interface is in contact
        peak_pressure=float(p.max()) if p.size else None,
        slips=slips,
        max_plastic_slip=float(np.abs(slip).max()) if slip.size else None,
        max_plastic_slip_interior=float(gi.max()) if gi.size else None,
        max_tangential_jump=float(np.abs(gt_all).max()) if gt_all.size else None,
        max_tangential_jump_interior=float(gt_in.max()) if gt_in.size else None,
        slip_fraction=float(np.mean(state[active] == 2)) if active.any() else None,
        slip_fraction_interior=float(np.mean(state[interior] == 2)) if interior.any() else None,
        end_slip_points=int(np.sum((state == 2) & ~interior)),
        num_points={"open": int(np.sum(state == 0)), "stick": int(np.sum(state == 1)),
                    "slip": int(np.sum(state == 2))},
        traction_ratio_min=float(ratio_i.min()) if ratio_i.size else None,
        traction_ratio_max=float(ratio_i.max()) if ratio_i.size else None,
        traction_ratio_min_all=float(ratio.min()) if ratio.size else None,
        traction_ratio_max_all=float(ratio.max()) if ratio.size else None,
        slip_threshold_mm=tol,
        max_newton_iterations=max(metrics["solver"]["newton_iterations"], default=None))
    metrics["analytic"].update(traction_ratio=SLOPE, slips=bool(args.mu < SLOPE))
    if args.supports == "uniaxial":
        metrics["analytic"].update(peak_pressure=float(ref["p_n"]), pressure=float(ref["p_n"]),
                                   shear=float(abs(ref["tau_t"])), sigma_yy=float(-ref["s"]))
        if not slips:  # the exact penalised solution is the uniform state
            wi, pi, qi = w[interior], p[interior], np.abs(q[interior])
            res["pressure_rel_l2_error"] = float(np.sqrt(np.sum(wi * (pi - ref["p_n"]) ** 2)
                                                         / np.sum(wi * ref["p_n"] ** 2)))
            res["traction_rel_l2_error"] = float(np.sqrt(np.sum(wi * (qi - abs(ref["tau_t"])) ** 2)
                                                         / np.sum(wi * ref["tau_t"] ** 2)))


def plot(folder, pts, g_t, metrics, ref, args):
    """tractions.png (p_n, p_t against the uniform state and the slip limit) and slip.png
    (plastic slip g_t^p and total tangential jump g_t along the interface)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x = pts["x"]
    mp = args.mu * pts["p_n"]
    curves = {"+- mu p_n (slip limit)": (np.r_[x, np.nan, x], np.r_[mp, np.nan, -mp])}
    if args.supports == "uniaxial":
        xs = np.array([0.0, SIZE])
        curves["uniform state p_n"] = (xs, [ref["p_n"]] * 2)
        curves["uniform state tau_t"] = (xs, [ref["tau_t"]] * 2)
    r = metrics["results"]
    verdict = f"mu = {args.mu:g}, tan theta = {SLOPE:g}: {'slips' if r['slips'] else 'sticks'}"
    plot_tractions(Path(folder) / "tractions.png", pts, curves,
                   title=f"inclined interface, {verdict}")
    fig, ax = plt.subplots(figsize=(7, 4))
    o = np.argsort(g_t[0])
    ax.plot(g_t[0][o], g_t[1][o], "-", lw=1, label="total jump g_t")
    ax.plot(x, pts["slip"], ".", ms=3, label="plastic slip g_t^p")
    for xe in (args.h, SIZE - args.h):
        ax.axvline(xe, color="0.6", lw=0.8, ls=":")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("tangential jump (mm)")
    ax.set_title(f"{verdict}; dotted: end margin h")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(Path(folder) / "slip.png", dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
