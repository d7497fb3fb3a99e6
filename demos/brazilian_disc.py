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

import numpy as np

if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
from dolfinx_forms.app import cli
from dolfinx_forms.app.demo import Run
from dolfinx_forms.app.mpm_run import Steps, binned_mean
from dolfinx_forms.fem.boundary import Dirichlet
from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
from meshes.mpm import brazilian_disc

# fmt: off
OPTIONS = [  # option, kind, default[, help]
    ("--R", "(0, inf)", 10.0, "disc radius (mm)"),
    ("--E", "(0, inf)", 100e3, "Young's modulus (N/mm^2)"),
    ("--nu", "(-1, 0.5)", 0.3),
    ("--mu", "[0, inf)", 0.5),
    ("--step-displacement", "(0, inf)", 0.02, "platen travel per step (mm)"),
    ("--steps", range(1, 10001), 50),
    ("--h", "(0, inf)", 0.2, "grid spacing (mm)"),
    ("--eps0", "(0, inf)", 0.6,
     "penalty factor (eq 51, eps = eps0 h / (2 E) against the rigid platens); 0.6: the "
     "penalty's compliance stays well below the disc's at a = 5 h (eps0 = 2 widens a by 13 %% "
     "there)"),
    ("--series-every", range(1, 10001), 10, "steps between frames of the time series"),
]
COLUMNS = ["step", "displacement", "force_top", "force_bottom", "half_width_top",
           "half_width_bottom", "area_levelset", "volume_points", "newton_iterations", "wall_s"]
# fmt: on


def parse(argv):
    p = cli.demo_parser(
        "brazilian_disc.py",
        __doc__,
        "results/brazilian_disc",
        OPTIONS,
        discretization=False,
        enforcement=cli.MPM_ENFORCEMENT,
    )
    a = p.parse_args(argv)
    if not a.h <= a.R / 5:
        p.error(
            f"--h: must be in (0, R/5] = (0, {a.R / 5:g}] (at least 10 cells across), got {a.h}"
        )
    if not a.R / a.h <= 2000:
        p.error(
            f"--h: must be >= R/2000 = {a.R / 2000:g} (grid of at most 4000^2 cells), got {a.h}"
        )
    if not a.steps * a.step_displacement <= 0.2 * a.R:
        p.error(
            f"--step-displacement: steps x step must be <= 0.2 R = {0.2 * a.R:g} "
            f"(small-strain MPM), got {a.steps * a.step_displacement:g}"
        )
    if not a.step_displacement <= 0.5 * a.h:
        p.error(
            f"--step-displacement: must be <= h/2 = {0.5 * a.h:g} per step (contact band "
            f"and level-set advection), got {a.step_displacement}"
        )
    return a


def hertz_half_width(F, R, E, nu):
    """Cylinder on a rigid flat (plane strain): a = 2 sqrt(F R (1 - nu^2) / (pi E))."""
    return 2 * np.sqrt(np.maximum(F, 0) * R * (1 - nu**2) / (np.pi * E))


def evaluate(run):
    """Hertz half-width where a > 5 h, force balance, area vs point volume, mass."""
    p, rows = run.params, run.rows
    F = np.array([r["force_top"] for r in rows])
    Fb = np.array([r["force_bottom"] for r in rows])
    a = np.array([[r["half_width_top"], r["half_width_bottom"]] for r in rows])
    a_h = hertz_half_width(F, p["R"], p["E"], p["nu"])
    judged = a.min(axis=1) > 5 * p["h"]
    err = np.abs(a / a_h[:, None] - 1)
    balance = np.abs(F - Fb) / np.maximum(np.abs(F), 1e-300)
    area = np.array([r["area_levelset"] for r in rows])
    vol = np.array([r["volume_points"] for r in rows])
    mass = [r["mass"]["disc"] for r in run.records]
    run.results.update(
        force_top=F.tolist(),
        force_bottom=Fb.tolist(),
        half_width=a.tolist(),
        half_width_rel_error_max=float(err[judged].max()) if judged.any() else None,
        steps_judged=int(judged.sum()),
        force_balance_rel_max=float(balance.max()),
        area_vs_points_rel_max=float(np.max(np.abs(area / vol - 1))),
        mass_rel_change=float(abs(mass[-1] / mass[0] - 1)),
        newton_iterations_mean=float(np.mean([r["newton_iterations"] for r in rows])),
        reinitializations=int(sum(r["reinitialized"]["disc"] for r in run.records)),
        gradient_drift_max=float(max(r["gradient_drift"]["disc"] for r in run.records)),
        points_outside_cells_max=int(max(r["points_outside_cells"] for r in run.records)),
    )
    run.analytic.update(half_width=a_h.tolist())
    warn = run.metrics["solver"]["warnings"]
    if judged.any() and err[judged].max() > 0.05:
        warn.append(f"half-width differs from Hertz by {err[judged].max():.1%} (> 5 %) at a > 5 h")
    if balance.max() > 1e-6:
        warn.append(f"platen forces differ by {balance.max():.1e} relative (> 1e-6)")
    if run.results["area_vs_points_rel_max"] > 0.01:
        warn.append(
            f"level-set area and point volume differ by {run.results['area_vs_points_rel_max']:.1%}"
        )
    run.results["mls_widened_points"] = int(sum(r["mls_widened"] for r in run.records))


