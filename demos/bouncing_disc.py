#!/usr/bin/python3
"""A damped elastic disc dropped on a rigid floor comes to rest on it (seed 004's bouncing disc).

Physics. A neo-Hookean disc (R, E, nu, rho) held --drop above a rigid floor falls under gravity
g, bounces and, damped by a Kelvin-Voigt viscosity (a viscous stress 2 eta sym grad of the
step's velocity, which rigid motions do not feel), comes to rest on the floor; Coulomb friction
mu. The implicit MPM with inertia (mpm/dynamics.py), --integrator dissipative or trapezoidal,
at --dt with step-size control (a failed step done again at half the step, down to dt / 64:
a stiff penalty, e.g. --eps0 1e-4, needs smaller steps at the impacts).

The check. At rest (the last fifth of the run) the floor carries the disc's weight m g (m: the
points' mass) and the disc no longer moves (kinetic energy against the drop's m g drop); no
loss of contact and no chatter there (every step of the last fifth in contact, the lowest
point's acceleration below g), the penetration (the penalty's, eps0 h / E_c) reported; the
first impact at the free-fall time sqrt(2 drop / g).

Run: /usr/bin/python3 demos/bouncing_disc.py [--viscosity 50] [--integrator dissipative]
"""

import importlib.util
import sys

import numpy as np

if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
from dolfinx_forms import _cpp
from dolfinx_forms.app import cli
from dolfinx_forms.app.demo import Run
from dolfinx_forms.app.mpm_run import Steps
from dolfinx_forms.fem.laws import NeoHookean
from dolfinx_forms.mpm.dynamics import PointNewmark
from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
from dolfinx_forms.solvers.dynamics import INTEGRATORS
from dolfinx_forms.solvers.newton import NewtonOptions
from meshes.mpm import cylinder_on_floor

# fmt: off
OPTIONS = [  # option, kind, default[, help]
    ("--R", "(0, 1e6]", 1.0, "disc radius (m)"),
    ("--E", "[1e-3, 1e9]", 1e4, "Young's modulus (Pa)"),
    ("--nu", "(-1, 0.5)", 0.3),
    ("--rho", "(0, inf)", 1.0, "density (kg/m^3)"),
    ("--g", "(0, inf)", 1.0, "gravity (m/s^2)"),
    ("--drop", "(0, inf)", 0.1, "initial gap between the disc and the floor (m); <= R"),
    ("--viscosity", "[0, inf)", 50.0, "Kelvin-Voigt viscosity eta (Pa s)"),
    ("--mu", "[0, inf)", 0.3, "friction coefficient"),
    ("--dt", "(0, inf)", 0.01, "time step (s; the largest: halved on failure)"),
    ("--t-end", "(0, inf)", 4.0, "end time (s); at most 10000 steps"),
    ("--h", "(0, inf)", 0.1, "grid spacing (m); R / h in [4, 100]"),
    ("--integrator", list(INTEGRATORS), "dissipative", "Newmark parameters (trapezoidal: the "
     "lowest point's acceleration rings at rest)"),
    ("--eps0", cli.MPM_EPS0_INTERVAL, 1.0, cli.MPM_EPS0_HELP),
    ("--series-every", range(1, 10001), 50, "steps between frames of the time series"),
]
COLUMNS = ["t", "gap", "velocity", "acceleration", "contact_force", "kinetic_energy", "dt",
           "retries"]
# fmt: on


def parse(argv):
    p = cli.demo_parser("bouncing_disc.py", __doc__, "results/bouncing_disc", OPTIONS,
                        discretization=False, multi_step=True)  # fmt: skip
    a = p.parse_args(argv)
    if not 4 <= a.R / a.h <= 100:
        p.error(f"--h: R / h must be in [4, 100], got {a.R / a.h:g}")
    if not a.drop <= a.R:
        p.error(f"--drop: must be in (0, R] = (0, {a.R:g}], got {a.drop}")
    if not 10 <= a.t_end / a.dt <= 10000:
        p.error(f"--dt: t-end / dt must be in [10, 10000], got {a.t_end / a.dt:g}")
    return a


