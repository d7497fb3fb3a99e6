#!/usr/bin/python3
"""Frictional sliding on an inclined interface (Annavarapu et al. 2014): slips iff mu < tan theta.

Physics. The square [0,1000]^2 mm is cut by the line y = 0.2 x + 458.6 (tan theta = 0.2) into
a lower and an upper body (plane strain, E = 1000 MPa, nu = 0.3), compressed from the top by
u_y = -1 mm. Under a uniform uniaxial vertical stress sigma_yy = -s the traction on the
interface is vertical, so everywhere on it
  p_n = s cos^2 theta,  |tau_t| = s sin theta cos theta,  |tau_t| / p_n = tan theta = 0.2,
and Coulomb friction holds the interface iff mu >= tan theta. The supports keep this state
(--supports uniaxial, default): top u_y = -d, bottom u_y = 0, both u_x = e_xx (x - 500) with
e_xx the lateral strain of the state, s including the penalty compliance of the interface
(analytic.inclined_uniaxial_state); sides free. --supports held: top u_x = 0, bottom on rollers
with its vertex nearest to x = 500 fixed. cut: both bodies on one uniform grid that the
interface cuts.

The check. The verdict `slips`: the committed plastic slip g_t^p exceeds 1e-6 d at a contact
point farther than h from the free sides (near them the contact normals are off). metrics.json
also reports g_t^p and the total tangential jump g_t (slip.png plots both), the fraction of
slipping points and |tau_t|/p_n; sticking under the uniaxial supports, the relative L2 errors
of p_n and tau_t against the uniform state. Default mu = 0.19: the slipping case.

Run: /usr/bin/python3 demos/inclined_interface.py [--mu 0.21] [--discretization cut]
Results and discussion: docs/demos/inclined_interface.md
"""

import importlib.util
import sys

import numpy as np

if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
from dolfinx_forms.analysis import analytic, compare, post
from dolfinx_forms.app import cli
from dolfinx_forms.app.demo import Run
from dolfinx_forms.fem.boundary import Dirichlet
from dolfinx_forms.solvers.protocol import friction_on, ramp
from meshes.cut import fitted_or_cut, incline_cut_scene
from meshes.incline import SUPPORTS, SUPPORTS_HELP, bottom_vertex, incline_scene
from meshes.plots import slip_plot

SIZE, SLOPE, INTERCEPT = 1000.0, 0.2, 458.6  # mm; interface y = SLOPE x + INTERCEPT
X0 = SIZE / 2  # u_x = 0 at x = X0 on top and bottom (uniaxial supports)
LINE = dict(size=SIZE, slope=SLOPE, intercept=INTERCEPT)
SLIP_TOL = 1e-6  # plastic slip threshold, relative to the imposed displacement
THRESHOLD = f"max |g_t^p| > {SLIP_TOL:g} d at points farther than h from the sides x = 0, x = size"
OPTIONS = [  # option, kind, default[, help]
    ("--h", "(0, 250]", 25.0, "mesh size (mm; cut: grid spacing 1000 / round(1000 / h))"),
    ("--mu", "[0, inf)", 0.19, "Coulomb friction coefficient (tan theta = 0.2)"),
    ("--E", "(0, inf)", 1000.0, "Young's modulus of both bodies (MPa)"),
    ("--nu", "(-1, 0.5)", 0.3),
    ("--displacement", "(0, inf)", 1.0, "downward displacement of the top (mm)"),
    ("--eps0", "(0, inf)", 1.0, "penalty factor of eq 51: eps = eps0 h / E"),
    ("--supports", ["uniaxial", "held"], "uniaxial", SUPPORTS_HELP),
    ("--steps", range(1, 101), 1, "load steps"),
    ("--grid-refine", range(1, 17), 4, "level-set grid cells per mesh size h"),
    ("--gauss", range(1, 6), 2, "Gauss points per contact-surface segment"),
    ("--degree", [1, 2], 1),
]
CELLS = (False, "quadrilateral cells (the cut grid is always quadrilateral)",
         "triangular cells (default; conforming only, ignored with cut)")  # fmt: skip


def parse(argv):
    p = cli.demo_parser("inclined_interface.py", __doc__, "results/inclined_interface",
                        OPTIONS, cells=CELLS)  # fmt: skip
    a = p.parse_args(argv)
    cli.check_scale(p, a, SIZE, "square")
    return a


