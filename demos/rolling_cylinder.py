#!/usr/bin/python3
"""A cylinder rolling down an incline: implicit Newmark dynamics on the MPM path (seed 003, 6.3).

Physics. An elastic cylinder (R, E, nu, rho; neo-Hookean: it turns by radians) released from
rest on a rigid incline at theta degrees, friction mu, gravity g; the frame has x along the
incline (the floor is y = 0, gravity turned by theta). The cylinder is a level set with material
points carrying F, v and a (mpm/dynamics.py: Newmark, --integrator); it starts touching the floor
with no force on it and a = g at its points (its first steps settle it on the floor).

The check. Rolling without slip when tan(theta) <= 3 mu: x(t) = g t^2 sin(theta) / 3 and the
rotation x / R; else x(t) = g t^2 (sin(theta) - mu cos(theta)) / 2. x(t) against it (the
largest difference over the run, relative to the final travel), the acceleration of a parabola
fitted to x(t), the rotation against x / R (no slip).

Run: /usr/bin/python3 demos/rolling_cylinder.py [--mu 0.1]  (docs/demos/rolling_cylinder.md)
"""

import importlib.util
import sys

import numpy as np

if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
from dolfinx_forms.app import cli
from dolfinx_forms.app.demo import Run
from dolfinx_forms.app.mpm_run import Steps
from dolfinx_forms.fem.laws import NeoHookean
from dolfinx_forms.mpm.dynamics import PointNewmark
from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
from dolfinx_forms.solvers.dynamics import INTEGRATORS
from meshes.mpm import cylinder_on_floor

# fmt: off
OPTIONS = [  # option, kind, default[, help]
    ("--R", "(0, 1e6]", 1.0, "cylinder radius (m)"),
    ("--E", "[1e-3, 1e9]", 1e4, "Young's modulus (Pa)"),
    ("--nu", "(-1, 0.5)", 0.3),
    ("--rho", "(0, inf)", 1.0, "density (kg/m^3)"),
    ("--theta", "(0, 60]", 30.0, "incline (degrees)"),
    ("--mu", "[0, inf)", 0.5, "friction coefficient"),
    ("--g", "(0, inf)", 1.0, "gravity (m/s^2)"),
    ("--dt", "(0, inf)", 0.05, "time step (s)"),
    ("--t-end", "(0, inf)", 2.0, "end time (s); at most 10000 steps"),
    ("--h", "(0, inf)", 0.1, "grid spacing (m); R / h in [4, 100]"),
    ("--integrator", list(INTEGRATORS), "trapezoidal", "Newmark parameters"),
    ("--eps0", cli.MPM_EPS0_INTERVAL, 1.0, cli.MPM_EPS0_HELP),
    ("--series-every", range(1, 10001), 10, "steps between frames of the time series"),
]
COLUMNS = ["t", "x_center", "y_center", "rotation", "kinetic_energy", "potential_energy",
           "contact_force_n", "contact_force_t"]
TOLERANCE = 0.03  # fitted acceleration and rotation against the reference
# fmt: on


def parse(argv):
    p = cli.demo_parser("rolling_cylinder.py", __doc__, "results/rolling_cylinder", OPTIONS,
                        discretization=False, multi_step=True)  # fmt: skip
    a = p.parse_args(argv)
    if not 4 <= a.R / a.h <= 100:
        p.error(f"--h: R / h must be in [4, 100], got {a.R / a.h:g}")
    if not 4 <= a.t_end / a.dt <= 10000:
        p.error(f"--dt: t-end / dt must be in [4, 10000], got {a.t_end / a.dt:g}")
    if 0.5 * a.g * a.t_end**2 * np.sin(np.radians(a.theta)) > 1000 * a.R:
        p.error("--t-end: the cylinder would travel more than 1000 R (the grid's length)")
    return a


def reference(p, t):
    """(x(t), rolling) of a rigid cylinder released from rest (module docstring)."""
    th = np.radians(p["theta"])
    if np.tan(th) <= 3 * p["mu"]:
        return p["g"] * t**2 * np.sin(th) / 3, True
    return p["g"] * t**2 * (np.sin(th) - p["mu"] * np.cos(th)) / 2, False


