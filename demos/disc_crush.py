#!/usr/bin/python3
"""A disc crushed between rigid platens at finite strain: the MPM against a body-fitted reference.

Physics. A disc of radius R (plane strain, --law neo-hookean or j2) between rigid platens with
Coulomb friction mu, the lower fixed, the upper moved down in --steps equal steps until they
have closed by --compression of the diameter; u_x = 0 on x = 0. The MPM carries F and the
law's history at the material points (mpm/finite_strain.py) on a grid of spacing h.

The check. The same disc, law, friction and penalty on body-fitted quads that follow the
material (fem/updated.py) at 4, 2, 1 x --reference-h: the finest is the reference, its
difference to the next its own error. Force and half-width at every step, plastic zones.
Run: /usr/bin/python3 demos/disc_crush.py [--law j2]  (docs/demos/disc_crush.md)
"""

import importlib.util
import sys
import time
from functools import partial

import numpy as np

HUGE_PAGES = True  # a mesh and factorisation per step: restart with huge pages (app/startup.py)
if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
from dolfinx_forms.app import cli, spec_values
from dolfinx_forms.app.demo import Run
from dolfinx_forms.app.mpm_run import Steps
from dolfinx_forms.fem.boundary import Dirichlet
from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
from meshes.disc import crush_reference, refinement
from meshes.mpm import brazilian_disc, check_brazilian_disc
from meshes.plots import disc_crush_outputs

# fmt: off
OPTIONS = [  # option, kind, default[, help]
    ("--R", "(0, 1e6]", 10.0, "disc radius (mm)"),
    ("--law", ["neo-hookean", "j2"], "neo-hookean", "bulk law (finite strain)"),
    ("--E", "[1e-3, 1e7]", 1000.0, "Young's modulus (N/mm^2)"),
    ("--nu", "(-1, 0.5)", 0.3),
    ("--yield-stress", "(0, inf)", 20.0, "j2: initial yield stress (N/mm^2)"),
    ("--hardening", "[0, inf)", 100.0, "j2: linear isotropic hardening (N/mm^2)"),
    ("--mu", "[0, inf)", 0.3, "Coulomb friction at both platens"),
    ("--compression", "(0, 0.5]", 0.4, "platen closure as a fraction of the diameter"),
    ("--steps", range(1, 10001), 40),
    ("--h", "(0, inf)", 0.4, "MPM grid spacing (mm)"),
    ("--reference-h", "(0, inf)", 0.25, "finest body-fitted cell size (mm): runs at 4, 2, 1 x"),
    ("--eps0", cli.MPM_EPS0_INTERVAL, 0.2, "penalty factor (eq 51), both paths (docs/demos)"),
    ("--series-every", range(1, 10001), 10, "steps between frames of the time series"),
]
COLUMNS = ["step", "compression", "force", "force_reference", "half_width",
           "half_width_reference", "plastic_fraction", "plastic_fraction_reference",
           "area_levelset", "volume_points", "newton_iterations", "wall_s"]
TOLERANCE = 0.02  # force against the reference at every step (docs/demos/disc_crush.md)
# fmt: on


def parse(argv):
    p = cli.demo_parser("disc_crush.py", __doc__, "results/disc_crush", OPTIONS,
                        discretization=False, multi_step=True)  # fmt: skip
    a = p.parse_args(argv)
    a.step_displacement, need = 2 * a.R * a.compression / a.steps, 4 * a.R * a.compression / a.h
    try:  # 10 to 4000 cells across
        check_brazilian_disc(a.R, a.h, 1, 0.0)
    except ValueError as e:
        p.error(str(e))
    lo, hi, n = a.R / 80, a.R / 20, int(np.ceil(need - 1e-9))
    if a.steps < n:  # the platen moves at most h/2 per step (contact band, advection)
        p.error(f"--steps: must be >= 4 R compression / h = {n}, got {a.steps}")
    if not lo <= a.reference_h <= hi:  # the coarsest level: 5 cells per radius
        p.error(f"--reference-h: must be in [R/80, R/20] = [{lo:g}, {hi:g}], got {a.reference_h}")
    return a