def evaluate(run, weight):
    p, rows = run.params, run.rows
    t, N, Ek, a, g = (np.array([r[k] for r in rows])
                      for k in ("t", "contact_force", "kinetic_energy", "acceleration", "gap"))
    rest = t >= 0.8 * t[-1]
    touched = np.flatnonzero(N > 0)
    run.results.update(
        first_impact=float(t[touched[0]]) if len(touched) else None,
        force_over_weight_rest=[float(N[rest].min() / weight), float(N[rest].max() / weight)],
        gap_rest_over_R=[float(g[rest].min() / p["R"]), float(g[rest].max() / p["R"])],
        kinetic_energy_rest=float(Ek[rest].max() / (weight * p["drop"])),
        contact_lost_at_rest=int(np.sum(N[rest] <= 0)), weight=float(weight),
        acceleration_rest_over_g=float(np.abs(a[rest]).max() / p["g"]),
    )  # fmt: skip
    run.analytic.update(first_impact=float(np.sqrt(2 * p["drop"] / p["g"])), weight=weight)
    warn, r = run.metrics["solver"]["warnings"], run.results
    if r["contact_lost_at_rest"]:
        warn.append(f"contact lost in {r['contact_lost_at_rest']} steps of the last fifth")
    if max(abs(v - 1) for v in r["force_over_weight_rest"]) > 0.02:
        warn.append(f"floor force at rest {r['force_over_weight_rest']} x the weight (> 2 % off)")
    if r["acceleration_rest_over_g"] > 1:
        warn.append(f"chatter: the lowest point's acceleration at rest reaches "
                    f"{r['acceleration_rest_over_g']:.3g} g")  # fmt: skip
    if r["kinetic_energy_rest"] > 1e-3:
        warn.append(f"not at rest: kinetic energy {r['kinetic_energy_rest']:.1e} of m g drop")


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    with Run("bouncing_disc", vars(args), discretization="cut", plot=False) as run:
        # the scene: the disc `drop` above the floor y < 0
        (xl, yl), (name, tag, shape), floor, scene = cylinder_on_floor(
            run.comm, args.R, args.h, 0.0, args.drop, "disc")  # fmt: skip
        body = MPMBody(name, tag, NeoHookean(args.E, args.nu), shape)
        dyn = PointNewmark({1: args.rho}, args.dt, args.integrator, gravity=(0.0, -args.g),
                           viscosity=args.viscosity)  # fmt: skip
        # no load-level cut-back inside a step (it ramps no load here): a failed step halves dt
        sim = ImplicitMPM(run.comm, (xl, yl), [body], scene, obstacles=[floor], dynamics=dyn,
                          newton=NewtonOptions(max_cutbacks=0), timer=run.timer,
                          **run.problem_options)  # fmt: skip

        # the run: from rest, gap `drop`
        steps = Steps(run, sim, COLUMNS, int(round(args.t_end / args.dt)), args.series_every)
        advance = dyn.advance(sim, args.t_end)
        while True:
            try:  # a step that fails down to dt / 64 ends the run with "step k: ..."
                rec = steps.step(lambda: next(advance))
            except StopIteration:
                break
            p = sim.points[1]
            low = int(np.argmin(p.x[:, 1]))  # the lowest material point
            # the gap as the contact sees it: the floor point below the disc's centre projected
            # on its level set's C1 interpolant (not a linear crossing along a grid line)
            c = np.average(p.x, axis=0, weights=p.vol)
            proj = _cpp.closest_point_projection(sim.levelsets[1], np.array([[c[0], 0.0]]))
            gap = proj["points"][0, 1]
            steps.rows.append(dict(t=rec["time"], gap=float(gap), velocity=float(p.v[low, 1]),
                                   acceleration=float(p.a[low, 1]),
                                   contact_force=-rec["obstacles"]["floor"]["fy"],
                                   kinetic_energy=rec["kinetic_energy"]["disc"],
                                   dt=rec["dt"], retries=rec["retries"]))  # fmt: skip
        steps.measure()

        # the check (rank 0): at rest on the floor, carrying the weight
        if run.rank0:
            evaluate(run, args.rho * sim.points[1].vol0.sum() * args.g)
        summary = ("Bouncing disc: first impact at {results[first_impact]} s (free fall "
                   "{analytic[first_impact]:.4g}); at rest: floor force / weight "
                   "{results[force_over_weight_rest]}, kinetic energy "
                   "{results[kinetic_energy_rest]:.1e} of m g drop")  # fmt: skip
        run.finish(summary, **steps.outputs())
    return run.status


if __name__ == "__main__":
    cli.exit_process(main())
