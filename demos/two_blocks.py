#!/usr/bin/python3
"""Two blocks with friction (Tur, Fuenmayor & Wriggers 2009): a central stick zone between two
slip zones of opposite slip.

Physics. A short block [10,30]x[10,20] mm rests on a long block [0,40]x[0,10] mm (plane
strain, E = 1e5 MPa, nu = 0.3 for both, Coulomb friction mu = 1.0). The top of the upper
block is moved down by 1.6e-3 mm and held horizontally (u_x = 0 there); the bottom of the
lower block is clamped (our choice, recorded in metrics.json). The sides of the lower block
carry the parabolic tractions of the paper (y from the lower-left corner):
  p_x = 0.4 y (10 - y) MPa pushing inward,  p_y = 1.0 y (10 - y) MPa upward.
The tangential traction is antisymmetric, largest at the ends of the upper block, where the
interface slips first (in opposite directions) when friction is low enough. Displacement and
side loads are ramped together over --steps load steps. cut: both blocks on one uniform grid
whose cells the interface y = 10 cuts.

The check. No closed-form solution exists; the paper shows a central stick zone flanked by two
slip zones of opposite slip, reached in 8 Newton iterations. metrics.json reports the stick
zone, the slip zones on each side and the sign of their plastic slip g_t^p, the Newton
iterations per step, the reaction on the top, the peak pressure, the largest traction ratio
max |p_t|/p_n (the friction coefficient below which slip starts) and sigma_x along y = 5 mm
(sigma_x_line.csv). At mu = 1.0 the interface does not slip; try --mu 0.5.

Run: /usr/bin/python3 demos/two_blocks.py [--mu 0.5] [--discretization cut] [--h 0.2]
Results and discussion: docs/demos/two_blocks.md
"""

import importlib.util
import sys

import numpy as np
import ufl

if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
from dolfinx_forms.analysis import compare, post
from dolfinx_forms.app import cli
from dolfinx_forms.app.demo import Run
from dolfinx_forms.fem.boundary import Dirichlet, Traction
from dolfinx_forms.io.output import write_columns
from dolfinx_forms.solvers.protocol import friction_on, ramp
from meshes.cut import fitted_or_cut, two_blocks_cut_scene
from meshes.two_blocks import two_blocks_scene

SIZES = dict(width_lower=40.0, height=10.0, width_upper=20.0)  # mm (Tur et al. 2009)
PX, PY = 0.4, 1.0  # side tractions p = P y (10 - y) MPa
LINE = np.column_stack([np.linspace(0.0, 40.0, 161), np.full(161, 5.0)])  # sigma_x at y = 5
OPTIONS = [  # option, kind, default[, help]
    ("--h", "(0, 2.5]", 0.2, "mesh size of both blocks (mm; cut: grid spacing)"),
    ("--E", "(0, inf)", 1.0e5, "Young's modulus of both blocks (MPa)"),
    ("--nu", "(-1, 0.5)", 0.3),
    ("--mu", "[0, inf)", 1.0, "Coulomb friction coefficient"),
    ("--displacement", "(0, inf)", 1.6e-3, "downward displacement of the top (mm)"),
    ("--eps0", "(0, inf)", 1.0, "penalty factor of eq 51: eps = eps0 h / E"),
    ("--steps", range(1, 101), 1, "load steps (displacement and side loads together)"),
    ("--degree", [1, 2], 1),
]
CELLS = (True, "quadrilateral cells (default; the cut grid is always quadrilateral)",
         "triangular cells (conforming only; ignored with cut)")  # fmt: skip
SIDE_TRACTION = (
    f"p_x = {PX} y (10 - y) MPa inward, p_y = {PY} y (10 - y) MPa upward on lower_left and "
    "lower_right"
)
SUPPORTS = (
    "lower_bottom clamped (u = 0); upper_top u_x = 0, u_y = -displacement; displacement and "
    "side loads ramped together"
)


def parse(argv):
    p = cli.demo_parser("two_blocks.py", __doc__, "results/two_blocks", OPTIONS, cells=CELLS)
    a = p.parse_args(argv)
    cli.check_scale(p, a, SIZES["width_lower"], "block", displacement=False)
    cli.check_scale(p, a, 2 * SIZES["height"], "stack")
    return a


