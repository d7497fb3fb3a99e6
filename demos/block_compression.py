#!/usr/bin/python3
"""A block compressed between frictionless rigid platens at finite strain: the implicit MPM.

Physics. A width x height block (plane strain) between frictionless rigid platens wider than
it; the upper moves down in --steps equal steps to --compression of the height. --law linear
(small strain), neo-hookean, j2 or drucker-prager (finite strain: F and the law's history at
the points, mpm/finite_strain.py; fem/plasticity.py). u_x = 0 on x = 0 holds the free motion.

The check. F = diag(l_x, l_y), l_y = 1 - compression, l_x from sigma_xx = 0: the force per unit
thickness against |P_yy| times the initial width (neo-Hookean closed form; plastic and linear
integrated along the steps, analytic.block_*), the width at mid-height against l_x W, the
level-set area against the points' volume, the mass.
Run: /usr/bin/python3 demos/block_compression.py [--law j2]  (docs/demos/block_compression.md)
"""

import importlib.util
import sys
from functools import partial

import numpy as np

if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
from dolfinx_forms.analysis import analytic
from dolfinx_forms.app import cli, spec_values
from dolfinx_forms.app.demo import Run
from dolfinx_forms.app.mpm_run import Steps
from dolfinx_forms.fem.boundary import Dirichlet
from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
from meshes.mpm import block_between_platens, check_block, width_at
from meshes.plots import block_plots

# fmt: off
OPTIONS = [  # option, kind, default[, help]
    ("--width", "(0, 1e6]", 2.0, "block width (mm)"),
    ("--height", "(0, 1e6]", 2.0, "block height (mm)"),
    ("--compression", "(0, 0.5]", 0.3, "platen travel as a fraction of the height"),
    ("--law", ["neo-hookean", "linear", "j2", "drucker-prager"], "neo-hookean", "bulk law"),
    ("--E", "[1e-3, 1e7]", 1000.0, "Young's modulus (N/mm^2)"),
    ("--nu", "(-1, 0.5)", 0.3),
    ("--yield-stress", "(0, inf)", 50.0, "j2: initial yield stress (N/mm^2)"),
    ("--hardening", "[0, inf)", 100.0, "j2, drucker-prager: linear hardening (N/mm^2)"),
    ("--cohesion", "(0, inf)", 5.0, "drucker-prager: cohesion (N/mm^2)"),
    ("--friction-angle", "(0, 90)", 30.0, "drucker-prager: friction angle (degrees)"),
    ("--dilatancy-angle", "(0, 90)", 10.0, "drucker-prager: dilatancy angle (degrees)"),
    ("--steps", range(1, 10001), 20),
    ("--h", "(0, inf)", 0.05, "grid spacing (mm)"),
    ("--eps0", cli.MPM_EPS0_INTERVAL, 0.1, "penalty factor (eq 51; 0.1: no checkerboard)"),
    ("--series-every", range(1, 10001), 5, "steps between frames of the time series"),
]
COLUMNS = ["step", "compression", "force", "width", "area_levelset", "volume_points"]
TOLERANCE = 0.02  # force and width against the homogeneous solution (docs/demos)
PLASTIC = {"linear": (), "neo-hookean": (), "j2": ("yield_stress", "hardening"),
           "drucker-prager": ("cohesion", "friction_angle", "dilatancy_angle", "hardening")}
# fmt: on


def parse(argv):
    p = cli.demo_parser("block_compression.py", __doc__, "results/block_compression", OPTIONS,
                        discretization=False, multi_step=True)  # fmt: skip
    a = p.parse_args(argv)
    try:
        check_block(a.width, a.height, a.h, a.compression, a.steps)
    except ValueError as e:
        p.error(str(e))
    if a.law == "drucker-prager" and a.dilatancy_angle > a.friction_angle:
        p.error(f"--dilatancy-angle: must be <= --friction-angle, got {a.dilatancy_angle}")
    return a


def make_law(p):  # the one place a law's parameters become a Law: spec_values.make_law
    return spec_values.make_law(dict(type=p["law"], E=p["E"], nu=p["nu"],
                                     **{k: p[k] for k in PLASTIC[p["law"]]}))  # fmt: skip


