#!/usr/bin/python3
"""A cantilever under a suddenly applied body force: implicit Newmark dynamics (seed 003, 6.1).

Physics. A plane-strain beam (length x height, E, nu, rho) clamped at x = 0, at rest, loaded at
t = 0 by the body force rho g (downwards) and left to vibrate. Body-fitted structured quads of
size h, degree 2 (Q2: no shear locking in bending); Newmark time steps dt to t-end,
--integrator trapezoidal (beta 1/4, gamma 1/2: no numerical damping) or dissipative (gamma 0.6).

The check. The first period against Euler-Bernoulli's, T1 = 2 pi / (1.8751^2 sqrt(E' I /
(rho A L^4))), E' = E / (1 - nu^2) (plane strain), no shear correction (L / h = 20: Timoshenko's
lowers omega by < 0.5 %; measured agreement 1e-4 at dt = T1 / 38); the peak tip deflection
against twice the static one, q L^4 / (8 E' I) with q = rho g height; the energy balance
E_kin + E_strain - W_gravity = 0 (exact for the trapezoidal rule).

Run: /usr/bin/python3 demos/cantilever.py [--dt 0.05] [--t-end 4]  (docs/demos/cantilever.md)
"""

import importlib.util
import sys

import numpy as np

if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
import ufl
from dolfinx import fem

from dolfinx_forms.app import cli
from dolfinx_forms.app.demo import Run
from dolfinx_forms.fem.boundary import BodyForce, Dirichlet
from dolfinx_forms.fem.laws import LinearElastic
from dolfinx_forms.io.output import write_table
from dolfinx_forms.solvers.dynamics import INTEGRATORS, Newmark
from dolfinx_forms.solvers.options import options
from dolfinx_forms.solvers.problem import ContactProblem
from meshes.beam import cantilever_scene

# fmt: off
OPTIONS = [  # option, kind, default[, help]
    ("--length", "(0, 1e6]", 16.0, "beam length (m)"),
    ("--height", "(0, 1e6]", 0.8, "beam height (m); length / height in [4, 200]"),
    ("--E", "(0, inf)", 1e6, "Young's modulus (Pa)"),
    ("--nu", "(-1, 0.5)", 0.3),
    ("--rho", "(0, inf)", 1.0, "density (kg/m^3)"),
    ("--g", "(0, inf)", 0.5, "body force per unit mass (m/s^2), applied at t = 0"),
    ("--dt", "(0, inf)", 0.05, "time step (s)"),
    ("--t-end", "(0, inf)", 4.0, "end time (s); at most 100000 steps"),
    ("--h", "(0, inf)", 0.2, "cell size (m); height / h in [1, 40]"),
    ("--integrator", list(INTEGRATORS), "trapezoidal", "Newmark parameters"),
]
COLUMNS = ["t", "tip_deflection", "kinetic_energy", "strain_energy"]
# fmt: on


def parse(argv):
    p = cli.demo_parser("cantilever.py", __doc__, "results/cantilever", OPTIONS,
                        discretization=False, petsc=False)  # fmt: skip
    a = p.parse_args(argv)
    if not 4 <= a.length / a.height <= 200:
        p.error(f"--height: length / height must be in [4, 200], got {a.length / a.height:g}")
    if not 1 <= a.height / a.h <= 40 or a.length / a.h > 4000:
        p.error(f"--h: height / h must be in [1, 40] (and length / h <= 4000), got {a.h}")
    if not 1 <= a.t_end / a.dt <= 100000:
        p.error(f"--dt: t-end / dt must be in [1, 100000], got {a.t_end / a.dt:g}")
    return a


def reference(p):
    """(T1, static tip deflection) of Euler-Bernoulli with the plane-strain modulus."""
    Ep, I, A = p["E"] / (1 - p["nu"] ** 2), p["height"] ** 3 / 12, p["height"]
    omega = 1.875104**2 * np.sqrt(Ep * I / (p["rho"] * A * p["length"] ** 4))
    return 2 * np.pi / omega, p["rho"] * p["g"] * A * p["length"] ** 4 / (8 * Ep * I)