def evaluate(run):
    """Zones, slip signs, pressures, the traction ratio and the sigma_x line (rank 0)."""
    pts, res, prm = run.pts, run.results, run.params
    active, iters = pts["state"] != 0, run.metrics["solver"]["newton_iterations"]
    res.update(reaction=run.reactions["upper_top"], **post.contact_zones(pts),
               max_newton_iterations=max(iters, default=None))  # fmt: skip
    if active.any():  # the friction coefficient below which slip starts; penalty compliance
        p, w = pts["p_n"], pts["w"]
        res["max_traction_ratio"] = float(np.max(np.abs(pts["p_t"][active]) / p[active]))
        gap = run.problem.eps_n * np.sum(w * p) / np.sum(w[active])  # eps_n at mean pressure
        res["interface_compliance_ratio"] = float(gap / prm["displacement"])
    else:
        res.update(max_traction_ratio=None, interface_compliance_ratio=None)
    sx = run.data["sigma_x"]
    res["sigma_x_line"] = dict(y=5.0, file="sigma_x_line.csv", min=sx.min(), max=sx.max())
    run.curves = compare.slip_limit(pts, prm["mu"])
    if res["stick_zone"] is not None:  # marked on the axis
        run.curves["stick zone"] = (np.array(res["stick_zone"]), np.zeros(2))
    h = run.metrics["mesh"]["h_contact"]
    run.plot_kw = dict(title=f"two blocks (Tur et al. 2009), mu = {prm['mu']}, h = {h:.3g} mm")


def files(run, folder):
    write_columns(folder / "sigma_x_line.csv", x=LINE[:, 0], sigma_x=run.data["sigma_x"])


def summary(run):
    r = run.results
    zone = lambda z: "none" if z is None else f"[{z[0]:.3f}, {z[1]:.3f}]"  # noqa: E731
    return (
        f"two blocks: reaction on the top {r['reaction'][0]:.5g}, {r['reaction'][1]:.5g} "
        f"N/mm; stick zone {zone(r['stick_zone'])}, slip zones {zone(r['slip_zone_left'])} "
        f"(slip sign {r['slip_sign_left']}) and {zone(r['slip_zone_right'])} (slip sign "
        f"{r['slip_sign_right']}); max {r['max_newton_iterations']} Newton iterations per step"
    )


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    params = dict(vars(args), quads=args.quads or args.discretization == "cut", **SIZES)
    params.update(side_traction=SIDE_TRACTION, supports=SUPPORTS)
    with Run("blocks", params) as run:
        # the scene: gmsh blocks, or both blocks on one uniform grid whose cells y = 10 cuts
        scenes = two_blocks_scene, two_blocks_cut_scene
        run.scene = fitted_or_cut(run, *scenes, args.h, args.quads, **SIZES)

        # the problem: lower bottom clamped, upper top held; side tractions p (x, y) (10 - y)
        y = ufl.SpatialCoordinate(run.scene.mesh)[1]
        side = y * (SIZES["height"] - y)
        top_y = Dirichlet("upper_top", 1, 0.0)
        left = Traction("lower_left", ufl.as_vector((PX * side, PY * side)))
        right = Traction("lower_right", ufl.as_vector((-PX * side, PY * side)))
        bcs = [Dirichlet("lower_bottom", None, 0.0), Dirichlet("upper_top", 0, 0.0), top_y]
        run.problem = run.contact_problem(bcs, mu=0.0, band=args.h, tractions=[left, right])

        # the run: friction from the start (zero plastic slip at u = 0), then the displacement
        # and the side loads ramped together
        loads, targets = [top_y, left, right], [-args.displacement, 1.0, 1.0]
        run.records = [friction_on(run.problem, args.mu)]
        run.records.append(ramp(run.problem, loads, targets, args.steps, label="blocks"))
        run.measure(reactions=["upper_top"])
        run.data["sigma_x"] = post.stress_at_points(run.problem, LINE)  # collective

        # the check (rank 0: the contact points live there)
        if run.rank0:
            evaluate(run)
        run.finish(summary, files=files)
    return run.status


if __name__ == "__main__":
    cli.exit_process(main())
