#!/usr/bin/python3
"""Stress table: the demos outside their comfortable settings, penalty against augmented
Lagrangian enforcement, each run judged from its own outputs (exit status, metrics.json,
tractions.csv).

Cases (Hertz: R = 10, E = 1e4, P = 430 at h = a/20 unless said):
* eps0 sweep 1e-4 ... 1e4, both enforcements, both discretizations;
* friction mu = 0.1 ... 10 with a Cattaneo-Mindlin stage (Q = 0.5 mu P);
* grazing (P = 1) and heavy (P = 5000) loads, in one load step;
* the patch test on matching and non-matching (5-on-8, 7-on-8) meshes.
Columns: the case, exit status, p(x) L2 error (or the patch pressure's deviation from the
exact E' d / H), contact half-width a against Hertz, the open points between two active ones
shorter than h (checkerboard, `checks.short_gaps`), the largest penetration / h (point-wise,
and of the law points' weighted mean gaps: metrics.json solver.penetration_h), the solver
warnings, Newton iterations,
augmentations, wall time. Writes benchmarks/results/stress.{csv,md,png}.

Run: /usr/bin/python3 benchmarks/stress.py [--quick] [--only eps0,mu,load,patch]
"""

import argparse
import csv
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from dolfinx_forms.solvers.checks import short_gaps

ROOT = Path(__file__).resolve().parents[1]
EXACT_PATCH = 0.01 / (1 - 0.3**2)


def cases(quick, only):
    eps = (
        [1e-4, 1e-2, 1.0, 1e2, 1e4] if quick else [1e-4, 1e-3, 1e-2, 0.1, 0.5, 1, 10, 100, 1e3, 1e4]
    )
    out = []
    if "eps0" in only:
        for disc in ("conforming", "cut"):
            for enf in ("penalty", "augmented"):
                for e in eps:
                    out.append(
                        (
                            f"eps0 {e:g}",
                            "hertz.py",
                            enf,
                            ["--discretization", disc, "--eps0", f"{e:g}"],
                        )
                    )
    if "mu" in only:
        for enf in ("penalty", "augmented"):
            for mu in [0.1, 1.0] if quick else [0.1, 0.3, 1.0, 10.0]:
                args = ["--mu", f"{mu:g}", "--tangential", "0.5", "--eps0", "0.5"]
                out.append((f"mu {mu:g}", "hertz.py", enf, args))
    if "load" in only:
        for enf in ("penalty", "augmented"):
            for load in (1.0, 5000.0):
                out.append((f"load {load:g}, 1 step", "hertz.py", enf, ["--load", f"{load:g}"]))
    if "patch" in only:
        for enf in ("penalty", "augmented"):
            for cells in (None, 5, 7):
                args = [] if cells is None else ["--upper-cells", str(cells)]
                name = "patch matching" if cells is None else f"patch {cells}-on-8"
                out.append((name, "patch_test.py", enf, args))
    return out


def zone_checks(folder, h):
    """From tractions.csv: short gaps in the contact zone (`checks.short_gaps`, along x) and
    the largest penetration of an active point over h."""
    d = np.genfromtxt(
        folder / "tractions.csv", delimiter=",", names=True, dtype=None, encoding="utf-8"
    )
    active = np.atleast_1d(d["state"] != "open")
    if not active.any():
        return 0, None
    pen = max(0.0, -float(np.atleast_1d(d["gap_n"])[active].min())) / h
    return short_gaps(np.atleast_1d(d["x"]), active, h), pen