def evaluate(run):
    """Slip verdict, jumps, traction ratio and (sticking, uniaxial supports) errors."""
    pts, p, ref, res = run.pts, run.params, run.data["ref"], run.results
    x, pn, h, (gt_x, gt) = pts["x"], pts["p_n"], p["h"], run.data["g_t"]
    interior = (pts["state"] != 0) & (x > h) & (x < SIZE - h)
    res.update(reaction=run.reactions["upper_top"], contact_half_width=None)  # all in contact
    res.update(peak_pressure=compare.extreme(pn), max_tangential_jump=compare.extreme(np.abs(gt)))
    away = (gt_x > h) & (gt_x < SIZE - h)  # from the sides
    res["max_tangential_jump_interior"] = compare.extreme(np.abs(gt[away]))
    res.update(compare.slip_results(pts, interior, SLIP_TOL * p["displacement"]))
    res["max_newton_iterations"] = max(run.metrics["solver"]["newton_iterations"], default=None)
    run.analytic.update(traction_ratio=SLOPE, slips=bool(p["mu"] < SLOPE))
    run.curves = compare.slip_limit(pts, p["mu"])
    if p["supports"] == "uniaxial":
        an = dict(pressure=ref["p_n"], shear=abs(ref["tau_t"]), sigma_yy=-ref["s"])
        run.analytic.update(peak_pressure=float(ref["p_n"]), **{k: float(v) for k, v in an.items()})
        if not res["slips"]:  # the exact penalised solution is the uniform state
            wi, pi, qi = pts["w"][interior], pn[interior], np.abs(pts["p_t"][interior])
            res["pressure_rel_l2_error"] = compare.rel_l2(wi, pi, np.full_like(pi, an["pressure"]))
            res["traction_rel_l2_error"] = compare.rel_l2(wi, qi, np.full_like(qi, an["shear"]))
        ends = np.array([0.0, SIZE])
        run.curves.update({f"uniform state {k}": (ends, [ref[k]] * 2) for k in ("p_n", "tau_t")})
    verdict = "slips" if res["slips"] else "sticks"
    run.data["verdict"] = f"mu = {p['mu']:g}, tan theta = {SLOPE:g}: {verdict}"
    run.plot_kw = dict(title=f"inclined interface, {run.data['verdict']}")


def summary(run):
    r, p = run.results, run.params
    return (
        f"inclined interface: mu = {p['mu']:g} (tan theta = {SLOPE:g}): "
        f"{'SLIPS' if r['slips'] else 'sticks'}; max plastic slip {r['max_plastic_slip']:.4g} mm "
        f"({r['max_plastic_slip_interior']:.4g} mm away from the sides), slipping points "
        f"{r['slip_fraction']:.1%}, |tau_t|/p_n in [{r['traction_ratio_min']:.4f}, "
        f"{r['traction_ratio_max']:.4f}] (interior)"
    )


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    params = dict(vars(args), quads=args.quads or args.discretization == "cut", **LINE)
    params.update(boundary_conditions=SUPPORTS[args.supports], slip_threshold=THRESHOLD)
    with Run("incline", params) as run:
        # the scene: gmsh bodies below and above the interface, or one uniform grid it cuts
        run.scene = fitted_or_cut(run, incline_scene, incline_cut_scene, args.h, args.quads, **LINE)

        # the problem: top and bottom held (SUPPORTS); the uniform state of the penalised one
        top_y, top_x = Dirichlet("upper_top", 1, 0.0), Dirichlet("upper_top", 0)
        bottom_x = Dirichlet("lower_bottom", 0, 0.0)
        if args.supports == "held":  # rollers, with the bottom vertex nearest to x = X0 held
            bottom_x = Dirichlet(bottom_vertex(run.scene.mesh, X0), 0)
        bcs = [top_y, Dirichlet("lower_bottom", 1, 0.0), top_x, bottom_x]
        pb = run.problem = run.contact_problem(bcs, mu=0.0, band=args.h)
        state = (args.E, args.nu, args.displacement, SIZE, SLOPE, pb.eps_n, pb.eps_t)
        ref = run.data["ref"] = analytic.inclined_uniaxial_state(*state)

        # the run: friction from the start (zero plastic slip at u = 0); the top moved down,
        # and with the uniaxial supports top and bottom moved horizontally as the uniform state
        def u_x(offset):  # of the uniform state, at the coordinates x of a condition's dofs
            return lambda x: ref["exx"] * (x[0] - X0) + offset

        loads, targets = [top_y], [-args.displacement]
        if args.supports == "uniaxial":
            loads, targets = loads + [top_x, bottom_x], targets + [u_x(ref["gx"]), u_x(0.0)]
        run.records = [friction_on(pb, args.mu)]
        run.records.append(ramp(pb, loads, targets, args.steps, label="incline"))
        run.measure(reactions=["upper_top"])
        run.data["g_t"] = post.tangential_jumps(pb)  # g_t (elastic + plastic), on rank 0

        # the check (rank 0)
        if run.rank0:
            evaluate(run)
        run.finish(summary, files=slip_plot)  # slip.png
    return run.status


if __name__ == "__main__":
    cli.exit_process(main())
