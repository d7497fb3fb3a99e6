#!/usr/bin/python3
"""The studies behind the tuned numbers of dolfinx_forms/defaults.py: each value swept on the
case it was tuned on and on a case it was not, side by side.

The tuned case: Hertz (demos/hertz.py) at R = 10 mm, h = a/20, both paths. The check case:
the same at R = 40 mm (a about twice as wide, h = a/20 of it: another mesh, another load per
unit length of contact). Normal factors (pointwise_eps0, consistent_eps0, consistent_length,
hybrid_closed_fraction, edge_offset): the augmented Lagrangian's p(x) L2 error against Hertz
and against the circle. Tangential factors (pointwise_eps0_t, consistent_eps0_t): Cattaneo-Mindlin
(--tangential 0.5 --mu 0.3), the stick half-width's relative error and q(x)'s L2 error.
augmented_eps0: the Uzawa updates (its only effect: the answer does not depend on it).
Runs in-process (demos/hertz.py's `solve`), one value at a time through
`dataclasses.replace(defaults.TUNING, ...)`.

Writes <out-dir>/calibration.json, calibration.csv and calibration.png; prints a table.

Run: PYTHONPATH=$PWD /usr/bin/python3 benchmarks/calibration.py [--constant NAME] [--quick]
"""

import argparse
import csv
import dataclasses
import io
import json
import sys
from pathlib import Path
from types import SimpleNamespace

from benchmarks.common import git_head, hertz_demo, write_atomic, write_json, write_text
from dolfinx_forms import defaults
from dolfinx_forms.app.demo import Run

ROOT = Path(__file__).resolve().parents[1]
AUGMENTED = ["--enforcement", "augmented"]
LUMPED = [*AUGMENTED, "--multiplier-mass", "lumped"]
MINDLIN = ["--tangential", "0.5", "--mu", "0.3"]
# constant -> (values swept, the demo arguments that use it, the measures)
SWEEPS = {
    "pointwise_eps0": ([0.5, 1.0, 2.0, 5.0], LUMPED, "normal"),
    "consistent_eps0": ([0.5, 1.0, 1.5, 2.0], AUGMENTED, "normal"),
    "consistent_length": ([1.0, 1.25, 1.5, 2.0], AUGMENTED, "normal"),
    "hybrid_closed_fraction": ([0.5, 0.75, 1.0], AUGMENTED, "normal"),
    "pointwise_eps0_t": ([1.25, 1.5, 2.0], [*LUMPED, *MINDLIN], "tangential"),
    "consistent_eps0_t": ([0.75, 1.0, 1.5], [*AUGMENTED, *MINDLIN], "tangential"),
    "edge_offset": ([0.0, 0.15, 0.27, 0.4, 0.5], AUGMENTED, "normal"),
    "augmented_eps0": ([1e-2, 1.0, 1e2], AUGMENTED, "speed"),
}
CASES = {"tuned R=10": ["--R", "10"], "check R=40": ["--R", "40"]}
PATHS = {"body-fitted": [], "cut": ["--discretization", "cut"]}


def measure(argv):
    """One in-process Hertz run: its errors, Newton iterations and Uzawa updates."""
    hertz = hertz_demo()
    args = hertz.parse(argv + ["--out", str(ROOT / "results" / "calibration-unused")])
    if "--eps0" not in argv and "--enforcement" in argv:  # the demos' default, read now
        args.eps0 = defaults.TUNING.augmented_eps0
    run = Run("hertz", vars(args), plot=False)
    hertz.solve(run, SimpleNamespace(**vars(args)))
    run.close()
    r, a, s = run.metrics["results"], run.metrics["analytic"], run.metrics["solver"]
    out = dict(
        p_l2=r["pressure_rel_l2_error"],
        p_l2_circle=r["pressure_rel_l2_error_circle"],
        newton=sum(s["newton_iterations"]),
        uzawa=sum(s.get("augmentations") or [0]),  # Uzawa updates over the stages
        dofs=run.metrics["mesh"]["num_dofs"],
    )
    if "stick_half_width_circle" in a:
        out["stick_rel"] = r["stick_half_width"] / a["stick_half_width_circle"] - 1
        out["q_l2"] = r.get("traction_rel_l2_error_circle", r.get("traction_rel_l2_error"))
    return out


def sweep(name, quick):
    values, extra, kind = SWEEPS[name]
    chosen = getattr(defaults.TUNING, name)
    rows = []
    for value in values[1:3] if quick else values:
        defaults.TUNING = dataclasses.replace(defaults.TUNING, **{name: value})
        try:
            for case, case_args in CASES.items():
                for path, path_args in PATHS.items():
                    argv = [*case_args, *path_args, *extra]
                    try:
                        rec = measure(argv)
                    except Exception as e:  # a setting that fails is a finding, not a crash
                        rec = dict(error=f"{type(e).__name__}: {e}")
                    rows.append(dict(constant=name, value=value, chosen=value == chosen,
                                     kind=kind, case=case, path=path, **rec))
                    print(json.dumps(rows[-1]), flush=True)
        finally:
            defaults.TUNING = dataclasses.replace(defaults.TUNING, **{name: chosen})
    return rows


def plot(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(dict.fromkeys(r["constant"] for r in rows))
    fig, axes = plt.subplots(1, len(names), figsize=(3.6 * len(names), 3.4), squeeze=False)
    for ax, name in zip(axes[0], names):
        mine = [r for r in rows if r["constant"] == name and "error" not in r]
        key = {"normal": "p_l2_circle", "tangential": "stick_rel", "speed": "uzawa"}[
            mine[0]["kind"] if mine else "normal"
        ]
        for case in CASES:
            for p, mk in zip(PATHS, "os"):
                rr = [r for r in mine if r["case"] == case and r["path"] == p]
                y = [abs(r[key]) * (1 if key == "uzawa" else 100) for r in rr]
                ls = "-" if case.startswith("tuned") else "--"
                ax.plot([r["value"] for r in rr], y, mk + ls, label=f"{case}, {p}")
        ax.axvline(getattr(defaults.TUNING, name), color="0.6", ls=":")
        ax.set(title=name, xlabel="value", ylabel=key + ("" if key == "uzawa" else " (%)"))
        if name == "augmented_eps0":
            ax.set_xscale("log")
    axes[0][0].legend(fontsize=6)
    fig.tight_layout()
    write_atomic(path, lambda tmp: fig.savefig(tmp, dpi=100, format="png"))
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--constant", choices=list(SWEEPS), action="append")
    ap.add_argument("--quick", action="store_true", help="two values per constant")
    ap.add_argument("--out-dir", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    rows = [r for name in (a.constant or SWEEPS) for r in sweep(name, a.quick)]
    a.out_dir.mkdir(parents=True, exist_ok=True)
    write_json(a.out_dir / "calibration.json", dict(git=git_head(), rows=rows))
    buf = io.StringIO()
    cols = list(dict.fromkeys(k for r in rows for k in r))
    w = csv.DictWriter(buf, fieldnames=cols, lineterminator="\n")
    w.writeheader()
    w.writerows(rows)
    write_text(a.out_dir / "calibration.csv", buf.getvalue())
    plot(rows, a.out_dir / "calibration.png")
    print(f"results in {a.out_dir}/calibration.{{json,csv,png}}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
