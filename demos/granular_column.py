#!/usr/bin/python3
"""A random granular sample deposited under gravity, compressed, then sheared (seed 004's test).

Physics. --grains grains, radii uniform in --radius (1 -+ --polydispersity), Fourier outlines
(--elongation, --roughness; both 0: discs), placed without contact by random sequential
addition in a square box of four rigid walls (area fraction 0.35, --seed); --law with --E --nu,
density --rho, Coulomb friction --mu on grains and walls, gravity --g, Kelvin-Voigt damping
eta = --damping R sqrt(rho E) (rigid motions feel none) and, to settle the deposit, Rayleigh's
mass damping --drag (a drag alpha rho v). Implicit dynamics (dissipative Newmark) at --dt, a
failed step done again at half the step. MELODY's protocol (meshes/column.py): deposition for
--t-deposit; the top wall put on the settled sample and moved down by --compression of its
height over --t-compress; biaxial shear at constant area to --shear-strain (eps_yy - eps_xx)
over --t-shear, the lateral walls moving apart and the top wall down.

The check. At the end of deposition the walls carry the grains' weight (2 %). steps.csv:
meshes/column.py's columns (wall forces, stress ratio, coordination, the contact forces' mean
and spread), Newton iterations, retries; contacts.csv, force_chains.png, column.png.
benchmarks/dem_peer.py runs the same sample and protocol with LAMMPS (rigid discs).

Run: /usr/bin/python3 demos/granular_column.py [--grains 100] [--E 1e4]
"""

import importlib.util
import sys

import numpy as np

HUGE_PAGES = True  # a mesh and factorisation per step: restart with huge pages (app/startup.py)
if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
from dolfinx_forms.app import cli
from dolfinx_forms.app.demo import Run
from dolfinx_forms.app.mpm_run import Steps
from dolfinx_forms.fem.laws import NeoHookean
from dolfinx_forms.mpm.dynamics import PointNewmark
from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
from dolfinx_forms.solvers.newton import NewtonOptions
from meshes import column
from meshes.assembly import ColumnWalls, column_scene
from meshes.plots import granular_column_plots

# fmt: off
OPTIONS = [  # option, kind, default[, help]
    ("--grains", range(1, 1001), 100),
    ("--radius", "(0, inf)", 1.0, "mean grain radius"),
    ("--polydispersity", "[0, 0.5]", 0.2, "radii uniform in radius (1 -+ this)"),
    ("--elongation", "[0, 0.5]", 0.0, "Fourier mode 2 (0 with --roughness 0: discs)"),
    ("--roughness", "[0, 0.1]", 0.0, "RMS of the modes k >= 3"),
    ("--seed", range(0, 2**31), 1),
    ("--law", ["linear", "neo-hookean"], "neo-hookean"),
    ("--E", "[1e-3, 1e9]", 1e4, "Young's modulus"),
    ("--nu", "(-1, 0.5)", 0.3),
    ("--rho", "(0, inf)", 1.0, "density"),
    ("--mu", "[0, 10]", 0.3, "friction coefficient (grains and walls)"),
    ("--g", "(0, inf)", 1.0, "gravity"),
    ("--damping", "[0, 100]", 1.0, "eta / (R sqrt(rho E)), eta the Kelvin-Voigt viscosity"),
    ("--drag", "[0, 100]", 1.0, "Rayleigh's mass damping alpha: a drag alpha rho v"),
    ("--t-deposit", "(0, inf)", 25.0, "deposition time"),
    ("--compression", "[0, 0.2]", 0.01, "top wall travel / settled height"),
    ("--t-compress", "(0, inf)", 5.0),
    ("--shear-strain", "[0, 0.5]", 0.1, "eps_yy - eps_xx at the end (log strains)"),
    ("--t-shear", "(0, inf)", 10.0),
    ("--dt", "(0, inf)", 0.1, "time step (the largest; halved on failure down to dt/64)"),
    ("--h", "(0, inf)", 0.2, "grid spacing; radius / h in [3, 50]"),
    ("--eps0", cli.MPM_EPS0_INTERVAL, 1.0, cli.MPM_EPS0_HELP),
    ("--series-every", range(1, 10001), 50, "steps between frames of the time series"),
]
COLUMNS = column.COLUMNS + ["dt", "newton_iterations", "retries", "wall_s"]
NEWTON = NewtonOptions(max_cutbacks=0)  # a failed step: again at half dt (granular_column.md)
# fmt: on