def run(case, timeout):
    name, demo, enf, args = case
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "r"
        cmd = [
            sys.executable,
            str(ROOT / "demos" / demo),
            "--out",
            str(out),
            "--enforcement",
            enf,
            *args,
        ]
        t0 = time.perf_counter()
        try:
            r = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, timeout=timeout)
            status = r.returncode
        except subprocess.TimeoutExpired:
            status = "timeout"
        wall = time.perf_counter() - t0
        row = dict(
            case=name,
            demo=demo,
            enforcement=enf,
            args=" ".join(args),
            exit=status,
            wall_s=round(wall, 2),
        )
        if status != 0 or not (out / "metrics.json").exists():
            msg = (
                r.stderr.strip().splitlines()[-1]
                if status != "timeout" and r.stderr.strip()
                else ""
            )
            row["message"] = msg[:160]
            return row
        m = json.loads((out / "metrics.json").read_text())
        res, an, s = m["results"], m["analytic"], m["solver"]
        h = m["mesh"]["h_contact"]
        if demo == "patch_test.py":
            row["error"] = abs(res["pressure_mean"] - EXACT_PATCH) / EXACT_PATCH
            row["spread"] = res.get("pressure_max_rel_deviation")
        else:
            row["error"] = res.get("pressure_rel_l2_error")
            a, a_h = res.get("contact_half_width"), an.get("contact_half_width")
            row["a_rel_error"] = None if a is None or a_h is None else abs(a - a_h) / a_h
            c, c_h = res.get("stick_half_width"), an.get("stick_half_width")
            if c_h:
                row["stick_rel_error"] = None if c is None else abs(c - c_h) / c_h
        row["checkerboard"], row["penetration_over_h"] = zone_checks(out, h)
        # the weighted mean gap of the active law points (augmented: what the multipliers
        # constrain; penalty: the points themselves)
        row["law_penetration_over_h"] = s.get("penetration_h", {}).get("law_points")
        row["warnings"] = len(s.get("warnings", []))
        row["newton"] = sum(s["newton_iterations"])
        row["augmentations"] = sum(s.get("augmentations", []))
        return row


def fmt(v):
    if isinstance(v, float):
        return f"{v:.3g}"
    return "" if v is None else str(v)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer eps0 and mu values")
    ap.add_argument("--only", default="eps0,mu,load,patch", help="comma-separated case groups")
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds per run")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results"))
    a = ap.parse_args()
    rows = []
    for case in cases(a.quick, a.only.split(",")):
        rows.append(run(case, a.timeout))
        r = rows[-1]
        print(" | ".join(f"{k}={fmt(v)}" for k, v in r.items()), flush=True)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    cols = [
        "case",
        "demo",
        "enforcement",
        "args",
        "exit",
        "error",
        "spread",
        "a_rel_error",
        "stick_rel_error",
        "checkerboard",
        "penetration_over_h",
        "law_penetration_over_h",
        "warnings",
        "newton",
        "augmentations",
        "wall_s",
        "message",
    ]
    with open(out / "stress.csv", "w", newline="") as f:
        w = csv.DictWriter(f, cols)
        w.writeheader()
        for r in rows:
            w.writerow({c: fmt(r.get(c)) for c in cols})
    md = ["| " + " | ".join(cols[:-1]) + " |", "|" + "---|" * (len(cols) - 1)]
    md += ["| " + " | ".join(fmt(r.get(c)) for c in cols[:-1]) + " |" for r in rows]
    (out / "stress.md").write_text("\n".join(md) + "\n")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for disc in ("conforming", "cut"):
        for enf, style in (("penalty", "o-"), ("augmented", "s--")):
            pts = [
                (float(r["case"].split()[1]), r["error"])
                for r in rows
                if r["case"].startswith("eps0")
                and enf == r["enforcement"]
                and disc in r["args"]
                and r.get("error") is not None
            ]
            if pts:
                x, y = zip(*pts)
                ax.loglog(x, y, style, label=f"{disc}, {enf}")
    ax.set_xlabel("eps0 (eq 51)")
    ax.set_ylabel("Hertz p(x) relative L2 error")
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "stress.png", dpi=120)
    print(f"results in {out / 'stress.csv'}, {out / 'stress.md'}, {out / 'stress.png'}")


if __name__ == "__main__":
    main()
