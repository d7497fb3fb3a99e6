#!/usr/bin/python3
"""A grain assembly in four rigid plates: isotropic compression, then simple shear (paper 5.3.2).

Physics. --grains elliptic grains (aspect 1.1, mean radius 5 mm, E = 100 GPa, nu = 0.2, plane
strain) on a hexagonal lattice, each overlapping its neighbours and the outermost ones the
plates by 0.02 h (a grain whose contacts are all open would make the step singular; the paper
enlarges its grains by 0.5 h for the same reason), friction angle --friction-angle. Phase 1:
the four rigid plates move toward the centre by --compression per step for --steps steps.
Phase 2 (simple shear): top and bottom plates fixed, the lateral plates turn about their bottom
ends by --shear-rotation per step for --shear-steps steps. Grains, pairs (broad phase), contact
surfaces and level sets are rebuilt every step (ImplicitMPM).

The check. Every grain in equilibrium at every step (its contact resultant below 1e-8 of the
largest contact force), the plates' forces in balance; the normal and tangential forces on the
plates per step (steps.csv), the force chains at the end of each phase.

Run: /usr/bin/python3 demos/grain_assembly.py [--grains 15] [--friction-angle 30]
Results and discussion: docs/demos/grain_assembly.md
"""

import importlib.util
import sys

import numpy as np

HUGE_PAGES = True  # a mesh and factorisation per step: restart with huge pages (app/startup.py)
if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
from dolfinx_forms.app import cli
from dolfinx_forms.app.demo import Run
from dolfinx_forms.app.mpm_run import Steps
from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody, equilibrium_error
from meshes.assembly import grain_assembly, plate_frame_forces
from meshes.plots import grain_assembly_plots

# fmt: off
OPTIONS = [  # option, kind, default[, help]
    ("--grains", range(2, 1001), 15),
    ("--radius", "(0, inf)", 5.0, "mean grain radius (mm)"),
    ("--E", "[1e-3, 1e7]", 100e3, "Young's modulus (N/mm^2; verified 1e-3 to 1e7)"),
    ("--nu", "(-1, 0.5)", 0.2),
    ("--friction-angle", "(0, 60]", 15.0, "degrees (mu = tan of it)"),
    ("--compression", "(0, inf)", 0.01, "inward motion of each plate per step (mm)"),
    ("--steps", range(0, 1001), 30, "compression steps"),
    ("--shear-rotation", "(0, 0.5]", np.degrees(0.3 / 180), "lateral plates' turn per step (deg)"),
    ("--shear-steps", range(0, 1001), 30),
    ("--h", "(0, inf)", 0.5, "grid spacing (mm)"),
    ("--eps0", cli.MPM_EPS0_INTERVAL, 1.0, cli.MPM_EPS0_HELP),
]
PLATES = ("plate_left", "plate_right", "plate_bottom", "plate_top")
COLUMNS = ["step", "phase"] + [f"{p}_{c}" for p in PLATES for c in ("normal", "tangential")] + [
    "newton_iterations", "wall_s"]
# fmt: on


def parse(argv):
    p = cli.demo_parser("grain_assembly.py", __doc__, "results/grain_assembly", OPTIONS,
                        discretization=False, multi_step=True)  # fmt: skip
    a = p.parse_args(argv)
    if not 5 <= a.radius / a.h <= 100:
        p.error(f"--h: must give 5 <= radius/h <= 100 (radius {a.radius:g}), got {a.h}")
    if not a.compression <= 0.1 * a.h:
        p.error(f"--compression: must be <= h/10 = {0.1 * a.h:g} per step, got {a.compression}")
    if not a.steps * a.compression <= 0.1 * a.radius:
        p.error(f"--compression: steps x compression must be <= 0.1 radius = {0.1 * a.radius:g}")
    if a.steps + a.shear_steps == 0:
        p.error("--steps: at least one compression or shear step is needed")
    return a


def evaluate(run):
    worst, warn = 0.0, run.metrics["solver"]["warnings"]
    for rec in run.records:
        fmax = max([q["normal_force"] for q in rec["pairs"]] + [1e-300])
        plates = np.hypot(*np.sum([[o["fx"], o["fy"]] for o in rec["obstacles"].values()], 0))
        worst = max(worst, equilibrium_error(rec), plates / fmax)
    run.results.update(
        equilibrium_rel_max=float(worst),
        newton_iterations=[r["newton_iterations"] for r in run.records],
        contacts_final=len([q for q in run.records[-1]["pairs"] if q["normal_force"] > 0]),
        top_normal_final=run.rows[-1]["plate_top_normal"],
        top_tangential_final=run.rows[-1]["plate_top_tangential"],
    )
    if worst > 1e-8:
        warn.append(f"equilibrium of the grains or plates off by {worst:.1e} (> 1e-8)")


def summary(run):
    r = run.results
    return (
        f"grain assembly: {run.params['grains']} grains, {len(run.rows)} steps, "
        f"{r['contacts_final']} contacts at the end, top plate N = {r['top_normal_final']:.5g}, "
        f"T = {r['top_tangential_final']:.4g} N/mm; equilibrium {r['equilibrium_rel_max']:.1e}; "
        f"Newton per step {np.mean(r['newton_iterations']):.1f}"
    )


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    with Run("grain_assembly", vars(args), discretization="cut", plot=False) as run:
        # the scene: a hexagonal packing of elliptic grains between four rigid plates
        grid, bodies, plates, scene, box, _ = grain_assembly(
            run.comm, args.grains, args.radius, args.h, aspect=1.1, overlap=0.02 * args.h
        )
        d = args.compression  # the plates' inward travel per compression step
        for name, t in zip(PLATES, ((d, 0), (-d, 0), (0, d), (0, -d))):
            plates[name].translation = np.array(t, float)
        run.data.update(plates=plates, height=box[1, 1] - box[0, 1])
        # the problem: Coulomb friction at the friction angle, on grains and plates alike
        mpm_bodies = [MPMBody(n, t, (args.E, args.nu), s) for n, t, s in bodies]
        mu = np.tan(np.radians(args.friction_angle))
        # the predictor holds the grains where they touch (they start 0.02 h overlapped)
        kw = dict(obstacles=list(plates.values()), mu=mu, predictor_gap=0.05 * args.h)
        sim = ImplicitMPM(  # problem_options: eps0, --petsc, --linear-solver
            run.comm, grid, mpm_bodies, scene, **kw, timer=run.timer, **run.problem_options
        )

        # the run: compression by the four plates, then simple shear (the lateral plates turn)
        steps = Steps(run, sim, COLUMNS, args.steps + args.shear_steps)
        for _ in range(args.steps + args.shear_steps):
            rec = steps.step()
            phase = "compression" if rec["step"] <= args.steps else "shear"
            steps.rows.append(dict(
                step=rec["step"], phase=phase, newton_iterations=rec["newton_iterations"],
                wall_s=rec["wall_s"], **plate_frame_forces(rec, plates),
            ))  # fmt: skip
            if rec["step"] == args.steps:  # compression done: turn the lateral plates from now on
                run.data["end_of_compression"] = rec
                for name in PLATES:
                    plates[name].translation = np.zeros(2)
                for name in ("plate_left", "plate_right"):
                    plates[name].rotation = -np.radians(args.shear_rotation)
        steps.measure()

        # the check (rank 0)
        if run.rank0:
            evaluate(run)
        run.finish(summary, **steps.outputs(grain_assembly_plots))
    return run.status


if __name__ == "__main__":
    cli.exit_process(main())