def parse(argv):
    p = cli.demo_parser("granular_column.py", __doc__, "results/granular_column", OPTIONS,
                        discretization=False, multi_step=True,
                        levelset_update="reference-map")  # fmt: skip
    a = p.parse_args(argv)
    if not (3 <= a.radius * (1 - a.polydispersity) / a.h and a.radius / a.h <= 50):
        p.error(f"--h: the smallest radius / h must be >= 3 and radius / h <= 50, got {a.h}")
    if not 3 <= (n := (a.t_deposit + a.t_compress + a.t_shear) / a.dt) <= 20000:
        p.error(f"--dt: the run's time / dt must be in [3, 20000], got {n:g}")
    return a


def evaluate(run, weight, deposited):
    r, warn = run.results, run.metrics["solver"]["warnings"]
    r.update(weight=weight, walls_over_weight_deposited=deposited["vertical"] / weight,
             kinetic_energy_deposited=deposited["kinetic_energy"],
             settled_height=run.data.get("settled"))  # fmt: skip
    r.update({f"end_of_{q['phase']}": {k: q[k] for k in column.COLUMNS[1:]} for q in run.rows})
    r.update(newton_per_step=float(np.mean([q["newton_iterations"] for q in run.rows])),
             retried_steps=int(sum(q["retries"] for q in run.rows)))  # fmt: skip
    if abs(r["walls_over_weight_deposited"] - 1) > 0.02:
        warn.append(f"after deposition the walls carry {r['walls_over_weight_deposited']:.4f} "
                    "of the weight (> 2 % off): not at rest; raise --t-deposit")  # fmt: skip


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    with Run("granular_column", vars(args), discretization="cut", plot=False) as run:
        # the sample and the protocol (shared with the DEM peer, meshes/column.py)
        sample = column.random_sample(args.grains, args.radius, args.polydispersity,
                                      args.elongation, args.roughness, seed=args.seed)  # fmt: skip
        protocol = column.Protocol(sample.box, args.t_deposit, args.t_compress, args.t_shear,
                                   args.compression, args.shear_strain)  # fmt: skip
        grid, grains, plates, scene = column_scene(run.comm, sample, args.h, args.shear_strain)
        # the problem: each grain its law and mass, Coulomb friction everywhere, inertia
        law = NeoHookean(args.E, args.nu) if args.law == "neo-hookean" else (args.E, args.nu)
        bodies = [MPMBody(name, tag, law, s) for name, tag, s in grains]
        eta = args.damping * args.radius * np.sqrt(args.rho * args.E)
        dyn = PointNewmark({b.tag: args.rho for b in bodies}, args.dt, "dissipative", (0, -args.g),
                           viscosity=eta, mass_damping=args.drag)  # fmt: skip
        sim = ImplicitMPM(run.comm, grid, bodies, scene, obstacles=list(plates.values()),
                          predictor_gap=0.5 * args.h, dynamics=dyn, newton=NEWTON,
                          timer=run.timer, **run.problem_options)  # fmt: skip
        walls = ColumnWalls(plates, protocol)

        # the run: the three phases, each to its end time with adaptive steps
        steps = Steps(run, sim, COLUMNS, int(np.ceil(protocol.t_end / args.dt)), args.series_every)
        deposited = {}
        for phase, t_end in zip(column.PHASES, np.cumsum([args.t_deposit, args.t_compress,
                                                          args.t_shear])):  # fmt: skip
            if phase == "compression":  # the top wall put on the settled sample
                run.data.update(settled=walls.settle(sim), deposited=dict(deposited))
            dyn.set_dt(args.dt)
            advance = dyn.advance(sim, t_end, prepare=walls.prepare)
            while True:
                try:  # a failed step (down to dt / 64) ends the run with "step k: ..."
                    rec = steps.step(lambda: next(advance))
                except StopIteration:
                    break
                row = walls.row(rec, sample)
                steps.rows.append(dict(row, **{k: rec[k] for k in COLUMNS[len(row) :]}))
                deposited = dict(vertical=walls.vertical(rec), kinetic_energy=row["kinetic_energy"])
        steps.measure()

        if run.rank0:  # the check: at rest after deposition, the walls carry the weight
            weight = args.rho * args.g * sum(float(p.vol0.sum()) for p in sim.points.values())
            evaluate(run, weight, run.data.get("deposited", deposited))
        summary = ("granular column: {parameters[grains]} grains; after deposition the walls "
                   "carry {results[walls_over_weight_deposited]:.4f} of the weight; "
                   "Newton per step {results[newton_per_step]:.1f}, "
                   "{results[retried_steps]} retried steps")  # fmt: skip
        run.finish(summary, **steps.outputs(granular_column_plots))
    return run.status


if __name__ == "__main__":
    cli.exit_process(main())
