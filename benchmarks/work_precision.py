#!/usr/bin/python3
"""Work-precision benchmark of the Hertz line-contact demo (frictionless, demo defaults).

Runs demos/hertz.py as one subprocess per run (so the timings of the runs are independent)
at contact mesh sizes h = a/10, a/14, a/20, a/28, a/40 (a: the Hertz half-width of the demo
defaults, ~1 mm) for each discretization variant, sequentially. Variants: the body-fitted
(gmsh) path p1-tri, p2-tri, p1-quad, p2-quad (hertz.py [--degree 2] [--quads]) and the cut path
q1-cut (hertz.py --discretization cut: level sets on a graded structured grid, Q1, hertz.py's
default ghost penalty); default p1-tri,p1-quad,q1-cut, so one run compares both paths. Writes

  <out-dir>/work_precision.json  the runs (h, dofs, phase wall times, Newton iterations,
                                 errors of a, p0 and p(x) against Hertz), per variant the
                                 observed convergence rates of each error vs h (least squares
                                 on log-log) and the time to reach 2 % pressure L2 error
                                 (log-log interpolation between the bracketing runs);
                                 cut_vs_conforming: q1-cut's time to 2 % beside the fastest
                                 conforming variant's;
  <out-dir>/work_precision.png   pressure L2 error vs wall time and vs dofs, and the stacked
                                 phase times of every run.

Both files are replaced atomically. A run whose demo exits non-zero is recorded with the last
line of its stderr and left out of the rates and curves. Times are the demo's own phase timer
(timing_s.total: mesh generation to the end of post-processing, without interpreter start-up
and file output); the subprocess wall time is recorded beside it as wall_s.
Running a demo and turning its metrics.json into errors is demos/convergence_study.py's
run_hertz (shared, with the variants' arguments and the log-log fit).

Usage: /usr/bin/python3 benchmarks/work_precision.py [--quick] [--variants p1-tri,p1-quad,q1-cut]
                                                     [--out-dir benchmarks/results] [--timeout S]
  --quick: a/10, a/14, a/20 only (default variants p1-tri,q1-cut), a smoke run of ~1 minute.
"""

import hashlib
import importlib.util
import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from dolfinx_forms.cli import DemoParser

ROOT = Path(__file__).resolve().parents[1]


def _load_study():
    """demos/convergence_study.py as a module (demos/ is not a package): run_hertz and the
    variants live there, once."""
    name = "convergence_study"
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, ROOT / "demos" / f"{name}.py")
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod
        spec.loader.exec_module(mod)
    return sys.modules[name]


study = _load_study()
DEMO = study.HERTZ
HERTZ_DEFAULTS = study.CASE  # passed explicitly to every run
VARIANTS = study.VARIANTS  # name -> extra demo arguments
ERRORS, PHASES = study.ERRORS, study.PHASES
loglog_rate = study.loglog_rate
DIVISORS = (10, 14, 20, 28, 40)
QUICK_DIVISORS = (10, 14, 20)
DEFAULT_VARIANTS = "p1-tri,p1-quad,q1-cut"  # p2-tri is selectable (about 8 minutes alone)
QUICK_VARIANTS = "p1-tri,q1-cut"
TARGET = 0.02  # pressure L2 error of the time-to-precision figure


def parse(argv):
    p = DemoParser(prog="work_precision.py", description=__doc__.split("\n\n")[0])
    p.add_argument(
        "--quick",
        action="store_true",
        help=f"smoke test: 3 coarse sizes (a/10, a/14, a/20), variants "
        f"{QUICK_VARIANTS} unless --variants is given",
    )
    p.add_argument(
        "--variants",
        default=None,
        help=f"comma-separated subset of {','.join(VARIANTS)} " f"(default {DEFAULT_VARIANTS})",
    )
    p.add_argument(
        "--out-dir",
        default=str(ROOT / "benchmarks" / "results"),
        help="folder of work_precision.json and .png (default benchmarks/results)",
    )
    p.add_argument(
        "--timeout",
        type=float,
        default=3600.0,
        help="seconds before one demo run is killed and recorded as failed",
    )
    a = p.parse_args(argv)
    names = [
        v.strip()
        for v in (a.variants or (QUICK_VARIANTS if a.quick else DEFAULT_VARIANTS)).split(",")
    ]
    bad = [v for v in names if v not in VARIANTS]
    if bad or not names:
        p.error(
            f"--variants: unknown variant {bad[0] if bad else ''!r}; "
            f"choose from {','.join(VARIANTS)}"
        )
    if len(set(names)) != len(names):
        p.error("--variants: a variant is listed twice")
    if not (math.isfinite(a.timeout) and a.timeout > 0):
        p.error(f"--timeout must be in (0, inf), got {a.timeout}")
    a.variants = names
    a.divisors = QUICK_DIVISORS if a.quick else DIVISORS
    return a


