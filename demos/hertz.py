#!/usr/bin/python3
"""Hertz line contact, and Cattaneo-Mindlin partial slip, on body-fitted meshes.

Physics. A half-cylinder of radius R (flat face on top) is pressed by a line load P (N/mm)
onto a block of the same material (plane strain). Hertz: E* = E / (2 (1 - nu^2)),
a = sqrt(4 P R / (pi E*)), p0 = 2 P / (pi a), p(x) = p0 sqrt(1 - x^2/a^2).
With --mu > 0 and --tangential r > 0 a second stage follows: after the normal load
(applied frictionless, so no tangential traction is locked in), friction is switched on and the
cylinder top is moved sideways until the tangential force reaches Q = r mu P (monotonically).
Cattaneo-Mindlin: a central stick zone of half-width c = a sqrt(1 - Q/(mu P)).

The check. metrics.json holds a, p0 and the relative L2 error of p(x) against Hertz *at the
computed load* (the reaction), the stick half-width against c at the computed Q, the Newton
residual history and the phase timings. The block (default 40 x 20 mm for a ~ 1 mm) is
clamped at its bottom; the cylinder top is moved rigidly (down, then sideways), so the
cylinder can neither roll nor slide freely; the approach is iterated until the reaction equals
the requested load P (0.1 %).

Method: level sets of both bodies on a fine structured grid over the pair's search box, the
intermediate contact surface (eqs 21-24), closest points (eq 25), penalty + Coulomb return
mapping with its consistent tangent (Algorithm 1, eq 48), Newton with load steps.
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
from dolfinx_forms.solver import (ContactProblem, ContactSolverError, Dirichlet,
                                  NewtonOptions, solver_metrics, zone_ends)
from meshes.cut import hertz_cut_scene
from meshes.hertz import hertz_scene

DEFAULTS = dict(R=10.0, E=1.0e4, nu=0.3, load=430.0)


def parse(argv):
    p = DemoParser(prog="hertz.py", description=__doc__.split("\n\n")[0])
    p.add_out("results/hertz")
    add_discretization(p)
    p.add_argument("--h", type=bounded("--h", 0, None, lo_open=True), default=None,
                   help="mesh size at the contact (default a/20 of the Hertz estimate)")
    p.add_argument("--R", type=bounded("--R", 0, None, lo_open=True), default=DEFAULTS["R"])
    p.add_argument("--E", type=bounded("--E", 0, None, lo_open=True), default=DEFAULTS["E"])
    p.add_argument("--nu", type=bounded("--nu", -1, 0.5, lo_open=True, hi_open=True),
                   default=DEFAULTS["nu"])
    p.add_argument("--load", type=bounded("--load", 0, None, lo_open=True),
                   default=DEFAULTS["load"], help="line load P (N/mm)")
    p.add_argument("--mu", type=bounded("--mu", 0, None), default=0.0)
    p.add_argument("--tangential", type=bounded("--tangential", 0, 1, hi_open=True), default=0.0,
                   help="Q/(mu P) of the Cattaneo-Mindlin stage (0: none; needs --mu > 0)")
    p.add_argument("--band", type=bounded("--band", 0, None, lo_open=True), default=None,
                   help="largest initial gap covered by the contact surface "
                        "(default: the gap at x = 1.6 a)")
    p.add_argument("--width", type=bounded("--width", 0, None, lo_open=True), default=None,
                   help="block width (default max(40, 40 a))")
    p.add_argument("--depth", type=bounded("--depth", 0, None, lo_open=True), default=None,
                   help="block depth (default max(20, 20 a))")
    p.add_argument("--eps0", type=bounded("--eps0", 0, None, lo_open=True), default=0.5,
                   help="penalty factor of eq 51: eps = eps0 h / E")
    p.add_argument("--degree", type=int, choices=[1, 2], default=1)
    p.add_argument("--grid-refine", type=int, choices=range(1, 17), metavar="[1..16]", default=4,
                   help="level-set grid cells per contact mesh size h")
    p.add_argument("--gauss", type=int, choices=range(1, 6), metavar="[1..5]", default=2,
                   help="Gauss points per contact-surface segment")
    p.add_argument("--quads", action="store_true", help="quadrilateral cells")
    p.add_argument("--steps", type=int, choices=range(1, 101), metavar="[1..100]", default=1,
                   help="load steps of the first normal approach")
    p.add_argument("--tangential-steps", type=int, choices=range(2, 101), metavar="[2..100]",
                   default=12, help="maximum displacement steps of the tangential stage")
    p.add_argument("--petsc", action="append", default=[], metavar="KEY=VALUE",
                   help="PETSc option for the linear solver (prefix ils_), repeatable")
    a = p.parse_args(argv)
    check_discretization(p, a)
    if a.tangential > 0 and a.mu == 0:
        p.error("--tangential: a Cattaneo-Mindlin stage needs --mu > 0")
    a.petsc = petsc_options(p, a.petsc)
    return a


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    comm = MPI.COMM_WORLD
    E_star = analytic.effective_modulus(args.E, args.nu, args.E, args.nu)
    a_est, _ = analytic.hertz_line(args.load, args.R, E_star)
    h = args.h if args.h is not None else a_est / 20
    width = args.width or max(40.0, 40 * a_est)
    depth = args.depth or max(20.0, 20 * a_est)
    params = dict(vars(args), h=h, width=width, depth=depth,
                  protocol="rigid approach of the cylinder top, frictionless, iterated to the load P; "
                           "then friction on and monotonic tangential displacement of the top")
    metrics = new_metrics("hertz" if args.tangential == 0 else "mindlin", args.discretization,
                          params)
    timer = PhaseTimer(metrics)

    with timer.phase("mesh"):
        zone = 1.6 * a_est
        if args.discretization == "cut":  # graded grid, spacing h on the zone; cylinder cut
            scene = hertz_cut_scene(comm, R=args.R, width=width, depth=depth, h=h, zone=zone)
        else:
            scene = hertz_scene(comm, R=args.R, width=width, depth=depth, h=h, zone=zone,
                                quads=args.quads)
    mat = {b.tag: (args.E, args.nu) for b in scene.bodies}
    top_x = Dirichlet("cylinder_top", 0, 0.0)
    top_y = Dirichlet("cylinder_top", 1, 0.0)
    problem = ContactProblem(
        scene, mat, mu=0.0, eps0=args.eps0, band=args.band or zone**2 / (2 * args.R), degree=args.degree,
        dirichlet=[Dirichlet("block_bottom", None, 0.0), top_x, top_y],
        petsc_options=args.petsc, timer=timer, newton=NewtonOptions(),
        grid_refine=args.grid_refine, num_gauss=args.gauss, ghost_penalty=args.ghost_penalty)
    try:
        normal_stage(problem, top_y, args.load, a_est**2 / args.R, args.steps)
        Q = 0.0
        if args.tangential > 0:
            Q = tangential_stage(problem, top_x, args.mu, args.tangential * args.mu * args.load,
                                 args.tangential_steps)
    except ContactSolverError as e:
        sys.stderr.write(f"hertz.py: {e}\n")
        return 1

    reaction = problem.reaction("block_bottom")
    pts = gather_points(problem)
    metrics["mesh"].update(h_contact=h, num_cells=scene.mesh.topology.index_map(2).size_global,
                           num_dofs=problem.num_dofs)
    metrics["solver"] = solver_metrics(problem)
    if comm.rank == 0:
        evaluate(metrics, pts, reaction, args, E_star, Q)
    timer.stop()
    with atomic_output(args.out, comm, force=args.force) as folder:
        finish(folder, metrics, problem, pts,
               plot=(lambda path: plot(path, pts, metrics, args)) if comm.rank == 0 else None)
    if comm.rank == 0:
        r = metrics["results"]
        print(f"hertz: P = {reaction[1]:.6g} N/mm, a = {r['contact_half_width']:.5g} "
              f"(Hertz {metrics['analytic']['contact_half_width']:.5g}), p0 = "
              f"{r['peak_pressure']:.5g} (Hertz {metrics['analytic']['peak_pressure']:.5g}), "
              f"p(x) L2 error {r['pressure_rel_l2_error']:.3%}")
        print(f"results in {Path(args.out).resolve()}")
    return 0


def move_top(problem, bc, target, steps=1, label="step"):
    """Ramp a Dirichlet value of the top from its current value to `target`."""
    start = bc.at(1.0)
    bc.value = lambda lam: start + lam * (target - start)
    problem.lam = 0.0  # each move is a stage lam: 0 -> 1 (cut-back safe)
    problem.solve(steps, label=label)


def normal_stage(problem, top_y, P, delta0, steps):
    """Press the cylinder top down (held horizontally, so it can neither roll nor slide) until
    the reaction reaches the line load P within 0.1 %. Frictionless, hence path independent:
    secant iterations on the approach delta, each solve starting from the last one."""
    history = [(0.0, 0.0)]
    delta = delta0
    for k in range(12):
        move_top(problem, top_y, -delta, steps if k == 0 else 1, label=f"normal delta={delta:.5g}")
        load = problem.reaction("block_bottom")[1]
        history.append((delta, load))
        if abs(load - P) <= 1e-3 * P:
            return load
        (d0, p0), (d1, p1) = history[-2], history[-1]
        delta = d1 + (P - p1) * (d1 - d0) / (p1 - p0)
    raise ContactSolverError(f"normal stage: load {load:.6g} did not reach {P:.6g} in 12 secant steps")


def tangential_stage(problem, top_x, mu, Q_target, max_steps):
    """Move the cylinder top sideways until the tangential force reaches Q_target, approaching
    it from below with secant steps (Q(delta) is concave: slip softens it), so that the
    loading is monotonic as Cattaneo-Mindlin assumes. Returns the reached Q."""
    problem.set_friction(mu)
    delta, Q = 0.0, 0.0
    history = [(0.0, 0.0)]
    for k in range(max_steps):
        if k == 0:
            step = 1e-3 * problem.scene.h_contact  # probe the initial (full-stick) stiffness
        else:
            (d0, q0), (d1, q1) = history[-2], history[-1]
            step = (Q_target - q1) * (d1 - d0) / (q1 - q0)
        delta += step
        move_top(problem, top_x, delta, label=f"tangential delta={delta:.4g}")
        Q = problem.reaction("cylinder_top")[0]  # the support drives the top by +delta
        history.append((delta, Q))
        if abs(Q - Q_target) <= 2e-3 * Q_target:
            break
    return Q


def evaluate(metrics, pts, reaction, args, E_star, Q):
    """Measured a, p0, p(x) error (and the Mindlin stick zone) against the analytic solution."""
    P = abs(reaction[1])
    a, p0 = analytic.hertz_line(P, args.R, E_star)
    x, p = pts["x"], pts["p_n"]
    active = pts["state"] != 0
    xl, xr = zone_ends(x, active, pts["gap_n"])
    ph = analytic.hertz_pressure(x, a, p0)
    w = pts["w"]
    res = metrics["results"]
    res.update(reaction=[float(reaction[0]), float(reaction[1])], applied_load=args.load,
               contact_half_width=0.5 * (xr - xl), contact_centre=0.5 * (xr + xl),
               peak_pressure=float(p.max()),
               pressure_rel_l2_error=float(np.sqrt(np.sum(w * (p - ph) ** 2) / np.sum(w * ph**2))),
               contact_force=float(np.sum(w * p)))
    metrics["analytic"].update(contact_half_width=float(a), peak_pressure=float(p0))
    if args.tangential > 0:
        c = analytic.mindlin_stick_half_width(a, Q, args.mu, P)
        # Stick zone: active points that never slipped during the tangential stage (a point
        # of the slip zone may be momentarily `stick` in a small last load increment)
        slipped = np.abs(pts["slip"]) > 1e-9 * max(np.abs(pts["slip"]).max(), 1e-300)
        sl, sr = zone_ends(x, active & ~slipped)
        q = np.abs(pts["p_t"])
        qa = analytic.mindlin_shear(x, a, c, p0, args.mu)
        res.update(tangential_force=float(Q), tangential_ratio=float(Q / (args.mu * P)),
                   stick_half_width=None if sl is None else 0.5 * (sr - sl),
                   traction_rel_l2_error=float(np.sqrt(np.sum(w * (q - qa) ** 2) / np.sum(w * qa**2))))
        metrics["analytic"]["stick_half_width"] = float(c)


def plot(path, pts, metrics, args):
    an = metrics["analytic"]
    a, p0 = an["contact_half_width"], an["peak_pressure"]
    xs = np.linspace(-1.5 * a, 1.5 * a, 400)
    curves = {"Hertz p(x)": (xs, analytic.hertz_pressure(xs, a, p0))}
    if args.tangential > 0:
        q = analytic.mindlin_shear(xs, a, an["stick_half_width"], p0, args.mu)
        sign = np.sign(np.sum(pts["p_t"])) or 1.0
        curves["Cattaneo-Mindlin q(x)"] = (xs, sign * q)
    plot_tractions(path, pts, curves, title=f"Hertz, h = {metrics['mesh']['h_contact']:.3g} mm")


if __name__ == "__main__":
    sys.exit(main())
