#!/usr/bin/python3
"""Whole-process wall time of the cut Hertz demo against GetFEM's whole process (issue 12,
"the whole process of the cut demo no slower than GetFEM's whole process").

Each case is one fresh process, timed from its start to its exit (interpreter start-up,
imports, meshing, solve, output: what a user who runs one command waits for):
  ours a/20   demos/hertz.py --discretization cut (its default h = a/20), into a fresh --out
  ours a/10   the same with --h a/10
  getfem a/20, getfem a/10   benchmarks/getfem_hertz.py --h ... (GetFEM's nodal P1 on the same
              Hertz problem, gmsh mesh, force control; prints one line, writes no file)
a: the Hertz half-width of the demo defaults (0.998 mm). The cases run interleaved, N rounds,
the order rotated each round, so that the machine's load (2 cores, shared) falls on all alike;
one untimed warm-up run of each first (FFCx's JIT cache and the file cache warm). Reported per
case: median, min and max of the wall times, the median of the in-process total (ours:
metrics.json timing_s.total; GetFEM: its timing_s.total) and the rest (start-up, imports,
output) as their difference; ratios ours / GetFEM of the medians at each h. Without GetFEM
(`import getfem` fails: apt-get install python3-getfem) its cases are skipped with a note.

Writes (each file replaced atomically) <out-dir>/startup.json (every run, the summary, the
load averages before and after), startup.csv (one row per run) and startup.png (median wall
time per case, min-max bars, with the in-process part).

Usage: /usr/bin/python3 benchmarks/startup.py [--n 7] [--out-dir benchmarks/results]
                                              [--no-getfem] [--timeout 300]
"""

import argparse
import csv
import importlib.util
import io
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from benchmarks.common import write_atomic

ROOT = Path(__file__).resolve().parents[1]
PYTHON = "/usr/bin/python3"  # Debian's interpreter: it has dolfinx, gmsh and getfem


def hertz_a():
    """The Hertz half-width of the demo defaults (R 10, E 1e4, nu 0.3, P 430; both bodies
    alike), without importing dolfinx_forms: this process stays MPI-free, its runs are not."""
    E_star = 1.0e4 / (2 * (1 - 0.3**2))
    return math.sqrt(4 * 430.0 * 10.0 / (math.pi * E_star))


def cases(getfem):
    a = hertz_a()
    demo = [PYTHON, str(ROOT / "demos" / "hertz.py"), "--discretization", "cut"]
    out = {"ours a/20": ("ours", 20, demo), "ours a/10": ("ours", 10, demo + ["--h", repr(a / 10)])}
    if getfem:
        gf = [PYTHON, str(ROOT / "benchmarks" / "getfem_hertz.py"), "--json"]
        out["getfem a/20"] = ("getfem", 20, gf)
        out["getfem a/10"] = ("getfem", 10, gf + ["--h", repr(a / 10)])
    return out


