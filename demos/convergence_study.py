#!/usr/bin/python3
"""Convergence study of the Hertz line contact: errors of a, p0 and p(x) as h -> 0.

Physics. demos/hertz.py presses a half-cylinder (--R, default 10 mm) onto a block (E = 10 GPa,
nu = 0.3, plane strain) with P = 430 N/mm: Hertz's a = sqrt(4 P R / (pi E*)), E* = E / (2 (1 -
nu^2)), p(x) = p0 sqrt(1 - x^2/a^2), p0 = 2 P / (pi a). p(x)'s infinite slope at +-a, resolved to
O(sqrt(h)) on a strip of width O(h), makes its L2 error O(h), with the penalty and the
augmented Lagrangian (P1 multipliers) alike (--enforcement, default both).

The check. With h = a/k, k in --sizes, the relative L2 error of p(x) against Hertz decreases
monotonically at a fitted rate (least squares, log error vs log h) >= 0.75; against the circle
the scene meshes it is reported (Hertz's parabola is 0.4 % off it at R = 10, 0.03 % at R = 40),
as are the rates of a and p0. Paths: body-fitted (P1 triangles in layers) and cut (Q1 on a graded
grid). --bulk resolved (default): bodies meshed so that their own error stays below the
contact's (study.bulk_args); demo: hertz.py's own meshes (their bulk refines below a/20 too:
the same figures at a/80, far fewer dofs at a/20, docs/demos/convergence_study.md).

Outputs in --out (default results/convergence, replaced atomically when every run is done):
  convergence.json  the case; per run h, dofs, times, a, p0, four errors; per group
                    (discretisation-enforcement) the fitted and local rates, the check;
  convergence.png   the errors vs h per group, with reference slopes 1 and 2;
  runs/<name>/      metrics.json and tractions.csv of every run (conforming-penalty-a20 ...).
A failed run is recorded with its error and left out of the fits (exit status 1).

Run: /usr/bin/python3 demos/convergence_study.py [--discretization {conforming,cut,both}]
         [--enforcement {penalty,augmented,both}] [--R 10] [--bulk {resolved,demo}]
         [--sizes 10,20,40,80] [--out results/convergence] [--timeout 3600]
Results and discussion: docs/demos/convergence_study.md
"""

import importlib.util
import signal
import sys
import tempfile
from pathlib import Path

if importlib.util.find_spec("dolfinx_forms") is None:  # a hint, not a ModuleNotFoundError
    sys.exit(f"{sys.argv[0]}: dolfinx_forms not found: run `make build`, then "
             "`export PYTHONPATH=$PWD` in the repository (README.md, Installation)")  # fmt: skip
from dolfinx_forms.app import cli, study
from dolfinx_forms.app.study import BULKS, CASE, CIRCLE_ERROR, CONVERGENCE_DEFINITIONS, ERRORS
from dolfinx_forms.app.study import ENFORCEMENTS, ERROR_LABELS, PATHS, VARIANT, VARIANTS
from dolfinx_forms.app.study import bulk_args, hertz_reference
from dolfinx_forms.io.folders import OutputFolderError

HERTZ = Path(__file__).resolve().with_name("hertz.py")  # the demo every run of the study runs


def run_hertz(h, variant_args=(), timeout=None, keep=None, case=None):
    """demos/hertz.py on the Hertz case at mesh size h (`study.run_hertz`)."""
    return study.run_hertz(HERTZ, h, variant_args, timeout, keep, case)


SIZES = (10, 20, 40, 80)
OPTIONS = [
    ("--discretization", [*PATHS, "both"], "both",
     "body-fitted P1 triangles, cut Q1, or both (default)"),
    ("--enforcement", [*ENFORCEMENTS, "both"], "both",
     "the penalty (eps0 0.5), the augmented Lagrangian (hybrid projection), or both (default)"),
    ("--R", "(0, inf)", CASE["R"], f"cylinder radius (default {CASE['R']:g})"),
    ("--bulk", list(BULKS), BULKS[0], "resolved: a bulk whose error stays below the contact's "
     "(default); demo: hertz.py's own meshes"),
    ("--timeout", "(0, inf)", 3600.0, "seconds before one run is killed and recorded as failed"),
]  # fmt: skip
CHECK = ("pressure_rel_l2_error", "p(x) L2 error", 0.75)  # least fitted rate in h (theory 1)
STUDY_ERRORS = (*ERRORS, CIRCLE_ERROR)
LABELS = {**ERROR_LABELS, CIRCLE_ERROR: "p(x) L2 vs circle"}