def evaluate(run):
    p, rows = run.params, run.rows
    t, x, rot = (np.array([r[k] for r in rows]) for k in ("t", "x_center", "rotation"))
    x_ref, rolling = reference(p, t)
    a_fit = 2 * np.polyfit(t, x, 2)[0]
    a_ref = 2 * x_ref[-1] / t[-1] ** 2
    run.results.update(
        rolling=bool(rolling), acceleration=float(a_fit),
        acceleration_rel_error=float(a_fit / a_ref - 1), x_end=float(x[-1]),
        x_rel_error_max=float(np.max(np.abs(x - x_ref)) / x_ref[-1]),
        rotation_vs_x=float(rot[-1] * p["R"] / x[-1] - 1) if rolling else None,
    )  # fmt: skip
    run.analytic.update(acceleration=float(a_ref), x_end=float(x_ref[-1]))
    warn = run.metrics["solver"]["warnings"]
    if (ex := run.results["x_rel_error_max"]) > TOLERANCE:
        warn.append(f"x(t) differs from the rigid cylinder's by {ex:.1%} of the travel")
    if abs(a_fit / a_ref - 1) > TOLERANCE:
        warn.append(f"acceleration {a_fit:.5g} differs from {a_ref:.5g} by {a_fit / a_ref - 1:.1%}")
    if rolling and abs(rot[-1] * p["R"] / x[-1] - 1) > TOLERANCE:
        warn.append(f"rotation R differs from x by {rot[-1] * p['R'] / x[-1] - 1:.1%} (no slip)")


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    with Run("rolling_cylinder", vars(args), discretization="cut", plot=False) as run:
        # the scene: the cylinder on the floor; gravity turned by theta
        th, n = np.radians(args.theta), int(round(args.t_end / args.dt))
        travel = 0.5 * args.g * args.t_end**2 * np.sin(th) + 2 * args.h
        grid, (name, tag, shape), floor, scene = cylinder_on_floor(run.comm, args.R, args.h, travel)
        gravity = args.g * np.array([np.sin(th), -np.cos(th)])
        dyn = PointNewmark({tag: args.rho}, args.dt, args.integrator, gravity=gravity)
        body = MPMBody(name, tag, NeoHookean(args.E, args.nu), shape)
        sim = ImplicitMPM(run.comm, grid, [body], scene, obstacles=[floor], dynamics=dyn,
                          timer=run.timer, **run.problem_options)  # fmt: skip

        # the run: n time steps from rest
        steps = Steps(run, sim, COLUMNS, n, args.series_every)
        mass, c0 = None, np.array([0.0, args.R])
        for _ in range(n):
            rec = steps.step()
            p = sim.points[tag]
            mass = args.rho * p.vol0.sum()
            c = np.average(p.x, axis=0, weights=p.vol0)
            F = p.F  # the rotation of each point's polar decomposition, mass-averaged
            angle = np.arctan2(F[:, 1, 0] - F[:, 0, 1], F[:, 0, 0] + F[:, 1, 1])
            steps.rows.append(dict(t=rec["time"], x_center=c[0] - c0[0], y_center=c[1] - c0[1],
                                   rotation=-float(np.average(angle, weights=p.vol0)),
                                   kinetic_energy=rec["kinetic_energy"][name],
                                   potential_energy=-mass * float(gravity @ (c - c0)),
                                   contact_force_n=-rec["obstacles"]["floor"]["fy"],
                                   contact_force_t=-rec["obstacles"]["floor"]["fx"]))  # fmt: skip
        steps.measure()

        # the check (rank 0): acceleration, rotation, position against the rigid cylinder's
        if run.rank0:
            evaluate(run)
        summary = ("Rolling cylinder: x(t-end) = {results[x_end]:.5g} (rigid {analytic[x_end]:.5g}"
                   ", largest difference {results[x_rel_error_max]:.2%} of it), fitted "
                   "acceleration {results[acceleration_rel_error]:+.2%} of the rigid one")
        run.finish(summary, **steps.outputs())
    return run.status


if __name__ == "__main__":
    cli.exit_process(main())
