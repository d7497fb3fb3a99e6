#!/usr/bin/python3
"""Brazilian disc over many load steps: the implicit level-set MPM (paper 5.3.1).

Physics. A disc of radius R (E, nu, plane strain) between two rigid platens, the lower fixed,
the upper moved down by --step-displacement per step; Coulomb friction mu on both contacts. The
disc is a level set on a uniform grid of spacing h carrying material points; every step rebuilds
the cut cells from the evolved level set, projects the points' stress to the new integration
points (MLS) and solves for the displacement increment (ImplicitMPM). By symmetry u_x = 0 on
x = 0, which also removes the rigid modes of the free disc.

The check. The contact half-width against Hertz for a cylinder on a rigid flat,
a = 2 sqrt(F R (1 - nu^2) / (pi E)) (the paper's eq 52 is 4x too small), at every step with
a > 5 h; the forces on the two platens equal (the disc is free: equilibrium); the level-set
area against the material points' volume; the mass of the points constant.

Run: /usr/bin/python3 demos/brazilian_disc.py [--steps 50] [--h 0.2]
Results and discussion: docs/demos/brazilian_disc.md
"""

import importlib.util
import sys
from functools import partial

import numpy as np

HUGE_PAGES = True  # a mesh and factorisation per step: restart with huge pages (app/startup.py)
if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
from dolfinx_forms.app import cli
from dolfinx_forms.app.demo import Run
from dolfinx_forms.app.mpm_run import Steps
from dolfinx_forms.fem.boundary import Dirichlet
from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
from meshes.mpm import brazilian_disc, check_brazilian_disc
from meshes.plots import brazilian_disc_plots as disc_plots

# fmt: off
OPTIONS = [  # option, kind, default[, help]
    ("--R", "(0, 1e6]", 10.0, "disc radius (mm)"),
    ("--E", "[1e-3, 1e7]", 100e3, "Young's modulus (N/mm^2; verified 1e-3 to 1e7)"),
    ("--nu", "(-1, 0.5)", 0.3),
    ("--mu", "[0, inf)", 0.5),
    ("--step-displacement", "(0, inf)", 0.02, "platen travel per step (mm)"),
    ("--steps", range(1, 10001), 50),
    ("--h", "(0, inf)", 0.2, "grid spacing (mm)"),
    ("--eps0", cli.MPM_EPS0_INTERVAL, 0.6, "penalty factor (eq 51: eps = eps0 h / (2 E) at the "
     "platens; cli.MPM_EPS0); 0.6: its compliance well below the disc's at a = 5 h"),
    ("--series-every", range(1, 10001), 10, "steps between frames of the time series"),
]
COLUMNS = ["step", "displacement", "force_top", "force_bottom", "half_width_top",
           "half_width_bottom", "area_levelset", "volume_points", "newton_iterations", "wall_s"]
# fmt: on


def parse(argv):
    p = cli.demo_parser("brazilian_disc.py", __doc__, "results/brazilian_disc", OPTIONS,
                        discretization=False, multi_step=True)  # fmt: skip
    a = p.parse_args(argv)
    try:  # 10 to 4000 cells across, small strain, at most h/2 per step
        check_brazilian_disc(a.R, a.h, a.steps, a.step_displacement)
    except ValueError as e:
        p.error(str(e))
    return a


def hertz_half_width(F, R, E, nu):
    """Cylinder on a rigid flat (plane strain): a = 2 sqrt(F R (1 - nu^2) / (pi E))."""
    return 2 * np.sqrt(np.maximum(F, 0) * R * (1 - nu**2) / (np.pi * E))


