#!/usr/bin/python3
"""Convergence study of the Hertz line contact: errors of a, p0 and p(x) as h -> 0.

Physics. demos/hertz.py presses a half-cylinder (R = 10 mm) onto a block of the same material
(E = 10 GPa, nu = 0.3, plane strain) with a line load P = 430 N/mm; Hertz gives
E* = E / (2 (1 - nu^2)), a = sqrt(4 P R / (pi E*)) ~ 1 mm, p0 = 2 P / (pi a) and
p(x) = p0 sqrt(1 - x^2/a^2). The computed solution differs from Hertz by
  * the discretisation: the contact pressure is a traction (a stress), one order below the
    displacement; p(x) has an infinite slope at x = +-a, so near the edges it is resolved to
    O(sqrt(h)) on a strip of width O(h), which alone limits the L2 error of p(x) to O(h);
  * the penalty eps_n = eps0 h / E (eq 51): a compliance O(eps0 h) and an element-scale ripple
    O(h / eps0) of the point-wise pressure. Both vanish like h since eps_n is tied to h;
  * small-strain kinematics and the finite body (40 x 20 mm block): a few 1e-4, far below
    the errors studied here.

The check. With h = a/k for k in --sizes (default 10, 20, 40, 80) the relative L2 error of
p(x) must decrease monotonically at an observed rate near 1 (least-squares slope of log error
vs log h; the check accepts >= 0.75). The half-width a is where the normal gap, linearly
interpolated between the last active and the first open contact point (spacing ~h/8 on Gamma_c),
changes sign: near the edge the gap grows like |x - a|^(3/2) and the penalty lets it go
negative inside, so the error of a depends on where the edge falls between two points and need
not decrease monotonically; the peak pressure p0 is the largest point value and carries the
penalty ripple. Their rates are reported, not checked. Both discretisations are studied by default: body-fitted (gmsh,
P1 triangles) and cut (level sets on a graded structured grid, Q1, hertz.py's ghost penalty).

Outputs in --out (default results/convergence, replaced atomically when every run is done):
  convergence.json  the case, per run h, dofs, phase times, a, p0 and the three errors, per
                    discretisation the fitted and the local (consecutive h) rates, the check;
  convergence.png   the three errors vs h per discretisation, with reference slopes 1 and 2;
  runs/<name>/      metrics.json and tractions.csv of every run (name: conforming-a20 ...).
A failed run is recorded with its error and left out of the fits (exit status 1).

Run: /usr/bin/python3 demos/convergence_study.py [--discretization {conforming,cut,both}]
         [--sizes 10,20,40,80] [--out results/convergence] [--timeout 3600]
(the default study takes about 6 minutes on 2 cores, most of it in the two runs at a/80).
The helpers run_hertz, loglog_rate and VARIANTS are shared with benchmarks/work_precision.py.
"""

import json
import math
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from dolfinx_forms import analytic
from dolfinx_forms.cli import DemoParser, bounded

ROOT = Path(__file__).resolve().parents[1]

HERTZ = ROOT / "demos" / "hertz.py"
# The Hertz case (the defaults of demos/hertz.py), passed explicitly to every run so that the
# mesh sizes a/k placed here and the case solved there cannot drift apart.
CASE = dict(R=10.0, E=1.0e4, nu=0.3, load=430.0)
VARIANTS = {  # name -> hertz.py arguments selecting the discretisation
    "p1-tri": [],
    "p2-tri": ["--degree", "2"],
    "p1-quad": ["--quads"],
    "p2-quad": ["--degree", "2", "--quads"],
    "q1-cut": ["--discretization", "cut"],
}
DISCRETIZATIONS = {"conforming": "p1-tri", "cut": "q1-cut"}  # this study's variant of each path
ERRORS = ("half_width_rel_error", "peak_pressure_rel_error", "pressure_rel_l2_error")
ERROR_LABELS = {"half_width_rel_error": "a", "peak_pressure_rel_error": "p0",
                "pressure_rel_l2_error": "p(x) L2"}
PHASES = ("mesh", "assembly", "contact", "solve")
# metrics.json parameters recorded with each run (the settings that change the errors)
HERTZ_PARAMETERS = ("discretization", "degree", "quads", "eps0", "ghost_penalty", "grid_refine",
                    "gauss", "width", "depth")
SIZES = (10, 20, 40, 80)
MIN_RATE = 0.75  # the check: fitted rate of the p(x) L2 error in h (theory: 1)


def variant_path(variant):
    """'cut' or 'conforming': the discretisation path of a variant."""
    return "cut" if "cut" in VARIANTS[variant] else "conforming"