def reference(p, ly):
    """(force, l_x) of the homogeneous block at the stretches ly (module docstring)."""
    W, law, E, nu, extra = p["width"], make_law(p), p["E"], p["nu"], PLASTIC[p["law"]]
    plastic = {"j2": analytic.block_j2, "drucker-prager": analytic.block_drucker_prager}
    return {"neo-hookean": lambda: analytic.block_neo_hookean(ly, W, law.mu, law.lmbda),
            "linear": lambda: analytic.block_hypoelastic(ly, W, E, nu)}.get(
        p["law"], lambda: plastic[p["law"]](ly, W, E, nu, *map(p.get, extra))[:2])()  # fmt: skip


def evaluate(run):
    """Force and width against the homogeneous solution; area, volume, mass."""
    p, rows, recs = run.params, run.rows, run.records
    c, F, w = (np.array([r[k] for r in rows]) for k in ("compression", "force", "width"))
    F_ref, lx = reference(p, 1 - c)
    err_F, err_w = np.abs(F / F_ref - 1), np.abs(w / (lx * p["width"]) - 1)
    area, vol = (np.array([r[k] for r in rows]) for k in ("area_levelset", "volume_points"))
    pts = run.sim.points[1]
    run.results.update(
        force=F.tolist(), width=w.tolist(), force_rel_error_max=float(err_F.max()),
        width_rel_error_max=float(err_w.max()),
        area_vs_points_rel_max=float(np.max(np.abs(area / vol - 1))),
        mass_rel_change=float(abs(recs[-1]["mass"]["block"] / recs[0]["mass"]["block"] - 1)),
        F_yy_points=[float(pts.F[:, 1, 1].min()), float(pts.F[:, 1, 1].max())],
        newton_iterations_mean=float(np.mean([r["newton_iterations"] for r in recs])),
        points_outside_cells_max=int(max(r["points_outside_cells"] for r in recs)),
    )  # fmt: skip
    run.analytic.update(force=F_ref.tolist(), width=(lx * p["width"]).tolist())
    warn = run.metrics["solver"]["warnings"]
    for name, e in (("force", err_F), ("width", err_w)):
        if e.max() > TOLERANCE:
            warn.append(f"{name} differs from the homogeneous solution by {e.max():.2%} "
                        f"(> {TOLERANCE:.0%}) at step {int(np.argmax(e)) + 1}")  # fmt: skip
    if (av := run.results["area_vs_points_rel_max"]) > 0.01:
        warn.append(f"level-set area and point volume differ by {av:.1%} (> 1 %)")


def summary(run):
    r, p = run.results, run.params
    return (f"Block ({p['law']}): {len(run.rows)} steps to {run.rows[-1]['compression']:.3g}, "
            f"F = {r['force'][-1]:.6g} N/mm (homogeneous {run.analytic['force'][-1]:.6g}), max "
            f"errors: force {r['force_rel_error_max']:.2e}, width {r['width_rel_error_max']:.2e}"
            f", area vs points {r['area_vs_points_rel_max']:.1e}; Newton "
            f"{r['newton_iterations_mean']:.1f} per step")  # fmt: skip


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    with Run("block_compression", vars(args), discretization="cut", plot=False) as run:
        # the scene: the block's level set and points between the two platens
        grid, (name, tag, shape), platens, scene = block_between_platens(
            run.comm, args.width, args.height, args.h, args.compression, args.steps)  # fmt: skip
        # the problem: frictionless platens, u_x = 0 on x = 0
        symmetry = Dirichlet(lambda x: np.isclose(x[0], 0.0, atol=1e-9 * args.width), 0, 0.0)
        body = MPMBody(name, tag, make_law(vars(args)), shape)
        kw = dict(obstacles=platens, dirichlet=[symmetry], timer=run.timer, mu=0.0)
        sim = ImplicitMPM(run.comm, grid, [body], scene, **kw, **run.problem_options)

        # the run: the upper platen moves down by compression x height / steps per step
        steps = Steps(run, sim, COLUMNS, args.steps, args.series_every)
        for _ in range(args.steps):
            rec, k = steps.step(), len(steps.rows) + 1
            steps.rows.append(dict(step=k, compression=k * args.compression / args.steps,
                force=rec["obstacles"]["platen_top"]["fy"], width=width_at(sim.levelsets[tag], 0),
                area_levelset=rec["area_levelset"]["block"],
                volume_points=rec["volume_points"]["block"]))  # fmt: skip
        steps.measure()
        if run.rank0:  # the check: force and width against the homogeneous solution
            evaluate(run)
        run.finish(summary, **steps.outputs(partial(block_plots, reference=reference)))
    return run.status


if __name__ == "__main__":
    cli.exit_process(main())