def evaluate(run):
    """Hertz half-width where a > 5 h, force balance, area vs point volume, mass."""
    p, rows, recs = run.params, run.rows, run.records
    F, Fb = (np.array([r[k] for r in rows]) for k in ("force_top", "force_bottom"))
    a = np.array([[r["half_width_top"], r["half_width_bottom"]] for r in rows])
    a_h = hertz_half_width(F, p["R"], p["E"], p["nu"])
    judged, err = a.min(axis=1) > 5 * p["h"], np.abs(a / a_h[:, None] - 1)
    balance = np.abs(F - Fb) / np.maximum(np.abs(F), 1e-300)
    area, vol = (np.array([r[k] for r in rows]) for k in ("area_levelset", "volume_points"))
    run.results.update(
        force_top=F.tolist(), force_bottom=Fb.tolist(), half_width=a.tolist(),
        half_width_rel_error_max=float(err[judged].max()) if judged.any() else None,
        steps_judged=int(judged.sum()), force_balance_rel_max=float(balance.max()),
        area_vs_points_rel_max=float(np.max(np.abs(area / vol - 1))),
        mass_rel_change=float(abs(recs[-1]["mass"]["disc"] / recs[0]["mass"]["disc"] - 1)),
        newton_iterations_mean=float(np.mean([r["newton_iterations"] for r in rows])),
        reinitializations=int(sum(r["reinitialized"]["disc"] for r in recs)),
        gradient_drift_max=float(max(r["gradient_drift"]["disc"] for r in recs)),
        points_outside_cells_max=int(max(r["points_outside_cells"] for r in recs)),
    )  # fmt: skip
    run.analytic.update(half_width=a_h.tolist())
    warn, av = run.metrics["solver"]["warnings"], run.results["area_vs_points_rel_max"]
    if judged.any() and err[judged].max() > 0.05:
        warn.append(f"half-width differs from Hertz by {err[judged].max():.1%} (> 5 %) at a > 5 h")
    if balance.max() > 1e-6:
        warn.append(f"platen forces differ by {balance.max():.1e} relative (> 1e-6)")
    if av > 0.01:
        warn.append(f"level-set area and point volume differ by {av:.1%}")
    run.results["mls_widened_points"] = int(sum(r["mls_widened"] for r in recs))


def summary(run):
    r, err = run.results, run.results["half_width_rel_error_max"]
    err = "n/a" if err is None else f"{err:.2%}"
    return (
        f"Brazilian disc: {len(run.rows)} steps, F = {r['force_top'][-1]:.6g} N/mm, "
        f"a = {r['half_width'][-1][0]:.4g} mm (Hertz {run.analytic['half_width'][-1]:.4g}), "
        f"max |a/a_Hertz - 1| over {r['steps_judged']} steps with a > 5 h: {err}, force balance "
        f"{r['force_balance_rel_max']:.1e}, Newton {r['newton_iterations_mean']:.1f} per step"
    )


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    with Run("brazilian", vars(args), discretization="cut", plot=False) as run:
        # the scene: the disc's level set and material points, the two rigid platens, moving
        scene_args = (args.R, args.h, args.step_displacement, args.steps)
        grid, (name, tag, shape), platens, scene = brazilian_disc(run.comm, *scene_args)
        # the problem: the disc (plane strain, linear elastic) between the platens, u_x = 0 on x = 0
        symmetry = Dirichlet(lambda x: np.isclose(x[0], 0.0, atol=1e-9 * args.R), 0, 0.0)
        body = MPMBody(name, tag, (args.E, args.nu), shape)
        kw = dict(obstacles=platens, dirichlet=[symmetry], timer=run.timer)
        sim = ImplicitMPM(run.comm, grid, [body], scene, **kw, **run.problem_options)

        # the run: the platens close by step_displacement per step
        steps = Steps(run, sim, COLUMNS, args.steps, args.series_every)
        for _ in range(args.steps):
            rec = steps.step()
            widths = {q["body_j"]: q["half_width"] for q in rec["pairs"]}
            obst, k = rec["obstacles"], rec["step"]
            steps.rows.append(dict(
                step=k, displacement=k * args.step_displacement,
                force_top=obst["platen_top"]["fy"], force_bottom=-obst["platen_bottom"]["fy"],
                **{f"half_width_{s}": widths.get(f"platen_{s}", 0.0) for s in ("top", "bottom")},
                area_levelset=rec["area_levelset"]["disc"],
                volume_points=rec["volume_points"]["disc"],
                newton_iterations=rec["newton_iterations"], wall_s=rec["wall_s"],
            ))  # fmt: skip
        steps.measure()

        # the check (rank 0): Hertz's half-width where a > 5 h, force balance, area, mass
        if run.rank0:
            evaluate(run)
        run.finish(summary, **steps.outputs(partial(disc_plots, half_width=hertz_half_width)))
    return run.status


if __name__ == "__main__":
    cli.exit_process(main())
