#!/usr/bin/python3
"""Grain assemblies as N grows (issue 32, item 4): time per compression step, its phases and
the peak memory of demos/grain_assembly.py for N grains on 1 and 2 ranks, side by side in one
run.

Each (N, ranks) runs the demo in a child process (under mpirun for ranks > 1) with its
defaults, `--steps` compression steps and no shear; the demo's in-process phase timings
(metrics.json, rank 0) give the time per step, the children's getrusage their peak resident
memory (summed over the ranks). growth = (t_step(N) / t_step(N0)) / (N / N0) for the smallest
N0 run on the same ranks: at most 1 is linear growth in N, the issue's bound.

Writes (atomically) <out-dir>/grain_scaling.json, grain_scaling.csv and grain_scaling.png.
Usage: /usr/bin/python3 benchmarks/grain_scaling.py [--grains 100,300] [--ranks 1,2]
       [--steps 5] [--out-dir benchmarks/results] [--timeout 3600]
Timings on a shared machine are noisy: compare the ratios of one run.
"""

import argparse
import csv
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from benchmarks.common import WRAP, git_head, write_json, write_text

ROOT = Path(__file__).resolve().parents[1]
PHASES = ("mesh", "assembly", "contact", "solve", "mls", "points", "evolution")


def run(grains, ranks, steps, timeout, tmp):
    """One demo run: its metrics summary, or an error entry."""
    out = Path(tmp) / f"grains_{grains}_{ranks}"
    script = [str(ROOT / "demos" / "grain_assembly.py"), "--grains", str(grains)]
    script += ["--steps", str(steps), "--shear-steps", "0", "--out", str(out)]
    cmd = [sys.executable, "-c", WRAP, *script]
    env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1")
    if ranks > 1:
        mpirun = shutil.which("mpirun")
        if mpirun is None:
            return dict(grains=grains, ranks=ranks, error="mpirun not found")
        cmd = [mpirun, "-n", str(ranks), *cmd]
        if os.geteuid() == 0:
            env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
        env["OMPI_MCA_rmaps_base_oversubscribe"] = "1"
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=timeout)
    except subprocess.TimeoutExpired:
        return dict(grains=grains, ranks=ranks, error=f"timeout after {timeout} s")
    wall = time.perf_counter() - t0
    if p.returncode:
        return dict(grains=grains, ranks=ranks, error=p.stderr.strip().splitlines()[-1:])
    rss = [int(x.split()[1]) for x in p.stderr.splitlines() if x.startswith("peak_rss_kb ")]
    m = json.loads((out / "metrics.json").read_text())
    t = m["timing_s"]
    return dict(
        grains=grains,
        ranks=ranks,
        steps=steps,
        dofs=m["mesh"]["num_dofs"] if "mesh" in m else None,
        newton_per_step=sum(m["solver"]["newton_iterations"]) / steps,
        factorisations=sum(m["solver"]["factorisations"]),
        # what besides Newton's iterations factorises: cut-backs, split steps, wider sparsity
        cutbacks=m["solver"].get("cutbacks", 0),
        substeps=sum(m["solver"].get("substeps", [])),
        coupling_rebuilds=sum(m["solver"].get("coupling_rebuilds", [])),
        total=t["total"],
        step=t["total"] / steps,
        **{f"step_{k}": t.get(k, 0.0) / steps for k in PHASES},
        wall=wall,
        # every rank's peak, or None if one did not report it (not a sum that reads 0 MB)
        peak_rss_mb=sum(rss) / 1024 if len(rss) == ranks else None,
    )


def plot(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    ranks = sorted({x["ranks"] for x in rows})
    for r in ranks:
        sel = sorted((x for x in rows if x["ranks"] == r), key=lambda x: x["grains"])
        n = [x["grains"] for x in sel]
        a.loglog(n, [x["step"] for x in sel], "o-", label=f"{r} rank(s)")
        if r == ranks[0] and sel:  # the phases of the fewest ranks run (a 2-rank run alone)
            a.loglog(n, [sel[0]["step"] * k / n[0] for k in n], "k:", label="linear in N")
            bottom = [0.0] * len(sel)
            for k in PHASES:
                v = [x[f"step_{k}"] for x in sel]
                b.bar([str(x) for x in n], v, bottom=bottom, label=k)
                bottom = [p + q for p, q in zip(bottom, v)]
    a.set_xlabel("grains N")
    a.set_ylabel("seconds per compression step")
    a.legend()
    b.set_xlabel(f"grains N ({ranks[0] if ranks else 1} rank(s))")
    b.set_ylabel("seconds per step, by phase")
    b.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grains", default="100,300")
    ap.add_argument("--ranks", default="1,2")
    ap.add_argument("--steps", type=int, default=5)
    ap.add_argument("--out-dir", default=str(ROOT / "benchmarks" / "results"))
    ap.add_argument("--timeout", type=float, default=3600.0)
    args = ap.parse_args(argv)
    grains = [int(x) for x in args.grains.split(",")]
    ranks = [int(x) for x in args.ranks.split(",")]
    rows, errors = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for r in ranks:
            for n in grains:
                row = run(n, r, args.steps, args.timeout, tmp)
                (errors if "error" in row else rows).append(row)
                print(row, flush=True)
    for r in ranks:
        sel = sorted((x for x in rows if x["ranks"] == r), key=lambda x: x["grains"])
        for x in sel:
            x["growth"] = (x["step"] / sel[0]["step"]) / (x["grains"] / sel[0]["grains"])
    for x in rows:
        one = [y for y in rows if y["ranks"] == 1 and y["grains"] == x["grains"]]
        x["speedup"] = one[0]["step"] / x["step"] if one else None
    d = Path(args.out_dir)
    write_json(d / "grain_scaling.json", dict(git=git_head(), runs=rows, errors=errors))
    buf = io.StringIO()
    if rows:
        w = csv.DictWriter(buf, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    write_text(d / "grain_scaling.csv", buf.getvalue())
    if rows:
        plot(rows, d / "grain_scaling.png")
    for x in rows:
        mb = x["peak_rss_mb"]
        print(
            f"N = {x['grains']:5d}, {x['ranks']} rank(s): {x['step']:.2f} s/step "
            f"(growth {x['growth']:.2f}, speed-up {x['speedup'] or 0:.2f}), "
            + (f"{mb:.0f} MB" if mb is not None else "peak memory not read")
        )
    print(f"results in {d}")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