def hertz_reference():
    """Hertz half-width and peak pressure of CASE (at the requested load)."""
    E_star = analytic.effective_modulus(CASE["E"], CASE["nu"], CASE["E"], CASE["nu"])
    a, p0 = analytic.hertz_line(CASE["load"], CASE["R"], E_star)
    return float(a), float(p0)


def last_line(text, fallback):
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    return lines[-1] if lines else fallback


def run_hertz(h, variant_args=(), timeout=None, keep=None):
    """Run demos/hertz.py (CASE, mesh size h at the contact, extra arguments) in its own
    process and scratch folder; return the run record: ok, command, wall_s, returncode and,
    if ok, dofs, cells, the demo's phase times, Newton iterations, a, p0, Hertz at the computed
    load, the errors (ERRORS) and hertz_parameters, else `error` (the last stderr line).
    `keep`: a folder that receives the run's metrics.json and tractions.csv."""
    rec = dict(h=h)
    with tempfile.TemporaryDirectory(prefix="hertz_run.") as tmp:
        out = Path(tmp) / "hertz"
        cmd = [sys.executable, str(HERTZ.relative_to(ROOT)), "--out", str(out), "--h", repr(h),
               *(a for k, v in CASE.items() for a in (f"--{k}", repr(v))), *variant_args]
        rec["command"] = " ".join(cmd[1:])
        t0 = time.perf_counter()
        try:
            proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            rec.update(ok=False, returncode=None, wall_s=time.perf_counter() - t0,
                       error=f"killed after the {timeout:g} s timeout")
            return rec
        rec["wall_s"] = time.perf_counter() - t0
        rec["returncode"] = proc.returncode
        if proc.returncode != 0:
            rec.update(ok=False, error=last_line(proc.stderr, f"exit status {proc.returncode}"))
            return rec
        try:
            m = json.loads((out / "metrics.json").read_text())
            res, ana = m["results"], m["analytic"]
            a, p0 = res["contact_half_width"], res["peak_pressure"]
            aH, p0H = ana["contact_half_width"], ana["peak_pressure"]
            errors = dict(half_width_rel_error=abs(a - aH) / aH,
                          peak_pressure_rel_error=abs(p0 - p0H) / p0H,
                          pressure_rel_l2_error=res["pressure_rel_l2_error"])
            if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in errors.values()):
                raise ValueError(f"non-finite error in metrics.json: {errors}")
            timing = {k: float(m["timing_s"][k]) for k in ("total", *PHASES)}
            its = m["solver"]["newton_iterations"]
            prm = m.get("parameters", {})
            rec.update(ok=True, hertz_parameters={k: prm.get(k) for k in HERTZ_PARAMETERS}, num_dofs=int(m["mesh"]["num_dofs"]),
                       num_cells=int(m["mesh"]["num_cells"]), timing_s=timing,
                       newton_iterations=its, newton_iterations_total=int(sum(its)),
                       converged=m["solver"].get("converged"), cutbacks=m["solver"].get("cutbacks"),
                       contact_half_width=a, peak_pressure=p0,
                       analytic=dict(contact_half_width=aH, peak_pressure=p0H), errors=errors)
        except (OSError, KeyError, TypeError, ValueError, ZeroDivisionError) as e:
            rec.update(ok=False, error=f"hertz.py exited 0 but metrics.json is unusable: {e}")
            return rec
        if keep is not None:
            Path(keep).mkdir(parents=True, exist_ok=True)
            for f in ("metrics.json", "tractions.csv"):
                shutil.copy2(out / f, Path(keep) / f)
    return rec


def loglog_rate(x, y):
    """Least-squares slope of log y vs log x (None with fewer than 2 distinct usable x)."""
    pts = [(xi, yi) for xi, yi in zip(x, y) if xi > 0 and yi > 0]
    if len({xi for xi, _ in pts}) < 2:
        return None
    return float(np.polyfit(np.log([p[0] for p in pts]), np.log([p[1] for p in pts]), 1)[0])


def decreasing(values):
    """Strictly decreasing (None with fewer than 2 values)."""
    return all(b < a for a, b in zip(values, values[1:])) if len(values) > 1 else None