def code_digest():
    """sha256 (12 hex) over the sources the demo runs (demo and its runner, package, meshes,
    compiled core):
    others may edit the repository while the benchmark runs; a change shows up per run."""
    files = [
        DEMO,
        Path(study.__file__),
        *sorted((ROOT / "dolfinx_forms").glob("*.py")),
        *sorted((ROOT / "dolfinx_forms").glob("_cpp*.so")),
        *sorted((ROOT / "meshes").glob("*.py")),
    ]
    h = hashlib.sha256()
    for f in files:
        h.update(str(f.relative_to(ROOT)).encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:12]


def git_head():
    try:
        r = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True, timeout=30
        )
        d = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"],
            cwd=ROOT,
            capture_output=True,
            text=True,
            timeout=30,
        )
        return dict(
            commit=r.stdout.strip() or None,
            modified=[ln[3:] for ln in d.stdout.splitlines() if ln.strip()],
        )
    except (OSError, subprocess.SubprocessError):
        return dict(commit=None, modified=None)


def hertz_half_width():
    return study.hertz_reference()[0]


def run_one(variant, divisor, h, timeout):
    """One demo run in a scratch folder; returns the run record (ok or failed)."""
    rec = dict(
        variant=variant,
        path=study.variant_path(variant),
        h_divisor=divisor,
        h=h,
        code_sha256=code_digest(),
    )
    rec.update(study.run_hertz(h, VARIANTS[variant], timeout))
    return rec


def time_to_target(runs, target=TARGET):
    """Total time (and dofs) at which the pressure L2 error reaches `target`, interpolated
    log-log between the first pair of runs (by increasing time) that brackets it."""
    ok = sorted(runs, key=lambda r: r["timing_s"]["total"])
    out = dict(target=target, reached=False, time_s=None, num_dofs=None, method=None)
    if not ok:
        out["method"] = "no successful run"
        return out
    e = [r["errors"]["pressure_rel_l2_error"] for r in ok]
    t = [r["timing_s"]["total"] for r in ok]
    n = [r["num_dofs"] for r in ok]
    if e[0] <= target:
        out.update(
            reached=True,
            time_s=t[0],
            num_dofs=n[0],
            method="upper bound: the fastest run is already at or below the target",
        )
        return out
    for i in range(len(ok) - 1):
        if e[i] > target >= e[i + 1]:
            s = (math.log(target) - math.log(e[i])) / (math.log(e[i + 1]) - math.log(e[i]))
            ti = math.exp(math.log(t[i]) + s * (math.log(t[i + 1]) - math.log(t[i])))
            ni = math.exp(math.log(n[i]) + s * (math.log(n[i + 1]) - math.log(n[i])))
            out.update(
                reached=True,
                time_s=ti,
                num_dofs=ni,
                method=f"log-log interpolation between h = {ok[i]['h']:.4g} and "
                f"h = {ok[i + 1]['h']:.4g}",
            )
            return out
    out["method"] = f"not reached (smallest error {min(e):.4g})"
    return out


def summarize(variant, runs):
    ok = [r for r in runs if r["ok"]]
    ok_h = sorted(ok, key=lambda r: -r["h"])  # coarse to fine
    hs = [r["h"] for r in ok_h]
    rates, monotone = {}, {}
    for k in ERRORS:
        errs = [r["errors"][k] for r in ok_h]
        rates[k] = loglog_rate(hs, errs)
        monotone[k] = study.decreasing(errs)
    return dict(
        variant=variant,
        path=study.variant_path(variant),
        runs_ok=len(ok),
        runs_failed=len(runs) - len(ok),
        rates_vs_h=rates,
        rate_pressure_l2_vs_dofs=loglog_rate(
            [r["num_dofs"] for r in ok_h], [r["errors"]["pressure_rel_l2_error"] for r in ok_h]
        ),
        errors_decrease_monotonically=monotone,
        time_to_target=time_to_target(ok),
    )