def plots(run, folder):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    p, rows = run.params, run.rows
    F = np.array([r["force_top"] for r in rows])
    Fs = np.linspace(0, F.max(), 200)
    fig, ax = plt.subplots(figsize=(5, 4))
    ax.plot(Fs, hertz_half_width(Fs, p["R"], p["E"], p["nu"]), "k-", label="Hertz")
    ax.plot(F, [r["half_width_top"] for r in rows], "o", ms=3, label="top platen")
    ax.plot(F, [r["half_width_bottom"] for r in rows], "x", ms=3, label="bottom platen")
    ax.axhline(5 * p["h"], color="0.6", ls=":", label="5 h")
    ax.set(xlabel="F (N/mm)", ylabel="a (mm)", title="Brazilian disc: contact half-width")
    ax.legend()
    fig.tight_layout()
    fig.savefig(folder / "half_width.png", dpi=120)
    plt.close(fig)
    frames = run.data["series"]["disc"].frames  # (step, x, {stress, ...}, cells)
    frames = [
        frames[k] for k in sorted({0, len(frames) // 3, 2 * len(frames) // 3, len(frames) - 1})
    ]
    fig, axes = plt.subplots(1, len(frames), figsize=(3.2 * len(frames), 3.4), squeeze=False)
    lo = min(f[2]["stress"][:, 1].min() for f in frames)
    for ax, (step, x, data, _) in zip(axes[0], frames):
        image, extent = binned_mean(x, data["stress"][:, 1], p["h"])
        sc = ax.imshow(image, extent=extent, origin="lower", cmap="viridis", vmin=lo, vmax=0)
        ax.set(aspect="equal", title=f"step {step:g}", xticks=[], yticks=[])
    fig.colorbar(sc, ax=axes[0].tolist(), label="sigma_yy at the material points (N/mm^2)")
    fig.savefig(folder / "sigma_yy.png", dpi=120)
    plt.close(fig)


def summary(run):
    r = run.results
    err = r["half_width_rel_error_max"]
    return (
        f"Brazilian disc: {len(run.rows)} steps, F = {r['force_top'][-1]:.6g} N/mm, "
        f"a = {r['half_width'][-1][0]:.4g} mm (Hertz {run.analytic['half_width'][-1]:.4g}), "
        f"max |a/a_Hertz - 1| over {r['steps_judged']} steps with a > 5 h: "
        + ("n/a" if err is None else f"{err:.2%}")
        + f", force balance {r['force_balance_rel_max']:.1e}, "
        f"Newton {r['newton_iterations_mean']:.1f} per step"
    )


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    with Run("brazilian", vars(args), discretization="cut", plot=False) as run:
        # the scene: the disc's level set and material points, the two rigid platens, moving
        grid, (name, tag, shape), platens, scene = brazilian_disc(
            run.comm, args.R, args.h, args.step_displacement, args.steps
        )
        # the problem: the disc (plane strain, linear elastic) between the platens, x = 0 held
        # horizontally (the symmetry line)
        symmetry = Dirichlet(lambda x: np.isclose(x[0], 0.0, atol=1e-9 * args.R), 0, 0.0)
        sim = ImplicitMPM(
            run.comm,
            grid,
            [MPMBody(name, tag, (args.E, args.nu), shape)],
            scene,
            obstacles=platens,
            dirichlet=[symmetry],
            timer=run.timer,
            **run.problem_options,  # mu, eps0, --petsc, --linear-solver
        )

        # the run: the platens close by step_displacement per step
        steps = Steps(run, sim, COLUMNS, args.steps, args.series_every)
        for _ in range(args.steps):
            rec = steps.step()
            widths = {q["body_j"]: q["half_width"] for q in rec["pairs"]}
            steps.rows.append(
                dict(
                    step=rec["step"],
                    displacement=rec["step"] * args.step_displacement,
                    force_top=rec["obstacles"]["platen_top"]["fy"],
                    force_bottom=-rec["obstacles"]["platen_bottom"]["fy"],
                    half_width_top=widths.get("platen_top", 0.0),
                    half_width_bottom=widths.get("platen_bottom", 0.0),
                    area_levelset=rec["area_levelset"]["disc"],
                    volume_points=rec["volume_points"]["disc"],
                    newton_iterations=rec["newton_iterations"],
                    wall_s=rec["wall_s"],
                )
            )
        steps.measure()

        # the check: Hertz's half-width where a > 5 h, force balance, area against the
        # points' volume, mass (rank 0)
        if run.rank0:
            evaluate(run)
        run.finish(summary, **steps.outputs(plots))
    return run.status


if __name__ == "__main__":
    cli.exit_process(main())
