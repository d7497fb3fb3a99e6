#!/usr/bin/python3
"""Frictionless contact patch test: two stacked blocks under uniform compression.

Physics. Blocks [0,1]x[0,0.5] and [0,1]x[0.5,1] (E = 1, nu = 0.3, plane strain), the bottom
held vertically, the top moved down by d = 0.01, one point of each block held horizontally,
sides free. The exact solution is a uniform stress: sigma_yy = -E/(1-nu^2) d/H
= -0.010989011 and a uniform contact pressure of the same size, zero shear.
With the penalty of eq 8 the interface adds a compliance eps_n: the pressure of the penalised
problem is p = E' d / (H + E' eps_n), E' = E/(1-nu^2), which tends to 0.010989011 as eps0 -> 0.

The check. Linear fields are reproduced exactly by the discretisation, so with the interface
on mesh lines the contact pressure must be uniform and equal to the penalised value to
round-off; metrics.json reports the spread, the shear, and both analytic values.
On the cut path (--discretization cut) both blocks are level sets on one uniform grid of
n = 1/h cells over the height and the interface y = --interface (default 0.5 + 0.3 h) cuts a
row of cells: the exact solution is still linear in each body, so the pressure stays uniform to
round-off for any cut height.
"""

import sys
from pathlib import Path

import numpy as np
from mpi4py import MPI

from dolfinx_forms import analytic
from dolfinx_forms.cli import (DemoParser, add_discretization, bounded,
                               check_discretization, petsc_options)
from dolfinx_forms.output import atomic_output, finish, gather_points, plot_tractions
from dolfinx_forms.results import PhaseTimer, new_metrics
from dolfinx_forms.solver import ContactProblem, ContactSolverError, solver_metrics
from meshes.cut import patch_cut_scene
from meshes.patch import patch_dirichlet, patch_scene


def parse(argv):
    p = DemoParser(prog="patch_test.py", description=__doc__.split("\n\n")[0])
    p.add_out("results/patch_test")
    add_discretization(p)
    p.add_argument("--interface", type=bounded("--interface", 0, 1, lo_open=True, hi_open=True),
                   default=None, help="cut path: height of the interface, off the grid lines "
                                      "(default 0.5 + 0.3 h)")
    p.add_argument("--h", type=bounded("--h", 0, 0.5, lo_open=True), default=0.125,
                   help="mesh size (cells of the lower block: 1/h x 0.5/h)")
    p.add_argument("--E", type=bounded("--E", 0, None, lo_open=True), default=1.0)
    p.add_argument("--nu", type=bounded("--nu", -1, 0.5, lo_open=True, hi_open=True), default=0.3)
    p.add_argument("--mu", type=bounded("--mu", 0, None), default=0.0)
    p.add_argument("--displacement", type=bounded("--displacement", 0, 0.1, lo_open=True),
                   default=0.01, help="downward displacement of the top")
    p.add_argument("--eps0", type=bounded("--eps0", 0, None, lo_open=True), default=1.0)
    p.add_argument("--upper-cells", type=int, default=None,
                   help="cells across the upper block (default: as the lower; non-matching otherwise)")
    p.add_argument("--degree", type=int, choices=[1, 2], default=1)
    p.add_argument("--triangles", action="store_true")
    p.add_argument("--petsc", action="append", default=[], metavar="KEY=VALUE")
    a = p.parse_args(argv)
    check_discretization(p, a)
    nx = round(1.0 / a.h)
    if abs(nx * a.h - 1.0) > 1e-12 or nx % 1:
        p.error(f"--h: must be 1/n for an integer n so that the interface lies on mesh lines, got {a.h}")
    if a.upper_cells is not None and not 1 <= a.upper_cells <= 1000:
        p.error("--upper-cells: must be in [1, 1000]")
    if a.discretization == "conforming" and a.interface is not None:
        p.error("--interface: only for --discretization cut (the gmsh blocks meet at 0.5)")
    if a.discretization == "cut":
        if a.interface is None:
            a.interface = 0.5 + 0.3 * a.h
        k = a.interface / a.h
        if abs(k - round(k)) < 1e-9:
            p.error(f"--interface: must not lie on a grid line (multiples of h = {a.h}), "
                    f"got {a.interface}")
        if a.upper_cells is not None:
            p.error("--upper-cells: only for --discretization conforming")
    a.petsc = petsc_options(p, a.petsc)
    return a


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    comm = MPI.COMM_WORLD
    metrics = new_metrics("patch", args.discretization, vars(args))
    timer = PhaseTimer(metrics)
    nx = round(1.0 / args.h)
    with timer.phase("mesh"):
        if args.discretization == "cut":
            scene = patch_cut_scene(comm, n=nx, interface=args.interface)
        else:
            scene = patch_scene(comm, nx=nx, ny=max(1, nx // 2), quads=not args.triangles,
                                nx_upper=args.upper_cells)
    d = args.displacement
    problem = ContactProblem(
        scene, {b.tag: (args.E, args.nu) for b in scene.bodies}, mu=args.mu, eps0=args.eps0,
        band=0.5 * args.h, degree=args.degree, petsc_options=args.petsc, timer=timer,
        ghost_penalty=args.ghost_penalty,
        dirichlet=patch_dirichlet(d))
    try:
        problem.solve(1, label="patch")
    except ContactSolverError as e:
        sys.stderr.write(f"patch_test.py: {e}\n")
        return 1
    reaction = problem.reaction("upper_top")
    pts = gather_points(problem)
    metrics["mesh"].update(h_contact=args.h, num_cells=scene.mesh.topology.index_map(2).size_global,
                           num_dofs=problem.num_dofs)
    metrics["solver"] = solver_metrics(problem)
    Ep = args.E / (1 - args.nu**2)
    exact = analytic.patch_pressure(args.E, args.nu, d / 1.0)
    penalised = Ep * d / (1.0 + Ep * problem.eps_n)
    if comm.rank == 0:
        p, w = pts["p_n"], pts["w"]
        res = metrics["results"]
        res.update(reaction=[float(v) for v in reaction], pressure_mean=float(np.sum(w * p) / np.sum(w)),
                   pressure_max_rel_deviation=float(np.max(np.abs(p - penalised)) / penalised),
                   pressure_rel_error_vs_exact=float(np.max(np.abs(p - exact)) / exact),
                   shear_max=float(np.max(np.abs(pts["p_t"]))),
                   contact_length=float(np.sum(w)),
                   pressure_rel_l2_error=float(np.sqrt(np.sum(w * (p - penalised) ** 2) /
                                                       np.sum(w * penalised**2))))
        metrics["analytic"].update(pressure=exact, pressure_penalised=penalised)
    timer.stop()

    def plot(path):
        xs = np.array([0.0, 1.0])
        plot_tractions(path, pts, {"exact": (xs, [exact] * 2), "penalised": (xs, [penalised] * 2)},
                       title="patch test", xlabel="x", ylabel="traction")

    with atomic_output(args.out, comm, force=args.force) as folder:
        finish(folder, metrics, problem, pts, plot=plot if comm.rank == 0 else None)
    if comm.rank == 0:
        r = metrics["results"]
        print(f"patch test: pressure {r['pressure_mean']:.10f} (penalised exact {penalised:.10f}, "
              f"eps -> 0: {exact:.10f}), max deviation {r['pressure_max_rel_deviation']:.2e}, "
              f"max shear {r['shear_max']:.2e}")
        print(f"results in {Path(args.out).resolve()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
