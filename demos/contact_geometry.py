#!/usr/bin/python3
"""Contact geometry of the Hertz set-up: the intermediate surface between a cylinder and a block.

Physics. A cylinder of radius R sits at a gap g above a block (both level sets on one
structured grid of spacing h). The unbiased contact surface Gamma_c is the zero contour of
phi_int = (phi_block - phi_cyl)/2 (eq 23) inside the contact region (eq 22). For a flat
face and a circle that curve is the parabola y = (x^2 + 2Rg + g^2) / (2(2R + g)), and at
a point of it at distance d from both bodies the initial normal gap (eq 28) is
g_n0 = d |n_block - n_cyl|.

The check. The demo builds Gamma_c, projects its quadrature points onto both bodies (eq 25),
and reports the errors of position and gap against these formulas.

Run: /usr/bin/python3 demos/contact_geometry.py [--R 10 --gap 0.02 --h 0.05 --out DIR]
Results and discussion: docs/demos/contact_geometry.md
"""

import importlib.util
import sys
from types import SimpleNamespace

import numpy as np

if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
import dolfinx_forms as df
from dolfinx_forms.app import cli
from dolfinx_forms.app.demo import Run
from dolfinx_forms.io.output import write_columns
from dolfinx_forms.solvers.newton import ContactSolverError
from meshes.plots import contact_geometry_plot

OPTIONS = [  # option, kind, default[, help]
    ("--R", "(0, inf)", 10.0, "radius (mm)"),
    ("--gap", "[0, inf)", 0.02, "initial gap (mm)"),
    ("--h", "(0, inf)", 0.05, "grid spacing at the contact (mm)"),
    ("--eps", "(0, inf)", None, "contact-region shift of eq 22 (mm), default 4 h"),
    ("--width", "(0, inf)", 2.0, "half-width of the grid window around the contact (mm)"),
]


def parse(argv=None):
    p = cli.demo_parser("contact_geometry.py", __doc__, "results/contact_geometry", OPTIONS, 0, 0)
    args = p.parse_args(argv)
    if args.h > args.width / 4:
        p.error(f"argument --h: must be <= width/4 = {args.width / 4}, got {args.h}")
    if args.width > args.R:
        p.error(f"argument --width: must be <= R = {args.R}, got {args.width}")
    if args.h < args.width / 2000:
        p.error(
            f"argument --h: must be >= width/2000 = {args.width / 2000:g} (a grid of at most "
            f"4000 x 2000 cells), got {args.h}"
        )
    if args.R > 1e9 * args.width:
        p.error(
            f"argument --R: must be <= 1e9 width = {1e9 * args.width:g} (a flatter cylinder is "
            f"flat to round-off), got {args.R}"
        )
    args.eps = 4 * args.h if args.eps is None else args.eps
    if not args.gap < min(2 * args.eps, args.width):
        p.error(
            f"argument --gap: must be < min(2 eps, width) = {min(2 * args.eps, args.width):g} "
            f"(the contact region of eq 22 is empty, or outside the grid), got {args.gap}"
        )
    return args


def evaluate(run):
    """Independent references from the outputs themselves: the parabola and the exact gap."""
    p, d, sc = run.params, run.data, run.scene
    R, g, x = p["R"], p["gap"], d["s"]["points"]
    parabola = (x[:, 0] ** 2 + 2 * R * g + g**2) / (2 * (2 * R + g))
    n_cyl = (x - sc.centre) / np.linalg.norm(x - sc.centre, axis=1)[:, None]
    d["exact"] = x[:, 1] * np.linalg.norm(np.array([0.0, 1.0]) - n_cyl, axis=1)  # y: distance
    its = max(d["pi"]["iterations"].max(), d["pj"]["iterations"].max())
    run.metrics["mesh"].update(h_contact=p["h"], num_cells=sc.grid.num_cells, num_dofs=None)
    run.results.update(
        num_contact_points=int(len(x)),
        surface_length=float(d["s"]["weights"].sum()),
        position_max_error=float(np.abs(x[:, 1] - parabola).max()),
        gap_max_error=float(np.abs(d["g_n0"] - d["exact"]).max()),
        projection_max_iterations=int(its),
    )
    run.analytic.update(min_gap=g)


def files(run, folder):
    """contact_points.csv and contact_geometry.png (the bodies and Gamma_c; g_n0 vs exact)."""
    d, x, n = run.data, run.data["s"]["points"], run.data["s"]["normals"]
    pi, pj = d["pi"]["points"], d["pj"]["points"]
    write_columns(
        folder / "contact_points.csv", x=x[:, 0], y=x[:, 1], nx=n[:, 0], ny=n[:, 1],
        weight=d["s"]["weights"], pi_x=pi[:, 0], pi_y=pi[:, 1], pj_x=pj[:, 0], pj_y=pj[:, 1],
        g_n0=d["g_n0"],
    )  # fmt: skip
    contact_geometry_plot(run, folder / "contact_geometry.png")


SUMMARY = (
    "contact geometry: h = {parameters[h]} mm, {results[num_contact_points]} contact points, "
    "position error {results[position_max_error]:.2e} mm, gap error {results[gap_max_error]:.2e} "
    "mm, {timing_s[total]:.3f} s"
)


def main(argv=None):
    args = parse(argv)
    with Run("contact_geometry", vars(args), discretization="cut", plot=False) as run:
        # the scene: the block y < 0 and the cylinder of centre (0, R + g), level sets on a grid
        R, w, n = args.R, args.width, int(np.ceil(2 * args.width / args.h))
        with run.phase("mesh"):
            grid = df.StructuredGrid.uniform([-w, -w / 2], [w, w / 2], [n, n // 2])
            centre = np.array([0.0, R + args.gap])
            block = df.levelset_from_shape(grid, df.Box([-4 * R, -4 * R], [4 * R, 0.0]))
            cyl = df.levelset_from_shape(grid, df.Circle(centre, R))
            run.scene = SimpleNamespace(grid=grid, centre=centre, block=block, cyl=cyl)

        # the geometry: Gamma_c (eqs 21-24), its points projected onto both bodies (eq 25), the
        # initial gaps (eq 28)
        with run.phase("contact"):
            s = df.contact_surface(block, cyl, eps=args.eps)
            pi = df.closest_point_projection(block, s["points"])
            pj = df.closest_point_projection(cyl, s["points"])
        if not (pi["converged"].all() and pj["converged"].all()):
            k = np.flatnonzero(~(pi["converged"] & pj["converged"]))[0]
            raise ContactSolverError(
                f"closest-point projection failed at contact point {k} ({s['points'][k][0]:.6g}, "
                f"{s['points'][k][1]:.6g}): status {int(pi['status'][k])}/{int(pj['status'][k])}"
            )
        zero = np.zeros_like(s["points"])
        gaps = df.compute_gaps(pi["points"], pj["points"], zero, zero, s["normals"], s["tangents"])
        run.data.update(s=s, pi=pi, pj=pj, g_n0=gaps["g_n0"])

        # the check: against the parabola and the exact gap (rank 0)
        if run.rank0:
            evaluate(run)
        run.finish(SUMMARY, files=files)  # no solver: no tractions
    return run.status


if __name__ == "__main__":
    cli.exit_process(main())
