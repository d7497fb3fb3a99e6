#!/usr/bin/python3
"""Four grains in four deformable plates under isotropic compression (paper 5.2.3).

Physics. One seeded Fourier sand-grain outline (meshes.grains.fourier_grain: elongation 0.15,
RMS roughness 0.03, 128 vertices) is used four times with different sizes, rotations and
positions on a 2 x 2 arrangement (meshes/four_grains.py), confined by four deformable plates
(thickness 1 mm, rounded up to the grid) whose outer faces move inward by --displacement per
step; E = 10 GPa, nu = 0.3 (plane strain) for grains and plates, Coulomb friction mu
everywhere. Every contact (grain-grain and grain-plate) starts closed with the same --overlap:
a grain whose contacts are all open is free and the first Newton iteration would be singular.

The check. Every body is in equilibrium (its contact forces plus, for the plates, the supports
of the outer faces) to 1e-8 of the largest contact force; every grain keeps its four contacts
(two neighbours, two plates); Newton iterations per step; the plate forces; and whether the
contacts slip (the paper: "an obvious shift between two stress concentration regions due to
slipping"): the stick fraction of every contact's active zone.

Run: /usr/bin/python3 demos/four_grains.py [--h 0.1] [--mu 0.5] [--steps 1]
Results and discussion: docs/demos/four_grains.md
"""

import importlib.util
import sys

if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
from dolfinx_forms.app import cli
from dolfinx_forms.app.demo import Run
from dolfinx_forms.app.mpm_run import Steps
from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody, equilibrium_error
from meshes.four_grains import checked_outlines, four_grains
from meshes.mpm import plate_face_conditions, plate_forces
from meshes.plots import four_grains_plots

# fmt: off
OPTIONS = [  # option, kind, default[, help]
    ("--radius", "(0, inf)", 2.0, "mean radius of the largest given grain size (mm)"),
    ("--seed", int, 1, "seed of the Fourier grain outline, in [0, 2^31)"),
    ("--E", "[1e-3, 1e7]", 10e3, "Young's modulus (N/mm^2; verified 1e-3 to 1e7)"),
    ("--nu", "(-1, 0.5)", 0.3),
    ("--mu", "(0, inf)", 0.5, "friction coefficient (> 0: frictionless grains turn freely)"),
    ("--displacement", "(0, inf)", 1e-3, "inward motion of each plate per step (mm)"),
    ("--overlap", "(0, inf)", 1e-3, "initial overlap of touching bodies (mm)"),
    ("--steps", range(1, 1001), 1),
    ("--h", "(0, inf)", 0.1, "grid spacing (mm)"),
    ("--eps0", cli.MPM_EPS0_INTERVAL, 1.0, cli.MPM_EPS0_HELP),
]
COLUMNS = ["step", "displacement", "force_left", "force_right", "force_bottom", "force_top",
           "active_contacts", "min_stick_fraction", "newton_iterations", "wall_s"]
# fmt: on
GRAINS = [f"grain{i}" for i in range(4)]
CLEARANCE = 0.25  # mm between a plate's end and the perpendicular plate's inner face


def parse(argv):
    p = cli.demo_parser("four_grains.py", __doc__, "results/four_grains", OPTIONS,
                        discretization=False, multi_step=True)  # fmt: skip
    a = p.parse_args(argv)
    try:  # the arrangement depends on the seed (numpy only, ~0.5 s): checked before any output
        travel = a.steps * a.displacement
        a.outlines = checked_outlines(a.radius, a.seed, a.h, a.overlap, CLEARANCE, travel)
    except ValueError as e:
        p.error(str(e))
    return a


def active(rec):
    return [q for q in rec["pairs"] if q["normal_force"] > 0]


def evaluate(run):
    rec = run.records[-1]
    act = active(rec)
    fmax = max(q["normal_force"] for q in act)
    eq = equilibrium_error(rec)  # contacts + supports (the plates' outer faces)
    per_grain = {g: sum(g in (q["body_i"], q["body_j"]) for q in act) for g in GRAINS}
    stick = {f"{q['body_i']}-{q['body_j']}": q["stick_fraction"] for q in act}
    plates = {k.removeprefix("force_"): v for k, v in plate_forces(rec).items()}
    run.results.update(
        equilibrium_rel=eq,
        newton_iterations=[r["newton_iterations"] for r in run.records],
        contacts=len(act), contacts_per_grain=per_grain, max_normal_force=fmax,
        plate_forces=plates, stick_fraction=stick,
        slipping_contacts=sorted(k for k, v in stick.items() if v < 1),
        grain3_scale=run.data["outlines"][2], grain3_angle=run.data["outlines"][3],
    )  # fmt: skip
    warn = run.metrics["solver"]["warnings"]
    if eq > 1e-8:
        warn.append(f"a body is out of equilibrium by {eq:.1e} of the largest contact force")
    lost = {g: n for g, n in per_grain.items() if n < 4}
    if lost:
        warn.append(f"grains with fewer than their 4 contacts: {lost}")


def summary(run):
    r = run.results
    pf = r["plate_forces"]
    return (
        f"four grains: {r['contacts']} contacts, largest normal force "
        f"{r['max_normal_force']:.5g} N/mm; plates L/R/B/T {pf['left']:.4g} {pf['right']:.4g} "
        f"{pf['bottom']:.4g} {pf['top']:.4g} N/mm; slipping contacts "
        f"{len(r['slipping_contacts'])}; equilibrium {r['equilibrium_rel']:.1e}; "
        f"Newton {r['newton_iterations']}"
    )


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    params = vars(args)
    outlines = params.pop("outlines")
    with Run("four_grains", params, discretization="cut", plot=False) as run:
        # the scene: four Fourier grains in a box of four plates, level sets with points
        run.data["outlines"] = outlines
        size = dict(h=args.h, radius=args.radius, seed=args.seed, overlap=args.overlap)
        grid, bodies, scene, faces = four_grains(
            run.comm, **size, clearance=CLEARANCE, outlines=outlines
        )
        run.data["faces"] = faces
        # the problem: the plates' outer faces moved inward by `displacement` per step
        mpm_bodies = [MPMBody(n, t, (args.E, args.nu), s) for n, t, s in bodies]
        kw = dict(dirichlet=plate_face_conditions(faces, args.displacement), timer=run.timer)
        sim = ImplicitMPM(run.comm, grid, mpm_bodies, scene, **kw, **run.problem_options)

        # the run
        steps = Steps(run, sim, COLUMNS, args.steps, series_every=1)
        for _ in range(args.steps):
            rec = steps.step()
            act = active(rec)
            steps.rows.append(dict(
                step=rec["step"], displacement=rec["step"] * args.displacement,
                **plate_forces(rec), active_contacts=len(act),
                min_stick_fraction=min(q["stick_fraction"] for q in act),
                newton_iterations=rec["newton_iterations"], wall_s=rec["wall_s"],
            ))  # fmt: skip
        steps.measure()

        # the check (rank 0)
        if run.rank0:
            evaluate(run)
        run.finish(summary, **steps.outputs(four_grains_plots))
    return run.status


if __name__ == "__main__":
    cli.exit_process(main())