def evaluate(run, reference):
    """Force and half-width against the finest reference, its own error, plastic zones."""
    F, Fr, a, ar, pf, pfr, area, vol = (np.array([r[k] for r in run.rows]) for k in COLUMNS[2:10])
    err, judged = np.abs(F / Fr - 1), ar > 5 * run.params["h"]  # zones of 10 grid cells
    levels, Fh, own, extrapolated = refinement(reference)  # finest against the next coarser
    run.results.update(  # resolved: where the contact zone spans at least 4 grid cells
        force=F.tolist(), force_rel_error_max=float(err.max()),
        force_rel_error_last=float(err[-1]), reference_own_error_max=float(own.max()),
        force_rel_error_max_resolved=float(np.max(err[ar > 2 * run.params["h"]], initial=0)),
        force_rel_error_vs_extrapolated_max=float(np.max(np.abs(F / extrapolated - 1))),
        reference_force_by_h={f"{h:g}": Fh[h].tolist() for h in levels},
        half_width_rel_error_max=float(np.abs(a / ar - 1)[judged].max()) if judged.any() else None,
        plastic_fraction_last=[pf[-1], pfr[-1]],
        area_vs_points_rel_max=float(np.max(np.abs(area / vol - 1))),
        newton_iterations_mean=float(np.mean([r["newton_iterations"] for r in run.rows])),
    )  # fmt: skip
    run.analytic.update(force=Fr.tolist(), half_width=ar.tolist())
    warn = run.metrics["solver"]["warnings"]
    if err.max() > TOLERANCE:
        warn.append(f"force differs from the body-fitted reference by {err.max():.2%} "
                    f"(> {TOLERANCE:.0%}) at step {int(np.argmax(err)) + 1}")  # fmt: skip
    if own.max() > TOLERANCE:
        warn.append(f"the reference's own error estimate reaches {own.max():.2%} (> "
                    f"{TOLERANCE:.0%}): a smaller --reference-h")  # fmt: skip
    if (av := run.results["area_vs_points_rel_max"]) > 0.01:
        warn.append(f"level-set area and point volume differ by {av:.1%} (> 1 %)")


def summary(run):
    r, own = run.results, run.results["reference_own_error_max"]
    return (f"Disc crush ({run.params['law']}): F = {r['force'][-1]:.6g} N/mm at the end (body-"
            f"fitted {run.analytic['force'][-1]:.6g}); max error {r['force_rel_error_max']:.2%} "
            f"(the reference's own {own:.2%})")  # fmt: skip


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    with Run("disc_crush", vars(args), discretization="cut", plot=False) as run:
        p, kw, t0 = vars(args), run.problem_options, time.perf_counter()
        j2 = {k: p[k] for k in ("yield_stress", "hardening")} if args.law == "j2" else {}
        law = spec_values.make_law(dict(type=args.law, E=args.E, nu=args.nu, **j2))
        # the reference: body-fitted, updated Lagrangian, at three cell sizes, finest first
        reference = crush_reference(run.comm, args.R, [k * args.reference_h for k in (1, 2, 4)],
                                    law, args.steps, args.step_displacement, **kw)  # fmt: skip
        run.results["reference_wall_s"], ref = time.perf_counter() - t0, reference[: args.steps]
        # the MPM: the disc's level set and material points between the two platens
        grid, (name, tag, shape), platens, scene = brazilian_disc(
            run.comm, args.R, args.h, args.step_displacement, args.steps)  # fmt: skip
        axis = Dirichlet(lambda x: np.isclose(x[0], 0.0, atol=1e-9 * args.R), 0, 0.0)
        sim = ImplicitMPM(run.comm, grid, [MPMBody(name, tag, law, shape)], scene,
                          obstacles=platens, dirichlet=[axis], timer=run.timer, **kw)  # fmt: skip
        # the run: the upper platen closes by step_displacement per step
        steps = Steps(run, sim, COLUMNS, args.steps, args.series_every)
        for k in range(args.steps):
            rec, pts = steps.step(), sim.points[tag]
            alpha = pts.history[:, -1] if law.history_size else np.zeros(len(pts.vol))
            steps.rows.append(dict(
                step=k + 1, compression=(k + 1) * args.step_displacement / (2 * args.R),
                force=rec["obstacles"]["platen_top"]["fy"],
                half_width={q["body_j"]: q["half_width"] for q in rec["pairs"]}["platen_top"],
                plastic_fraction=float(pts.vol[alpha > 0].sum() / pts.vol.sum()),
                **{f"{c}_reference": ref[k][c] for c in COLUMNS[2:8:2]},
                area_levelset=rec["area_levelset"][name], volume_points=rec["volume_points"][name],
                newton_iterations=rec["newton_iterations"], wall_s=rec["wall_s"],
            ))  # fmt: skip
        steps.measure()
        if run.rank0:  # the check: force and half-width against the body-fitted reference
            evaluate(run, reference)
        run.finish(summary, **steps.outputs(partial(disc_crush_outputs, reference=reference)))
    return run.status


if __name__ == "__main__":
    cli.exit_process(main())
