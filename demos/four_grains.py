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

import numpy as np

if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
from dolfinx_forms.app import cli
from dolfinx_forms.app.demo import Run
from dolfinx_forms.app.mpm_run import Steps, binned_mean, plot_force_chains
from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody, equilibrium_error
from meshes.four_grains import check_contact_zones, four_grains, grain_outlines
from meshes.mpm import plate_face_conditions, plate_forces

# fmt: off
OPTIONS = [  # option, kind, default[, help]
    ("--radius", "(0, inf)", 2.0, "mean radius of the largest given grain size (mm)"),
    ("--seed", int, 1, "seed of the Fourier grain outline, in [0, 2^31)"),
    ("--E", "(0, inf)", 10e3, "Young's modulus (N/mm^2)"),
    ("--nu", "(-1, 0.5)", 0.3),
    ("--mu", "(0, inf)", 0.5, "friction coefficient (> 0: frictionless grains turn freely)"),
    ("--displacement", "(0, inf)", 1e-3, "inward motion of each plate per step (mm)"),
    ("--overlap", "(0, inf)", 1e-3, "initial overlap of touching bodies (mm)"),
    ("--steps", range(1, 1001), 1),
    ("--h", "(0, inf)", 0.1, "grid spacing (mm)"),
    ("--eps0", "(0, inf)", 1.0),
]
COLUMNS = ["step", "displacement", "force_left", "force_right", "force_bottom", "force_top",
           "active_contacts", "min_stick_fraction", "newton_iterations", "wall_s"]
# fmt: on
GRAINS = [f"grain{i}" for i in range(4)]
CLEARANCE = 0.25  # mm between a plate's end and the perpendicular plate's inner face


def parse(argv):
    p = cli.demo_parser(
        "four_grains.py",
        __doc__,
        "results/four_grains",
        OPTIONS,
        discretization=False,
        enforcement=cli.MPM_ENFORCEMENT,
    )
    a = p.parse_args(argv)
    if not 0 <= a.seed < 2**31:
        p.error(f"--seed: must be in [0, 2^31), got {a.seed}")
    if not 5 <= a.radius / a.h <= 200:
        p.error(f"--h: must give 5 <= radius/h <= 200 (radius {a.radius:g}), got {a.h}")
    if not a.overlap <= 0.5 * a.h:
        p.error(f"--overlap: must be in (0, h/2] = (0, {0.5 * a.h:g}], got {a.overlap}")
    if not a.steps * a.displacement <= 0.05 * a.radius:
        p.error(
            f"--displacement: steps x displacement must be <= 0.05 radius = " f"{0.05 * a.radius:g}"
        )
    try:  # the arrangement depends on the seed (numpy only, ~0.5 s): checked before any output
        a.outlines = grain_outlines(a.radius, a.seed, a.overlap)
    except ValueError as e:
        p.error(f"--seed: {e}")
    try:
        check_contact_zones(*a.outlines[:2], a.h, a.overlap, CLEARANCE)
    except ValueError as e:
        p.error(f"--h: {e}")
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
    f = rec["body_forces"]
    plates = dict(
        left=-f["plate_left"][0],
        right=f["plate_right"][0],
        bottom=-f["plate_bottom"][1],
        top=f["plate_top"][1],
    )
    run.results.update(
        equilibrium_rel=eq,
        newton_iterations=[r["newton_iterations"] for r in run.records],
        contacts=len(act),
        contacts_per_grain=per_grain,
        max_normal_force=fmax,
        plate_forces=plates,
        stick_fraction=stick,
        slipping_contacts=sorted(k for k, v in stick.items() if v < 1),
        grain3_scale=run.data["outlines"][2],
        grain3_angle=run.data["outlines"][3],
    )
    warn = run.metrics["solver"]["warnings"]
    if eq > 1e-8:
        warn.append(f"a body is out of equilibrium by {eq:.1e} of the largest contact force")
    lost = {g: n for g, n in per_grain.items() if n < 4}
    if lost:
        warn.append(f"grains with fewer than their 4 contacts: {lost}")


def max_principal(s):
    """Largest principal stress of [s_xx, s_yy, s_xy] rows."""
    return 0.5 * (s[:, 0] + s[:, 1]) + np.hypot(0.5 * (s[:, 0] - s[:, 1]), s[:, 2])


def plots(run, folder):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sim, rec = run.sim, run.records[-1]
    plot_force_chains(sim, rec, folder / "force_chains.png", "four grains")
    x = np.concatenate([p.x for p in sim.points.values()])
    s1 = max_principal(np.concatenate([p.stress for p in sim.points.values()]))
    lim = np.percentile(np.abs(s1), 99.5)  # the contact peaks would wash out the rest
    fig, ax = plt.subplots(figsize=(6, 6))
    image, extent = binned_mean(x, s1, sim.h)
    sc = ax.imshow(image, extent=extent, origin="lower", cmap="RdBu_r", vmin=-lim, vmax=lim)
    for q in active(rec):
        ax.plot(q["x"], q["y"], "k+", ms=6)
    fig.colorbar(sc, ax=ax, label="largest principal stress (N/mm^2)", shrink=0.8)
    ax.set(aspect="equal", title=f"four grains: largest principal stress, step {rec['step']}")
    fig.tight_layout()
    fig.savefig(folder / "max_principal_stress.png", dpi=120)
    plt.close(fig)


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
        grid, bodies, scene, faces = four_grains(
            run.comm,
            h=args.h,
            radius=args.radius,
            seed=args.seed,
            overlap=args.overlap,
            clearance=CLEARANCE,
            outlines=outlines,
        )
        run.data["faces"] = faces
        # the problem: the plates' outer faces moved inward by `displacement` per step
        sim = ImplicitMPM(
            run.comm,
            grid,
            [MPMBody(n, t, (args.E, args.nu), s) for n, t, s in bodies],
            scene,
            dirichlet=plate_face_conditions(faces, args.displacement),
            timer=run.timer,
            **run.problem_options,  # mu, eps0, --petsc, --linear-solver
        )

        # the run
        steps = Steps(run, sim, COLUMNS, args.steps, series_every=1)
        for _ in range(args.steps):
            rec = steps.step()
            act = active(rec)
            steps.rows.append(
                dict(
                    step=rec["step"],
                    displacement=rec["step"] * args.displacement,
                    **plate_forces(rec),
                    active_contacts=len(act),
                    min_stick_fraction=min(q["stick_fraction"] for q in act),
                    newton_iterations=rec["newton_iterations"],
                    wall_s=rec["wall_s"],
                )
            )
        steps.measure()

        # the check (rank 0)
        if run.rank0:
            evaluate(run)
        run.finish(summary, **steps.outputs(plots))
    return run.status


if __name__ == "__main__":
    cli.exit_process(main())
