#!/usr/bin/python3
"""Frictionless contact patch test: two stacked blocks under uniform compression.

Physics. Blocks [0,1]x[0,0.5] and [0,1]x[0.5,1] (E = 1, nu = 0.3, plane strain), the bottom
held vertically, the top moved down by d = 0.01, one point of each block held horizontally,
sides free. The exact solution is a uniform stress: sigma_yy = -E/(1-nu^2) d/H
= -0.010989011 and a uniform contact pressure of the same size, zero shear; with the penalty
(eq 8) the pressure is p = E' d / (H + E' eps_n), E' = E/(1-nu^2).

The check. Linear fields are reproduced exactly, so the contact pressure must be uniform and
equal to the penalised value (--enforcement penalty) or the exact one (augmented) to
round-off, with the interface on mesh lines (conforming) or cutting a row of cells
(--discretization cut, interface y = --interface); metrics.json reports the spread, the shear,
and both analytic values.

Run: /usr/bin/python3 demos/patch_test.py [--discretization cut] [--h 0.125]
Results and discussion: docs/demos/patch_test.md
"""

import importlib.util
import sys

import numpy as np

if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
from dolfinx_forms.analysis import compare
from dolfinx_forms.app import cli
from dolfinx_forms.app.demo import Run
from dolfinx_forms.solvers.protocol import ramp
from meshes.cut import patch_cut_scene
from meshes.patch import patch_dirichlet, patch_scene

# fmt: off
OPTIONS = [  # option, kind, default[, help]
    ("--interface", "(0, 1)", None,
     "cut path: height of the interface, off the grid lines (default 0.5 + 0.3 h)"),
    ("--h", "(0, 0.5]", 0.125, "mesh size (cells of the lower block: 1/h x 0.5/h)"),
    ("--E", "(0, inf)", 1.0),
    ("--nu", "(-1, 0.5)", 0.3),
    ("--mu", "[0, inf)", 0.0),
    ("--displacement", "(0, 0.1]", 0.01, "downward displacement of the top"),
    ("--eps0", "(0, inf)", 1.0),
    ("--upper-cells", int, None,
     "cells across the upper block (default: as the lower; non-matching otherwise)"),
    ("--degree", [1, 2], 1),
    ("--triangles", bool, False),
]
# fmt: on


def parse(argv):
    p = cli.demo_parser("patch_test.py", __doc__, "results/patch_test", OPTIONS)
    a = p.parse_args(argv)
    if a.h < 1e-3:
        p.error(f"--h: must be >= 1/1000 (at most 1000 x 500 cells per block), got {a.h}")
    nx = round(1.0 / a.h)
    if abs(nx * a.h - 1.0) > 1e-12:
        p.error(
            f"--h: must be 1/n for an integer n so that the interface lies on mesh lines, "
            f"got {a.h}"
        )
    if a.upper_cells is not None and not 1 <= a.upper_cells <= 1000:
        p.error("--upper-cells: must be in [1, 1000]")
    if a.discretization == "conforming" and a.interface is not None:
        p.error("--interface: only for --discretization cut (the gmsh blocks meet at 0.5)")
    if a.discretization == "cut":
        a.interface = 0.5 + 0.3 * a.h if a.interface is None else a.interface
        if abs(a.interface / a.h - round(a.interface / a.h)) < 1e-9:
            p.error(
                f"--interface: must not lie on a grid line (multiples of h = {a.h}), "
                f"got {a.interface}"
            )
        if a.upper_cells is not None:
            p.error("--upper-cells: only for --discretization conforming")
    return a


SUMMARY = (
    "patch test: pressure {results[pressure_mean]:.10f} (penalised exact "
    "{analytic[pressure_penalised]:.10f}, eps -> 0: {analytic[pressure]:.10f}), max deviation "
    "{results[pressure_max_rel_deviation]:.2e}, max shear {results[shear_max]:.2e}"
)


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    with Run("patch", vars(args)) as run:
        # the scene: a uniform grid cut by the interface, or gmsh blocks meeting at y = 0.5
        nx, cut = round(1.0 / args.h), args.discretization == "cut"
        run.metrics["mesh"]["h_contact"] = args.h
        with run.phase("mesh"):
            if cut:
                run.scene = patch_cut_scene(run.comm, n=nx, interface=args.interface)
            else:
                ny, quads = max(1, nx // 2), not args.triangles
                run.scene = patch_scene(run.comm, nx, ny, quads, nx_upper=args.upper_cells)

        # the problem: bottom held vertically, one point of each block horizontally; body-fitted,
        # the level-set grid passes through the blocks' corners, as the meshes do (a corner inside
        # a grid cell bends Gamma_c there: the clip at the ends moves by ~h / 40)
        bcs = patch_dirichlet(args.displacement)
        origin = None if cut else (0.0, 0.0)
        run.problem = run.contact_problem(bcs, band=0.5 * args.h, pair_grid_origin=origin)

        # the run: the top moved down
        run.records = [ramp(run.problem, bcs[1], -args.displacement, label="patch")]
        run.measure(reactions=["upper_top"])

        # the check: uniform pressure (against the penalised and the exact value: the augmented
        # Lagrangian's compliance is 0) and zero shear
        if run.rank0:
            pts = run.pts
            eps_n = 0.0 if run.problem.contact.augmented else run.problem.eps_n
            res, an, run.curves = compare.patch(
                pts, args.E, args.nu, args.displacement, 1.0, eps_n
            )
            run.results.update(
                reaction=run.reactions["upper_top"],
                **res,
                shear_max=float(np.max(np.abs(pts["p_t"]))),
                contact_length=float(np.sum(pts["w"])),
            )
            run.analytic.update(an)
            run.plot_kw = dict(title="patch test", xlabel="x", ylabel="traction")
        run.finish(SUMMARY)
    return run.status


if __name__ == "__main__":
    cli.exit_process(main())