def parse(argv):
    p = cli.DemoParser(prog="convergence_study.py", description=__doc__.split("\n\n")[0])
    cli.add_options(p, OPTIONS[:4])
    ks = ",".join(map(str, SIZES))
    what = "comma-separated k of the mesh sizes h = a/k, at least 2 distinct, each in [2, 400]"
    p.add_argument("--sizes", default=ks, help=f"{what} (default {ks})")
    p.add_out("results/convergence")
    cli.add_options(p, OPTIONS[4:])
    a = p.parse_args(argv)
    try:  # argparse.ArgumentTypeError: the message names --sizes
        sizes = [cli.bounded("--sizes", 2, 400)(s.strip()) for s in a.sizes.split(",")]
    except Exception as e:
        p.error(str(e))
    a.sizes = [int(k) if k.is_integer() else k for k in sizes]
    if len(set(a.sizes)) != len(a.sizes):
        p.error(f"--sizes: a size is listed twice: {','.join(map(str, a.sizes))}")
    if len(a.sizes) < 2:
        p.error("--sizes: a rate needs at least 2 sizes")
    a.sizes = sorted(a.sizes)  # coarse to fine
    a.discretizations = list(PATHS) if a.discretization == "both" else [a.discretization]
    a.enforcements = list(ENFORCEMENTS) if a.enforcement == "both" else [a.enforcement]
    a.groups = {f"{d}-{e}": (d, e) for d in a.discretizations for e in a.enforcements}
    return a


def sweep(args, a, scratch):
    """Every run, one process each, sequentially: h = a/k per group and size."""
    runs = []
    for group, (d, e) in args.groups.items():
        for k in args.sizes:
            v, name = VARIANT[d, e], f"{group}-a{k}"
            print(f"[convergence] {group} ({v}) h = a/{k} ...", flush=True)
            rec = dict(discretization=d, enforcement=e, group=group, variant=v, h_divisor=k)
            extra = [*VARIANTS[v], *bulk_args(args.bulk, a, a / k, d == "cut")]
            keep = Path(scratch) / name
            rec.update(name=name, **run_hertz(a / k, extra, args.timeout, keep, dict(R=args.R)))
            runs.append(rec)
            print(f"    {study.run_line(rec, *CHECK[:2])}", flush=True)
    return runs


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    if argv is None:  # killed: unwind, so the scratch folder and the running child go too
        signal.signal(signal.SIGTERM, lambda *_: sys.exit(128 + signal.SIGTERM))
    a, p0 = hertz_reference(dict(R=args.R))
    with tempfile.TemporaryDirectory(prefix="convergence_study.") as scratch:
        runs = sweep(args, a, scratch)
        gs = list(args.groups)
        groups = {g: [r for r in runs if r["group"] == g] for g in gs}
        summary = {g: study.convergence(groups[g], STUDY_ERRORS, *CHECK) for g in gs}
        data = dict(
            study="hertz convergence in h (frictionless, demos/hertz.py)",
            case=dict(CASE, R=args.R), a_hertz=a, p0_hertz=p0, sizes=args.sizes,
            h=[a / k for k in args.sizes], discretizations=args.discretizations,
            enforcements=args.enforcements, groups=gs, bulk=args.bulk,
            variants={g: VARIANT[de] for g, de in args.groups.items()},
            hertz_args={g: VARIANTS[VARIANT[de]] for g, de in args.groups.items()},
            **CONVERGENCE_DEFINITIONS,
            runs=[dict(r, files=f"runs/{r['name']}" if r["ok"] else None) for r in runs],
            summary=summary,
        )  # fmt: skip
        panels = [(f"{g} ({VARIANT[de]})", groups[g], summary[g]) for g, de in args.groups.items()]
        ks = ", ".join(map(str, args.sizes))
        title = (f"Hertz line contact, R = {args.R:g}: convergence in h (a = {a:.4g} mm, h = a/k, "
                 f"k = {ks}, bulk {args.bulk})")  # fmt: skip
        plot = lambda path: study.plot_errors(  # noqa: E731
            path, panels, LABELS, title, reference="pressure_rel_l2_error"
        )
        try:
            study.write_study(args.out, data, runs, scratch, plot, force=args.force)
        except OutputFolderError as e:  # the folder changed during the runs (checked before)
            sys.stderr.write(f"convergence_study.py: error: {e}\n")
            return 1
    study.print_errors(runs, summary, LABELS, group="group")
    print(f"results in {Path(args.out).resolve()}")
    return 0 if all(r["ok"] for r in runs) else 1


if __name__ == "__main__":
    cli.exit_process(main())