def compare_paths(summary):
    """Time (and dofs) to TARGET of the cut variant(s) beside the fastest conforming variant."""

    def best(path):
        got = [
            (s["time_to_target"]["time_s"], v)
            for v, s in summary.items()
            if s["path"] == path and s["time_to_target"]["reached"]
        ]
        return min(got) if got else (None, None)

    (t_c, v_c), (t_x, v_x) = best("conforming"), best("cut")
    return dict(
        target=TARGET,
        time_to_target_s={v: s["time_to_target"]["time_s"] for v, s in summary.items()},
        dofs_at_target={v: s["time_to_target"]["num_dofs"] for v, s in summary.items()},
        rate_pressure_l2_vs_h={
            v: s["rates_vs_h"]["pressure_rel_l2_error"] for v, s in summary.items()
        },
        fastest_conforming=v_c,
        fastest_cut=v_x,
        cut_over_conforming_time=(t_x / t_c if t_c and t_x else None),
        definition="time_to_target_s: the demo's total time at which the pressure L2 error "
        "reaches the target (log-log interpolation, see summary.*.time_to_target); "
        "cut_over_conforming_time: fastest cut / fastest conforming (< 1: the cut "
        "path is faster)",
    )


def write_atomic(path, writer):
    """writer(tmp_path) writes the file; it then replaces `path` in one rename."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        writer(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the usual file mode
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def write_json(path, data):
    def writer(tmp):
        with open(tmp, "w") as f:
            json.dump(data, f, indent=2, allow_nan=False)
            f.write("\n")
            f.flush()
            os.fsync(f.fileno())

    write_atomic(path, writer)


COLORS = {
    "p1-tri": "tab:blue",
    "p2-tri": "tab:orange",
    "p1-quad": "tab:green",
    "p2-quad": "tab:red",
    "q1-cut": "tab:purple",
}
PHASE_COLORS = {
    "mesh": "tab:gray",
    "assembly": "tab:blue",
    "contact": "tab:orange",
    "solve": "tab:green",
    "other": "whitesmoke",
}


def plain_log_labels(ax):
    """Log axes labelled 2, 5, 10 ... instead of 2x10^0; minor labels only on short spans."""
    from matplotlib.ticker import FuncFormatter, NullFormatter

    fmt = FuncFormatter(lambda v, _: f"{v:g}")
    # x labels are wide: beyond a span of 6 the minor ones overlap (y: beyond 30)
    for axis, (lo, hi), span in ((ax.xaxis, ax.get_xlim(), 6), (ax.yaxis, ax.get_ylim(), 30)):
        axis.set_major_formatter(fmt)
        short = lo > 0 and hi / lo < span
        axis.set_minor_formatter(fmt if short else NullFormatter())


def plot(path, data):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(12, 9))
    gs = fig.add_gridspec(2, 2, height_ratios=[1, 1])
    ax_t, ax_n = fig.add_subplot(gs[0, 0]), fig.add_subplot(gs[0, 1])
    ax_s = fig.add_subplot(gs[1, :])
    by_variant = {v: [r for r in data["runs"] if r["variant"] == v] for v in data["variants"]}
    for v, runs in by_variant.items():
        ok = sorted((r for r in runs if r["ok"]), key=lambda r: -r["h"])
        if not ok:
            continue
        e = [100 * r["errors"]["pressure_rel_l2_error"] for r in ok]
        rate = data["summary"][v]["rates_vs_h"]["pressure_rel_l2_error"]
        label = f"{v} ({'cut' if study.variant_path(v) == 'cut' else 'gmsh'})" + (
            f", rate {rate:.2f} in h" if rate is not None else ""
        )
        c, style = COLORS.get(v), "s--" if study.variant_path(v) == "cut" else "o-"
        ax_t.loglog([r["timing_s"]["total"] for r in ok], e, style, color=c, label=label)
        ax_n.loglog([r["num_dofs"] for r in ok], e, style, color=c, label=label)
        for r, ei in zip(ok, e):
            ax_n.annotate(
                f"a/{r['h_divisor']}",
                (r["num_dofs"], ei),
                fontsize=7,
                xytext=(3, 3),
                textcoords="offset points",
                color=c,
            )
        tt = data["summary"][v]["time_to_target"]
        if tt["reached"]:
            ax_t.plot(tt["time_s"], 100 * TARGET, "*", ms=12, color=c, mec="k", mew=0.5)
            ax_n.plot(tt["num_dofs"], 100 * TARGET, "*", ms=12, color=c, mec="k", mew=0.5)
    for ax, xl in ((ax_t, "total wall time of the run (s)"), (ax_n, "number of dofs")):
        ax.axhline(100 * TARGET, ls="--", color="k", lw=0.8)
        ax.set_xlabel(xl)
        ax.set_ylabel("pressure relative L2 error (%)")
        ax.grid(True, which="both", lw=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=8)
    for ax in (ax_t, ax_n):
        plain_log_labels(ax)
    ax_t.set_title(f"error vs time (star: {100 * TARGET:g} % reached)")
    ax_n.set_title("error vs problem size")

    # stacked phase times, grouped by variant
    x, labels, pos = 0.0, [], []
    bottoms_seen = set()
    for v, runs in by_variant.items():
        for r in sorted(runs, key=lambda r: -r["h"]):
            pos.append(x)
            labels.append(f"{v}\na/{r['h_divisor']}")
            if r["ok"]:
                b = 0.0
                ts = r["timing_s"]
                parts = [(k, ts[k]) for k in PHASES]
                parts.append(("other", max(0.0, ts["total"] - sum(ts[k] for k in PHASES))))
                for k, val in parts:
                    ax_s.bar(
                        x,
                        val,
                        bottom=b,
                        color=PHASE_COLORS[k],
                        edgecolor="k",
                        lw=0.3,
                        label=k if k not in bottoms_seen else None,
                    )
                    bottoms_seen.add(k)
                    b += val
                ax_s.text(x, b, f"{b:.1f}", ha="center", va="bottom", fontsize=7)
            else:
                ax_s.text(
                    x, 0, "failed", ha="center", va="bottom", rotation=90, color="r", fontsize=8
                )
            x += 1.0
        x += 0.8
    ax_s.set_xticks(pos)
    ax_s.set_xticklabels(labels, fontsize=7)
    ax_s.set_ylim(0, 1.12 * ax_s.get_ylim()[1])  # room for the totals above the bars
    ax_s.set_ylabel("wall time (s)")
    ax_s.set_title("phase times per run (other: total minus the four phases)")
    if bottoms_seen:
        ax_s.legend(fontsize=8, ncol=5, loc="upper left")
    ax_s.grid(True, axis="y", lw=0.3)
    fig.suptitle(
        f"Hertz line contact, frictionless: work-precision "
        f"(a = {data['a_hertz']:.4g} mm, h = a/k)",
        fontsize=11,
    )
    fig.tight_layout()
    write_atomic(path, lambda tmp: fig.savefig(tmp, dpi=110, format="png"))
    plt.close(fig)


def fmt(x, spec):
    return "-" if x is None else format(x, spec)


def report(data):
    print(
        f"{'variant':8} {'h':>7} {'dofs':>8} {'total s':>8} {'solve s':>8} {'Newton':>6} "
        f"{'|a-aH|/aH':>10} {'|p0-pH|/pH':>10} {'p L2 err':>9}"
    )
    for r in data["runs"]:
        if not r["ok"]:
            print(f"{r['variant']:8} {r['h']:7.4f}  FAILED: {r['error']}")
            continue
        e = r["errors"]
        print(
            f"{r['variant']:8} {r['h']:7.4f} {r['num_dofs']:8d} {r['timing_s']['total']:8.2f} "
            f"{r['timing_s']['solve']:8.2f} {r['newton_iterations_total']:6d} "
            f"{e['half_width_rel_error']:10.3%} {e['peak_pressure_rel_error']:10.3%} "
            f"{e['pressure_rel_l2_error']:9.3%}"
        )
    for v, s in data["summary"].items():
        rt = s["rates_vs_h"]
        tt = s["time_to_target"]
        print(
            f"{v}: rates vs h: a {fmt(rt['half_width_rel_error'], '.2f')}, "
            f"p0 {fmt(rt['peak_pressure_rel_error'], '.2f')}, "
            f"p L2 {fmt(rt['pressure_rel_l2_error'], '.2f')}; "
            f"time to {100 * TARGET:g} %: "
            + (f"{tt['time_s']:.2f} s ({tt['method']})" if tt["reached"] else tt["method"])
        )
    c = data["cut_vs_conforming"]
    print(f"time to {100 * TARGET:g} % pressure L2 error, gmsh vs cut path:")
    print(f"  {'variant':8} {'path':10} {'rate in h':>9} {'time s':>8} {'dofs':>8}")
    for v, s in data["summary"].items():
        tt = s["time_to_target"]
        print(
            f"  {v:8} {s['path']:10} {fmt(s['rates_vs_h']['pressure_rel_l2_error'], '9.2f'):>9} "
            f"{fmt(tt['time_s'], '8.2f'):>8} {fmt(tt['num_dofs'], '8.0f'):>8}"
        )
    if c["cut_over_conforming_time"] is not None:
        print(
            f"  {c['fastest_cut']} / {c['fastest_conforming']}: "
            f"{c['cut_over_conforming_time']:.2f} x the time"
        )


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    out_dir = Path(args.out_dir)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        sys.stderr.write(f"work_precision.py: error: --out-dir: cannot create {out_dir}: {e}\n")
        return 2
    a = hertz_half_width()
    git = git_head()
    load0 = os.getloadavg()[0] if hasattr(os, "getloadavg") else None
    runs = []
    for v in args.variants:
        for k in args.divisors:
            h = a / k
            print(f"[work_precision] {v} h = a/{k} = {h:.5f} ...", flush=True)
            rec = run_one(v, k, h, args.timeout)
            runs.append(rec)
            if rec["ok"]:
                print(
                    f"    {rec['num_dofs']} dofs, {rec['timing_s']['total']:.2f} s, "
                    f"p L2 error {rec['errors']['pressure_rel_l2_error']:.3%}",
                    flush=True,
                )
            else:
                print(f"    FAILED: {rec['error']}", flush=True)
    data = dict(
        benchmark="hertz work-precision (frictionless, demos/hertz.py defaults)",
        a_hertz=a,
        hertz_defaults=HERTZ_DEFAULTS,
        h_divisors=list(args.divisors),
        variants=args.variants,
        variant_args={v: VARIANTS[v] for v in args.variants},
        quick=args.quick,
        python=sys.executable,
        git=git,
        code_sha256=sorted({r["code_sha256"] for r in runs}),
        code_changed_during_benchmark=len({r["code_sha256"] for r in runs}) > 1,
        load_average_at_start=load0,
        cpu_count=os.cpu_count(),
        errors_definition=dict(
            half_width_rel_error="|a - a_H| / a_H, a_H Hertz at the computed load",
            peak_pressure_rel_error="|p0 - p0_H| / p0_H, p0_H Hertz at the computed load",
            pressure_rel_l2_error="results.pressure_rel_l2_error of metrics.json",
        ),
        rates_definition="least-squares slope of log(error) vs log(h) over the successful runs "
        "(positive: converging); rate_pressure_l2_vs_dofs: slope vs num_dofs",
        timing_definition="timing_s: the demo's phase timer (total excludes interpreter start-up "
        "and file output); wall_s: the subprocess wall time",
        runs=runs,
        summary={v: summarize(v, [r for r in runs if r["variant"] == v]) for v in args.variants},
    )
    data["cut_vs_conforming"] = compare_paths(data["summary"])
    json_path, png_path = out_dir / "work_precision.json", out_dir / "work_precision.png"
    write_json(json_path, data)
    plot(png_path, data)
    report(data)
    if data["code_changed_during_benchmark"]:
        print(
            "warning: the demo/package sources changed during the benchmark "
            f"(digests {', '.join(data['code_sha256'])}); runs are not comparable"
        )
    print(f"results in {json_path.resolve()} and {png_path.resolve()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