# --------------------------------------------------------------------------- the study
def parse(argv):
    p = DemoParser(prog="convergence_study.py", description=__doc__.split("\n\n")[0])
    p.add_argument("--discretization", choices=["conforming", "cut", "both"], default="both",
                   help="body-fitted P1 triangles, cut Q1, or both (default)")
    p.add_argument("--sizes", default=",".join(map(str, SIZES)),
                   help="comma-separated k of the mesh sizes h = a/k, at least 2 distinct, "
                        "each in [2, 400] (default 10,20,40,80)")
    p.add_out("results/convergence")
    p.add_argument("--timeout", type=bounded("--timeout", 0, None, lo_open=True), default=3600.0,
                   help="seconds before one run is killed and recorded as failed")
    a = p.parse_args(argv)
    check_size = bounded("--sizes", 2, 400)
    try:
        a.sizes = [check_size(s.strip()) for s in a.sizes.split(",")]
    except Exception as e:  # argparse.ArgumentTypeError: the message names --sizes
        p.error(str(e))
    a.sizes = [int(k) if float(k).is_integer() else k for k in a.sizes]
    if len(set(a.sizes)) != len(a.sizes):
        p.error(f"--sizes: a size is listed twice: {','.join(map(str, a.sizes))}")
    if len(a.sizes) < 2:
        p.error("--sizes: a rate needs at least 2 sizes")
    a.sizes = sorted(a.sizes)  # coarse to fine
    a.discretizations = ["conforming", "cut"] if a.discretization == "both" else [a.discretization]
    return a


def summarize(runs):
    """Fitted and local rates in h and monotonicity of each error (successful runs)."""
    ok = sorted((r for r in runs if r["ok"]), key=lambda r: -r["h"])  # coarse to fine
    hs = [r["h"] for r in ok]
    out = dict(runs_ok=len(ok), runs_failed=len(runs) - len(ok), rates_vs_h={},
               local_rates_vs_h={}, errors_decrease_monotonically={})
    for k in ERRORS:
        e = [r["errors"][k] for r in ok]
        out["rates_vs_h"][k] = loglog_rate(hs, e)
        out["local_rates_vs_h"][k] = [loglog_rate(hs[i:i + 2], e[i:i + 2])
                                      for i in range(len(ok) - 1)]
        out["errors_decrease_monotonically"][k] = decreasing(e)
    rate = out["rates_vs_h"]["pressure_rel_l2_error"]
    mono = out["errors_decrease_monotonically"]["pressure_rel_l2_error"]
    out["check"] = dict(
        criterion=f"p(x) L2 error decreases monotonically and its fitted rate in h is "
                  f">= {MIN_RATE} (theory 1), over >= 2 successful runs",
        passed=bool(len(ok) >= 2 and mono and rate is not None and rate >= MIN_RATE))
    return out


