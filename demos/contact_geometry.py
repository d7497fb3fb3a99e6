"""Contact geometry of the Hertz set-up: the intermediate surface between a cylinder and a block.

Physics and check first
-----------------------
A cylinder of radius R sits at a gap g above a block (both level sets on one structured
grid of spacing h). The unbiased contact surface Gamma_c is the zero contour of
phi_int = (phi_block - phi_cyl)/2 (eq 23) inside the contact region (eq 22). For a flat
face and a circle that curve is the parabola y = (x^2 + 2Rg + g^2) / (2(2R + g)), and at
a point of it at distance d from both bodies the initial normal gap (eq 28) is
g_n0 = d |n_block - n_cyl|. The demo builds Gamma_c, projects its quadrature points onto
both bodies (eq 25), and reports the errors of position and gap against these formulas.

Run: /usr/bin/python3 demos/contact_geometry.py [--R 10 --gap 0.02 --h 0.05 --out DIR]
"""

import csv
import sys
from pathlib import Path

import numpy as np

import dolfinx_forms as df
from dolfinx_forms.cli import DemoParser, bounded
from dolfinx_forms.results import (PhaseTimer, atomic_output_dir, new_metrics,
                                   write_metrics)


def parse(argv=None):
    p = DemoParser(description=__doc__.split("\n")[0])
    p.add_out("results/contact_geometry")
    p.add_argument("--R", type=bounded("R", 0, lo_open=True), default=10.0, help="radius (mm)")
    p.add_argument("--gap", type=bounded("gap", 0), default=0.02, help="initial gap (mm)")
    p.add_argument("--h", type=bounded("h", 0, lo_open=True), default=0.05,
                   help="grid spacing at the contact (mm)")
    p.add_argument("--eps", type=bounded("eps", 0, lo_open=True), default=None,
                   help="contact-region shift of eq 22 (mm), default 4 h")
    p.add_argument("--width", type=bounded("width", 0, lo_open=True), default=2.0,
                   help="half-width of the grid window around the contact (mm)")
    args = p.parse_args(argv)
    if args.h > args.width / 4:
        p.error(f"argument --h: must be <= width/4 = {args.width / 4}, got {args.h}")
    if args.width > args.R:
        p.error(f"argument --width: must be <= R = {args.R}, got {args.width}")
    if args.eps is None:
        args.eps = 4 * args.h
    return args


def main(argv=None):
    args = parse(argv)
    R, g, h = args.R, args.gap, args.h
    m = new_metrics("contact_geometry", "cut", vars(args))
    timer = PhaseTimer(m)

    with timer.phase("mesh"):
        n = int(np.ceil(2 * args.width / h))
        grid = df.StructuredGrid.uniform([-args.width, -args.width / 2],
                                         [args.width, args.width / 2], [n, n // 2])
        centre = np.array([0.0, R + g])
        block = df.levelset_from_shape(grid, df.Box([-4 * R, -4 * R], [4 * R, 0.0]))
        cyl = df.levelset_from_shape(grid, df.Circle(centre, R))
    with timer.phase("contact"):
        s = df.contact_surface(block, cyl, eps=args.eps)
        pi = df.closest_point_projection(block, s["points"])
        pj = df.closest_point_projection(cyl, s["points"])
    if not (pi["converged"].all() and pj["converged"].all()):
        bad = np.flatnonzero(~(pi["converged"] & pj["converged"]))[0]
        sys.exit(f"closest-point projection failed at contact point {bad} "
                 f"({s['points'][bad][0]:.6g}, {s['points'][bad][1]:.6g}): status "
                 f"{int(pi['status'][bad])}/{int(pj['status'][bad])}")
    zero = np.zeros_like(s["points"])
    gaps = df.compute_gaps(pi["points"], pj["points"], zero, zero, s["normals"], s["tangents"])
    timer.stop()

    # Independent references from the outputs themselves
    x = s["points"]
    parabola = (x[:, 0] ** 2 + 2 * R * g + g**2) / (2 * (2 * R + g))
    d = x[:, 1]  # distance to the flat face
    n_cyl = (x - centre) / np.linalg.norm(x - centre, axis=1)[:, None]
    gap_exact = d * np.linalg.norm(np.array([0.0, 1.0]) - n_cyl, axis=1)
    m["mesh"].update(h_contact=h, num_cells=grid.num_cells, num_dofs=None)
    m["results"].update(
        num_contact_points=int(len(x)),
        surface_length=float(s["weights"].sum()),
        position_max_error=float(np.abs(x[:, 1] - parabola).max()),
        gap_max_error=float(np.abs(gaps["g_n0"] - gap_exact).max()),
        projection_max_iterations=int(max(pi["iterations"].max(), pj["iterations"].max())))
    m["analytic"].update(min_gap=g)

    with atomic_output_dir(args.out, force=args.force) as tmp:
        write_metrics(tmp, m)
        with open(tmp / "contact_points.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["x", "y", "nx", "ny", "weight", "pi_x", "pi_y", "pj_x", "pj_y", "g_n0"])
            w.writerows(np.c_[x, s["normals"], s["weights"], pi["points"], pj["points"],
                              gaps["g_n0"]].tolist())
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(1, 2, figsize=(10, 4))
        X = grid.nodes().reshape(grid.shape + (2,))
        ax[0].contour(X[..., 0], X[..., 1], block.values, [0], colors="k")
        ax[0].contour(X[..., 0], X[..., 1], cyl.values, [0], colors="b")
        for seg in s["segments"]:
            ax[0].plot(seg[:, 0], seg[:, 1], "g-")
        ax[0].set_aspect("equal")
        ax[0].set_title("bodies (black, blue) and $\\Gamma_c$ (green)")
        ax[1].plot(x[:, 0], gaps["g_n0"], "g.", label="computed $g_{n0}$")
        order = np.argsort(x[:, 0])
        ax[1].plot(x[order, 0], gap_exact[order], "k-", lw=0.8, label="exact")
        ax[1].set_xlabel("x (mm)")
        ax[1].set_ylabel("initial normal gap $g_{n0}$ (mm), eq 28")
        ax[1].legend()
        fig.tight_layout()
        fig.savefig(tmp / "contact_geometry.png", dpi=120)
        plt.close(fig)

    r = m["results"]
    print(f"contact geometry: h = {h} mm, {r['num_contact_points']} contact points, "
          f"position error {r['position_max_error']:.2e} mm, gap error {r['gap_max_error']:.2e} mm, "
          f"{m['timing_s']['total']:.3f} s")
    print(f"results in {Path(args.out).resolve()}")


if __name__ == "__main__":
    main()