def run_once(name, side, cmd, scratch, k, timeout):
    """One process: (wall time s, in-process total s, p(x) error); RuntimeError if it fails."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    if side == "ours":
        folder = Path(scratch) / f"{name.replace(' ', '_').replace('/', '')}_{k}"
        cmd = cmd + ["--out", str(folder)]
    t = time.perf_counter()
    p = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout)
    wall = time.perf_counter() - t
    if p.returncode != 0:
        tail = (p.stderr.strip().splitlines() or ["(no stderr)"])[-1]
        raise RuntimeError(f"{name}: exit {p.returncode}: {tail}")
    if side == "ours":
        m = json.loads((folder / "metrics.json").read_text())
        return wall, m["timing_s"]["total"], m["results"]["pressure_rel_l2_error"]
    res = json.loads(p.stdout.strip().splitlines()[-1])  # GetFEM prints a line of its own first
    return wall, res["timing_s"]["total"], res["errors"]["pressure_rel_l2_error"]


def summarise(runs, names):
    out = {}
    for name in names:
        r = [x for x in runs if x["case"] == name]
        wall, inproc = [x["wall_s"] for x in r], [x["in_process_s"] for x in r]
        out[name] = dict(
            n=len(r),
            wall_median_s=statistics.median(wall),
            wall_min_s=min(wall),
            wall_max_s=max(wall),
            in_process_median_s=statistics.median(inproc),
            rest_median_s=statistics.median(w - i for w, i in zip(wall, inproc)),
            pressure_rel_l2_error=r[0]["pressure_rel_l2_error"],
        )
    ratios = {}
    for d in (20, 10):
        ours, gf = out.get(f"ours a/{d}"), out.get(f"getfem a/{d}")
        if ours and gf:
            ratios[f"a/{d}"] = ours["wall_median_s"] / gf["wall_median_s"]
    return out, ratios


def write_binary(path, write):
    """write(binary file object) into `path` in one rename (common.write_atomic)."""

    def writer(tmp):
        with open(tmp, "wb") as f:
            write(f)

    write_atomic(path, writer)


def plot(path, summary, ratios, n):
    import matplotlib  # only here: the measured processes, not this one, are the subject

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(summary)
    med = [summary[k]["wall_median_s"] for k in names]
    inproc = [summary[k]["in_process_median_s"] for k in names]
    err = [
        [m - summary[k]["wall_min_s"] for k, m in zip(names, med)],
        [summary[k]["wall_max_s"] - m for k, m in zip(names, med)],
    ]
    colors = ["tab:blue" if k.startswith("ours") else "tab:orange" for k in names]
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.bar(names, med, color=colors, alpha=0.45, yerr=err, capsize=4, label="whole process")
    ax.bar(names, inproc, color=colors, label="in-process total (mesh ... post)")
    for i, m in enumerate(med):
        ax.text(i, m, f" {m:.2f} s", ha="left", va="bottom", fontsize=8)
    title = ", ".join(f"ours/GetFEM at {h}: {r:.2f}" for h, r in ratios.items())
    ax.set_title(f"Hertz, whole process wall time (median of {n}); {title}", fontsize=9)
    ax.set_ylabel("wall time (s)")
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    write_binary(path, lambda f: f.write(buf.getvalue()))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=7, help="timed runs of each case (7)")
    ap.add_argument("--out-dir", type=Path, default=ROOT / "benchmarks" / "results")
    ap.add_argument("--no-getfem", action="store_true", help="our cases only")
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds per process (300)")
    a = ap.parse_args(argv)
    if a.n < 1:
        ap.error(f"--n must be >= 1, got {a.n}")
    getfem = not a.no_getfem and importlib.util.find_spec("getfem") is not None
    note = None
    if not getfem:
        note = "--no-getfem" if a.no_getfem else "GetFEM not installed (python3-getfem)"
        print(f"startup: GetFEM cases skipped: {note}")
    todo = cases(getfem)
    names = list(todo)
    a.out_dir.mkdir(parents=True, exist_ok=True)
    load0, runs = os.getloadavg(), []
    with tempfile.TemporaryDirectory(prefix="startup-") as scratch:
        for name in names:  # warm-up, untimed
            side, _, cmd = todo[name]
            run_once(name, side, cmd, scratch, "warm", a.timeout)
        for k in range(a.n):
            order = names[k % len(names) :] + names[: k % len(names)]
            for name in order:
                side, div, cmd = todo[name]
                wall, inproc, err = run_once(name, side, cmd, scratch, k, a.timeout)
                runs.append(
                    dict(
                        case=name,
                        side=side,
                        h_divisor=div,
                        round=k,
                        wall_s=wall,
                        in_process_s=inproc,
                        pressure_rel_l2_error=err,
                    )
                )
                print(f"{name:12s} round {k}: {wall:.3f} s (in-process {inproc:.3f} s)")
    summary, ratios = summarise(runs, names)
    record = dict(
        n=a.n,
        cases={
            k: " ".join(Path(c).name if c.startswith("/") else c for c in v[2])
            for k, v in todo.items()
        },
        summary=summary,
        ratio_ours_to_getfem=ratios,
        getfem_skipped=note,
        loadavg_before=load0,
        loadavg_after=os.getloadavg(),
        cpus=os.cpu_count(),
        runs=runs,
    )
    write_atomic(
        a.out_dir / "startup.json", lambda f: f.write(json.dumps(record, indent=1).encode())
    )

    def write_csv(f):
        text = io.StringIO()
        w = csv.DictWriter(text, fieldnames=list(runs[0]), lineterminator="\n")
        w.writeheader()
        w.writerows(runs)
        f.write(text.getvalue().encode())

    write_atomic(a.out_dir / "startup.csv", write_csv)
    plot(a.out_dir / "startup.png", summary, ratios, a.n)
    for name, s in summary.items():
        print(
            f"{name:12s} wall median {s['wall_median_s']:.3f} s [{s['wall_min_s']:.3f}, "
            f"{s['wall_max_s']:.3f}], in-process {s['in_process_median_s']:.3f} s, "
            f"start-up/imports/output {s['rest_median_s']:.3f} s"
        )
    for h, r in ratios.items():
        print(f"ours / GetFEM at {h}: {r:.2f}")
    print(f"results in {a.out_dir / 'startup.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