def evaluate(run, balance):
    """First period (crossings of the mid level), peak against 2 x static, energy balance."""
    p, rows = run.params, run.rows
    t, w = (np.array([r[k] for r in rows]) for k in ("t", "tip_deflection"))
    T1, static = reference(p)
    mid = 0.5 * w.min()  # the static position is about half the first trough
    cross = np.flatnonzero(np.sign(w[1:] - mid) != np.sign(w[:-1] - mid))
    tc = t[cross] + (t[cross + 1] - t[cross]) * (mid - w[cross]) / (w[cross + 1] - w[cross])
    period = float(tc[2] - tc[0]) if len(tc) >= 3 else None
    run.results.update(
        first_period=period, period_rel_error=None if period is None else period / T1 - 1,
        peak_deflection=float(-w.min()), peak_over_static=float(-w.min() / static),
        energy_balance_rel_max=float(balance), steps=len(rows),
    )  # fmt: skip
    run.analytic.update(first_period=T1, static_deflection=static)
    warn = run.metrics["solver"]["warnings"]
    if period is None:
        warn.append("t-end holds less than one period: no period check")
    elif abs(period / T1 - 1) > 0.02:
        warn.append(f"first period differs from Euler-Bernoulli's by {period / T1 - 1:.2%}")
    if period is not None and abs(-w.min() / static / 2 - 1) > 0.05:
        warn.append(f"peak deflection {-w.min() / static:.3f} x static (2 expected, > 5 % off)")
    if p["integrator"] == "trapezoidal" and balance > 1e-6:
        warn.append(f"energy not conserved: {balance:.1e} of the work (trapezoidal rule)")


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    with Run("cantilever", vars(args), discretization="fitted", plot=False) as run:
        # the scene: the beam clamped at x = 0, Q2
        with run.phase("mesh"):
            run.scene = scene = cantilever_scene(run.comm, args.length, args.height, args.h)
        law = LinearElastic(args.E, args.nu)
        nm = Newmark({1: args.rho}, args.dt, args.integrator)
        gravity = BodyForce(ufl.as_vector([0.0, -args.rho * args.g]), scale=lambda lam: 1.0)
        problem = ContactProblem(scene, nm.laws({1: law}), dirichlet=[Dirichlet("clamp", None)],
                                 loads=[gravity, nm.loads()[0]], timer=run.timer,
                                 log=lambda *a, **k: None, **options(degree=2))  # fmt: skip
        run.problem, u = problem, problem.u
        dx = problem.bulk.measure(1)
        strain = fem.form(0.5 * ufl.inner(law.stress(u), ufl.grad(u)) * dx)
        work = fem.form(ufl.inner(ufl.as_vector([0.0, -args.rho * args.g]), u) * dx)
        X = problem.V.tabulate_dof_coordinates()[: problem.n_owned // 2, :2]
        near = np.linalg.norm(X - [args.length, 0.5 * args.height], axis=1)
        tip = int(np.argmin(near)) if len(near) else -1
        mine = (near[tip] if len(near) else np.inf, run.comm.rank)
        owner = min(run.comm.allgather(mine))[1]

        # the run: Newmark steps from rest, a_0 = M^-1 f (the load applied at t = 0)
        nm.start(problem)
        run.rows, balance, total = [], 0.0, 0.0
        for n in range(int(round(args.t_end / args.dt))):
            nm.step(problem)
            w = u.x.array.reshape(-1, 2)[tip, 1] if run.comm.rank == owner else 0.0
            Es, W = (run.comm.allreduce(fem.assemble_scalar(f)) for f in (strain, work))
            Ek = nm.kinetic_energy(problem)
            balance, total = max(balance, abs(Ek + Es - W)), max(total, abs(W))
            run.rows.append(dict(t=nm.time, tip_deflection=run.comm.allreduce(w),
                                 kinetic_energy=Ek, strain_energy=Es))  # fmt: skip
        run.measure()

        # the check (rank 0): period, peak, energy
        if run.rank0:
            evaluate(run, balance / max(total, 1e-300))

        T = "{results[first_period]:.5g} s" if run.results.get("first_period") else "none"
        summary = ("Cantilever: first period within t-end " + T + " (Euler-Bernoulli "
                   "{analytic[first_period]:.5g} s), peak / static {results[peak_over_static]:.4f}"
                   ", energy balance {results[energy_balance_rel_max]:.1e}")  # fmt: skip
        files = lambda run, folder: write_table(folder / "steps.csv", COLUMNS, run.rows)  # noqa
        run.finish(summary, plot=None, files=files, solution=False, tractions=False)
    return run.status


if __name__ == "__main__":
    cli.exit_process(main())
