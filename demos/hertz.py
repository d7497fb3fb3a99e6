#!/usr/bin/python3
"""Hertz line contact, and Cattaneo-Mindlin partial slip, on body-fitted meshes or a cut grid.

Physics. A half-cylinder of radius R (flat face on top) is pressed by a line load P (N/mm)
onto a block of the same material (plane strain), clamped at its bottom. Hertz:
E* = E / (2 (1 - nu^2)), a = sqrt(4 P R / (pi E*)), p0 = 2 P / (pi a),
p(x) = p0 sqrt(1 - x^2/a^2). With --mu > 0 and --tangential r > 0 a second stage follows: after
the normal load (applied frictionless, so no tangential traction is locked in), friction is
switched on and the cylinder top is moved sideways until the tangential force reaches
Q = r mu P. Cattaneo-Mindlin: a central stick zone of half-width c = a sqrt(1 - Q/(mu P)).

The check. a, p0 and the L2 error of p(x) against Hertz at the computed load, the stick
half-width against c at the computed Q; also against the circle itself (`_circle`: 0.4 % apart
at a/R = 0.1). Defaults: the fastest accurate settings per path (meshes/hertz.py).
Run: /usr/bin/python3 demos/hertz.py [--discretization cut] [--mu 0.3 --tangential 0.5]
Results and discussion: docs/demos/hertz.md
"""

import importlib.util
import sys

if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
from dolfinx_forms.analysis import analytic, compare
from dolfinx_forms.app import cli
from dolfinx_forms.app.demo import Run
from dolfinx_forms.fem.boundary import Dirichlet
from dolfinx_forms.solvers.protocol import friction_on, reach_force
from meshes.cut import hertz_cut_scene
from meshes.hertz import MESHER_OPTIONS, SIZE_OPTIONS, demo_band, demo_sizes, scene_sizes
from meshes.hertz import hertz_scene, path_defaults

PROTOCOL = (
    "rigid approach of the cylinder top, frictionless, iterated to the load P; "
    "then friction on and monotonic tangential displacement of the top"
)
# fmt: off
OPTIONS = [  # option, kind, default[, help]
    ("--h", "(0, inf)", None, "mesh size at the contact (default a/20 of the Hertz estimate)"),
    ("--R", "(0, inf)", 10.0), ("--E", "(0, inf)", 1.0e4), ("--nu", "(-1, 0.5)", 0.3),
    ("--load", "(0, inf)", 430.0, "line load P (N/mm)"), ("--mu", "[0, inf)", 0.0),
    ("--tangential", "[0, 1)", 0.0,
     "Q/(mu P) of the Cattaneo-Mindlin stage (0: none; needs --mu > 0)"),
    *SIZE_OPTIONS,  # --band, --width, --depth, --zone, --h-far, --grading (meshes/hertz.py)
    ("--eps0", "(0, inf)", 0.5, "penalty factor of eq 51: eps = eps0 h / E"),
    ("--degree", [1, 2], 1),
    ("--grid-refine", range(1, 17), 4, "level-set grid cells per contact mesh size h"),
    ("--gauss", range(1, 6), 2, "Gauss points per contact-surface segment"),
    *MESHER_OPTIONS,  # --quads, --mesher (meshes/hertz.py)
    ("--steps", range(1, 101), 1, "load steps of the first normal approach"),
    ("--tangential-steps", range(2, 101), 12, "maximum displacement steps of the tangential stage"),
]
# fmt: on


def parse(argv):
    p = cli.demo_parser("hertz.py", __doc__, "results/hertz", OPTIONS)
    a = p.parse_args(argv)
    if a.tangential > 0 and a.mu == 0:
        p.error("--tangential: a Cattaneo-Mindlin stage needs --mu > 0")
    if a.tangential == 0 and any(str(t).startswith("--tangential-steps") for t in argv):
        p.error("--tangential-steps: steps of the tangential stage: give --tangential r > 0")
    if a.mu > 0 and a.tangential == 0:
        p.error("--mu: friction acts in the tangential stage only: give --tangential r > 0")
    path_defaults(a, argv)  # the fastest accurate settings of the path, for options not given
    try:  # the mesher; the defaults that depend on the Hertz half-width; what the scene can mesh
        a.width, a.depth, a.h = demo_sizes(a, estimate(vars(a))[1])
    except ValueError as e:
        p.error(str(e))
    return a