def plot(path, data):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, NullFormatter

    discs = data["discretizations"]
    fig, axes = plt.subplots(1, len(discs), figsize=(6 * len(discs), 4.8), squeeze=False,
                             sharey=True)
    colors = {"half_width_rel_error": "tab:blue", "peak_pressure_rel_error": "tab:orange",
              "pressure_rel_l2_error": "tab:green"}
    for ax, d in zip(axes[0], discs):
        ok = sorted((r for r in data["runs"] if r["discretization"] == d and r["ok"]),
                    key=lambda r: -r["h"])
        s = data["summary"][d]
        for k in ERRORS:
            if not ok:
                break
            rate = s["rates_vs_h"][k]
            ax.loglog([r["h"] for r in ok], [100 * r["errors"][k] for r in ok], "o-",
                      color=colors[k], label=f"{ERROR_LABELS[k]}" +
                      (f" (rate {rate:.2f})" if rate is not None else ""))
        if ok:  # reference slopes through the coarsest p(x) error
            h = np.array([ok[0]["h"], ok[-1]["h"]])
            e0 = 100 * ok[0]["errors"]["pressure_rel_l2_error"]
            for slope, ls in ((1, "--"), (2, ":")):
                ax.loglog(h, e0 * (h / h[0]) ** slope, ls, color="k", lw=0.9,
                          label=f"slope {slope}")
        ax.invert_xaxis()  # refinement to the right
        ax.set_xticks([r["h"] for r in ok])
        ax.set_xticklabels([f"a/{r['h_divisor']}\n{r['h']:.3g}" for r in ok])
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("mesh size at the contact h (mm)")
        ax.set_title(f"{d} ({DISCRETIZATIONS[d]})"
                     + ("" if s["check"]["passed"] else "  [check failed]"), fontsize=10)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=8)
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axes[0][0].set_ylabel("relative error against Hertz (%)")
    fig.suptitle(f"Hertz line contact: convergence in h (a = {data['a_hertz']:.4g} mm, "
                 f"h = a/k, k = {', '.join(map(str, data['sizes']))})", fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def report(data):
    print(f"{'discretization':14} {'h':>8} {'dofs':>8} {'time s':>7} {'a err':>8} "
          f"{'p0 err':>8} {'p L2 err':>8}")
    for r in data["runs"]:
        head = f"{r['discretization']:14} {r['h']:8.5f}"
        if not r["ok"]:
            print(f"{head}  FAILED: {r['error']}")
            continue
        e = r["errors"]
        print(f"{head} {r['num_dofs']:8d} {r['timing_s']['total']:7.2f} "
              f"{e['half_width_rel_error']:8.3%} {e['peak_pressure_rel_error']:8.3%} "
              f"{e['pressure_rel_l2_error']:8.3%}")
    for d, s in data["summary"].items():
        rt = s["rates_vs_h"]
        print(f"{d}: rates in h: " + ", ".join(
            f"{ERROR_LABELS[k]} {'-' if rt[k] is None else format(rt[k], '.2f')}"
            for k in ERRORS) + f"; check {'passed' if s['check']['passed'] else 'FAILED'} "
            f"({s['check']['criterion']})")


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    if argv is None:  # killed: unwind, so the scratch folder and the running child go too
        signal.signal(signal.SIGTERM, lambda *_: sys.exit(128 + signal.SIGTERM))
    a, p0 = hertz_reference()
    runs = []
    with tempfile.TemporaryDirectory(prefix="convergence_study.") as scratch:
        # every run first (one process each, sequential), then one atomic write: the parent
        # initialises MPI (atomic_output_dir) only after its children are done
        for d in args.discretizations:
            v = DISCRETIZATIONS[d]
            for k in args.sizes:
                name = f"{d}-a{k}"
                print(f"[convergence] {d} ({v}) h = a/{k} ...", flush=True)
                rec = dict(discretization=d, variant=v, h_divisor=k, name=name)
                rec.update(run_hertz(a / k, VARIANTS[v], args.timeout,
                                     keep=Path(scratch) / name))
                runs.append(rec)
                print(f"    {rec['num_dofs']} dofs, {rec['timing_s']['total']:.2f} s, p(x) L2 "
                      f"error {rec['errors']['pressure_rel_l2_error']:.3%}" if rec["ok"] else
                      f"    FAILED: {rec['error']}", flush=True)
        data = dict(
            study="hertz convergence in h (frictionless, demos/hertz.py)",
            case=CASE, a_hertz=a, p0_hertz=p0, sizes=args.sizes,
            h=[a / k for k in args.sizes], discretizations=args.discretizations,
            variants={d: DISCRETIZATIONS[d] for d in args.discretizations},
            hertz_args={d: VARIANTS[DISCRETIZATIONS[d]] for d in args.discretizations},
            errors_definition=dict(
                half_width_rel_error="|a - a_H| / a_H, a: half the distance between the zeros "
                                     "of the interpolated gap at the two ends of the active "
                                     "zone, a_H: Hertz at the computed load",
                peak_pressure_rel_error="|p0 - p0_H| / p0_H, p0: the largest point pressure",
                pressure_rel_l2_error="||p - p_H|| / ||p_H|| over the contact points "
                                      "(results.pressure_rel_l2_error of metrics.json)"),
            rates_definition="rates_vs_h: least-squares slope of log(error) vs log(h) over the "
                             "successful runs (positive: converging); local_rates_vs_h: the "
                             "slope between consecutive sizes",
            runs=[dict(r, files=f"runs/{r['name']}" if r["ok"] else None) for r in runs],
            summary={d: summarize([r for r in runs if r["discretization"] == d])
                     for d in args.discretizations},
        )
        from dolfinx_forms.results import OutputFolderError, atomic_output_dir

        try:
            with atomic_output_dir(args.out, force=args.force) as tmp:
                for r in runs:
                    if r["ok"]:
                        shutil.copytree(Path(scratch) / r["name"], tmp / "runs" / r["name"])
                plot(tmp / "convergence.png", data)
                with open(tmp / "convergence.json", "w") as f:
                    json.dump(data, f, indent=2, allow_nan=False)
                    f.write("\n")
        except OutputFolderError as e:  # the folder changed during the runs (checked before)
            sys.stderr.write(f"convergence_study.py: error: {e}\n")
            return 1
        except OSError as e:
            sys.stderr.write(f"convergence_study.py: error: --out: cannot write {args.out}: {e}\n")
            return 1
    report(data)
    print(f"results in {Path(args.out).resolve()}")
    return 0 if all(r["ok"] for r in runs) else 1


if __name__ == "__main__":
    sys.exit(main())
