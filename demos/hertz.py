#!/usr/bin/python3
"""Hertz line contact, and Cattaneo-Mindlin partial slip, on body-fitted meshes or a cut grid.

Physics. A half-cylinder of radius R (flat face on top) is pressed by a line load P (N/mm)
onto a block of the same material (plane strain), clamped at its bottom. Hertz:
E* = E / (2 (1 - nu^2)), a = sqrt(4 P R / (pi E*)), p0 = 2 P / (pi a),
p(x) = p0 sqrt(1 - x^2/a^2). With --mu > 0 and --tangential r > 0 a second stage follows: after
the normal load (applied frictionless, so no tangential traction is locked in), friction is
switched on and the cylinder top is moved sideways until the tangential force reaches
Q = r mu P. Cattaneo-Mindlin: a central stick zone of half-width c = a sqrt(1 - Q/(mu P)).

The check. metrics.json holds a, p0 and the relative L2 error of p(x) against Hertz *at the
computed load* (the reaction), the stick half-width against c at the computed Q, the Newton
residual history and the phase timings. Hertz keeps the parabola of the cylinder's gap: the
errors against the circle itself (`_circle`, to O((a/R)^4)) are there too; they differ by up
to 0.4 % at the default a/R = 0.1.

Run: /usr/bin/python3 demos/hertz.py [--discretization cut] [--mu 0.3 --tangential 0.5]
     [--mesher layers] (body-fitted triangles without gmsh: meshes/layers.py)
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
from meshes.hertz import MESHERS, hertz_scene, mesh_size_bounds

PROTOCOL = (
    "rigid approach of the cylinder top, frictionless, iterated to the load P; "
    "then friction on and monotonic tangential displacement of the top"
)
# fmt: off
OPTIONS = [  # option, kind, default[, help]
    ("--h", "(0, inf)", None, "mesh size at the contact (default a/20 of the Hertz estimate)"),
    ("--R", "(0, inf)", 10.0),
    ("--E", "(0, inf)", 1.0e4),
    ("--nu", "(-1, 0.5)", 0.3),
    ("--load", "(0, inf)", 430.0, "line load P (N/mm)"),
    ("--mu", "[0, inf)", 0.0),
    ("--tangential", "[0, 1)", 0.0,
     "Q/(mu P) of the Cattaneo-Mindlin stage (0: none; needs --mu > 0)"),
    ("--band", "(0, inf)", None,
     "largest initial gap covered by the contact surface (default: the gap at x = 1.6 a)"),
    ("--width", "(0, inf)", None, "block width (default max(40, 40 a))"),
    ("--depth", "(0, inf)", None, "block depth (default max(20, 20 a))"),
    ("--zone", "[1, inf)", 1.2, "half-width of the zone meshed at h, in units of the Hertz a"),
    ("--h-far", "(0, inf)", None,
     "mesh size far from the contact (default min(R / 2, depth / 2, 100 h))"),
    ("--grading", "(0, inf)", None,
     "size growth away from the zone: slope (body-fitted, default 0.25) or ratio of "
     "neighbouring cells (cut, > 1, default 2)"),
    ("--eps0", "(0, inf)", 0.5, "penalty factor of eq 51: eps = eps0 h / E"),
    ("--degree", [1, 2], 1),
    ("--grid-refine", range(1, 17), 4, "level-set grid cells per contact mesh size h"),
    ("--gauss", range(1, 6), 2, "Gauss points per contact-surface segment"),
    ("--quads", bool, False, "quadrilateral cells"),
    ("--mesher", list(MESHERS), "gmsh",
     "body-fitted mesher: gmsh, or layers (triangles in layers around the contact point, "
     "no gmsh)"),
    ("--steps", range(1, 101), 1, "load steps of the first normal approach"),
    ("--tangential-steps", range(2, 101), 12, "maximum displacement steps of the tangential stage"),
]
# fmt: on


def parse(argv):
    p = cli.demo_parser("hertz.py", __doc__, "results/hertz", OPTIONS)
    a = p.parse_args(argv)
    if a.tangential > 0 and a.mu == 0:
        p.error("--tangential: a Cattaneo-Mindlin stage needs --mu > 0")
    if a.mu > 0 and a.tangential == 0:
        p.error("--mu: friction acts in the tangential stage only: give --tangential r > 0")
    if a.mesher != "gmsh" and (a.discretization == "cut" or a.quads):
        p.error(f"--mesher {a.mesher}: body-fitted triangles only (not with --quads or cut)")
    if a.grading is not None and a.discretization == "cut" and not a.grading > 1:
        p.error(f"--grading: the cut grid's growth ratio must be > 1, got {a.grading:g}")
    # the defaults that depend on the Hertz half-width, then what the scene can mesh
    hertz_a = estimate(vars(a))[1]
    a.width, a.depth = a.width or max(40.0, 40 * hertz_a), a.depth or max(20.0, 20 * hertz_a)
    zone = a.zone * hertz_a
    given = "--h" if a.h is not None else "--R, --load, --E (h = a/20 of the Hertz a)"
    a.h = a.h or hertz_a / 20
    room = {"--R": a.R, "--width": a.width / 2, "--depth": a.depth}
    name = min(room, key=room.get)
    if not zone < room[name]:
        p.error(
            f"{name}: the zone meshed at h, {a.zone:g} a = {zone:.4g} (a = {hertz_a:.4g}, the "
            f"Hertz half-width of --load, --R, --E), must lie inside both bodies: "
            f"below {name.lstrip('-')}{'/2' if name == '--width' else ''} = {room[name]:.4g}"
        )
    lo, hi = mesh_size_bounds(a.R, a.width, a.depth, zone)  # cells and grading gmsh can do
    if not lo <= a.h <= hi:
        p.error(
            f"{given}: h = {a.h:.4g} outside [{lo:.4g}, {hi:.4g}] (at least 1/2000 of the "
            f"zone's half-width {zone:.4g} and 1e-5 of the largest body size "
            f"{max(a.R, a.width, a.depth):.4g}, at most half the zone; a small load needs "
            "smaller --R, --width, --depth)"
        )
    return a


def estimate(p):
    """E* and the Hertz half-width at the requested load: they size the mesh and the stages."""
    E_star = analytic.effective_modulus(p["E"], p["nu"], p["E"], p["nu"])
    return E_star, analytic.hertz_line(p["load"], p["R"], E_star)[0]


def band(p):
    """The largest initial gap Gamma_c covers: --band, default the gap at x = 1.6 a."""
    return p["band"] or (1.6 * estimate(p)[1]) ** 2 / (2 * p["R"])


def evaluate(run, E_star):
    """Measured a, p0, p(x) (and the stick zone) against Hertz (and Cattaneo-Mindlin) at the
    computed loads: P the reaction at the block bottom, Q the one at the cylinder top."""
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
    cut, a = args.discretization == "cut", estimate(vars(args))[1]
    size = dict(R=args.R, width=args.width, depth=args.depth, h=args.h, zone=args.zone * a)
    size["band"] = band(vars(args))  # rank 0 holds the cells of Gamma_c
    # the far field coarsens with h, so that its error falls with h's (fixed h_far: a floor)
    size["h_far"] = args.h_far or min(args.R / 2, args.depth / 2, 100 * args.h)
    # body-fitted slope 0.5 instead: the same error at a/20 but a floor of 0.55 % from a/40
    size["growth"] = args.grading or (2.0 if cut else 0.25)
    if cut:  # graded grid, spacing h on the zone; cylinder cut
        return hertz_cut_scene(comm, **size)
    return hertz_scene(comm, **size, quads=args.quads, mesher=args.mesher)


def solve(run, args):
    """Scene, problem, loading and check of one run (main; the benchmarks call it too)."""
    p = vars(args)
    E_star, a = estimate(p)
    with run.phase("mesh"):
        run.scene = scene(run.comm, args)

    # the problem: block clamped at its bottom, the cylinder top held (moved by the stages)
    top_x, top_y = Dirichlet("cylinder_top", 0, 0.0), Dirichlet("cylinder_top", 1, 0.0)
    bcs = [Dirichlet("block_bottom", None, 0.0), top_x, top_y]
    pb = run.problem = run.contact_problem(bcs, mu=0.0, band=band(p))

    # the run: the top pressed down until the reaction is P (frictionless; the approach
    # solved for in Newton with the equation "reaction = P"), from the rigid interference
    # a^2 / 2R, whose overlap |x| < a is Hertz's contact (3-4 iterations; a^2 / R: 9-10).
    # Then friction on and the top moved sideways while the tangential reaction rises to
    # Q = r mu P (monotonic loading, as Cattaneo-Mindlin assumes).
    P, r = args.load, args.tangential
    guess = -(a**2) / (2 * args.R)
    run.records = [reach_force(pb, top_y, "block_bottom", 1, P, guess, steps=args.steps)]
    if r > 0:
        run.records.append(friction_on(pb, args.mu))
        Q, probe = r * args.mu * P, 1e-3 * run.scene.h_contact  # the full-stick stiffness
        n = args.tangential_steps
        tangential = reach_force(pb, top_x, "cylinder_top", 0, Q, probe, 2e-3, n, monotone=True)
        run.records.append(tangential)
    run.measure(reactions=["block_bottom", "cylinder_top"])

    # the check: a, p0, p(x) (and the stick zone) against Hertz (and Cattaneo-Mindlin) at
    # the computed loads (rank 0)
    if run.rank0:
        evaluate(run, E_star)


if __name__ == "__main__":
    cli.exit_process(main())