def estimate(p):
    """E* and the Hertz half-width at the requested load: they size the mesh and the stages."""
    E_star = analytic.effective_modulus(p["E"], p["nu"], p["E"], p["nu"])
    return E_star, analytic.hertz_line(p["load"], p["R"], E_star)[0]


def evaluate(run, E_star):
    """a, p0, p(x) (stick zone) against Hertz (Mindlin) at the reactions P (bottom), Q (top)."""
    p, pts, reaction = run.params, run.pts, run.reactions["block_bottom"]
    Q = run.reactions["cylinder_top"][0] if p["tangential"] > 0 else None
    res, an, run.curves = compare.hertz(pts, abs(reaction[1]), p["R"], E_star, p["mu"], Q)
    measured = compare.contact_results(pts, run.problem.mu)
    keys = ["contact_half_width", "contact_centre", "peak_pressure", "contact_force"]
    keys += ["stick_half_width"] if Q is not None else []
    run.results.update(reaction=reaction, applied_load=p["load"], **{k: measured[k] for k in keys})
    run.results.update(**({} if Q is None else {"tangential_force": Q}), **res)
    run.analytic.update(an)
    run.plot_kw = dict(title=f"Hertz, h = {run.metrics['mesh']['h_contact']:.3g} mm")


SUMMARY = (
    "hertz: P = {results[reaction][1]:.6g} N/mm, a = {results[contact_half_width]:.5g} "
    "(Hertz {analytic[contact_half_width]:.5g}), p0 = {results[peak_pressure]:.5g} "
    "(Hertz {analytic[peak_pressure]:.5g}), p(x) L2 error {results[pressure_rel_l2_error]:.3%}"
    " (against the circle {results[pressure_rel_l2_error_circle]:.3%})"
)


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    args.protocol = PROTOCOL
    with Run("mindlin" if args.tangential else "hertz", vars(args)) as run:
        solve(run, args)
        run.finish(SUMMARY)
    return run.status


def scene(comm, args):
    """The block and the half-cylinder, mesh size h on |x|, |y| < zone a."""
    size = scene_sizes(vars(args), estimate(vars(args))[1])  # zone, band, h_far, growth
    if args.discretization == "cut":  # graded grid, spacing h on the zone; cylinder cut
        return hertz_cut_scene(comm, **size)
    return hertz_scene(comm, **size, quads=args.quads, mesher=args.mesher)


def solve(run, args):
    """Scene, problem, loading and check of one run (main; the benchmarks call it too)."""
    E_star, a = estimate(vars(args))
    with run.phase("mesh"):
        run.scene = scene(run.comm, args)

    # the problem: block clamped at its bottom, the cylinder top held (moved by the stages)
    top_x, top_y = Dirichlet("cylinder_top", 0, 0.0), Dirichlet("cylinder_top", 1, 0.0)
    bcs = [Dirichlet("block_bottom", None, 0.0), top_x, top_y]
    pb = run.problem = run.contact_problem(bcs, mu=0.0, band=demo_band(vars(args), a))

    # the run: the top pressed down until the reaction is P (frictionless; the approach solved
    # for in Newton with "reaction = P") from the rigid interference a^2 / 2R, whose overlap
    # |x| < a is Hertz's contact (3-4 iterations; a^2 / R: 9-10). Then friction on and the top
    # moved sideways until the tangential reaction is Q = r mu P (monotonic, as Mindlin assumes).
    P, r, guess = args.load, args.tangential, -(a**2) / (2 * args.R)
    run.records = [reach_force(pb, top_y, "block_bottom", 1, P, guess, steps=args.steps)]
    if r > 0:
        run.records.append(friction_on(pb, args.mu))
        Q, probe = r * args.mu * P, 1e-3 * run.scene.h_contact  # the full-stick stiffness
        stage = (pb, top_x, "cylinder_top", 0, Q, probe, 2e-3, args.tangential_steps)
        run.records.append(reach_force(*stage, monotone=True))
    run.measure(reactions=["block_bottom", "cylinder_top"])

    # the check (rank 0): a, p0, p(x) (the stick zone) against Hertz (Cattaneo-Mindlin)
    if run.rank0:
        evaluate(run, E_star)


if __name__ == "__main__":
    cli.exit_process(main())
