"""Studies over mesh sizes: run a demo once per size in its own process, fit convergence rates,
plot and tabulate the errors, and write the study's folder atomically.

    rec = run_demo("demos/hertz.py", ["--h", "0.05"], cwd=repository, evaluate=errors_of)
    summary = convergence(runs, ("pressure_rel_l2_error",), checked="pressure_rel_l2_error",
                          label="p(x) L2 error", min_rate=0.75)

A run record (a dict) holds `h`, `command`, `wall_s`, `returncode`, `ok` and, when the demo
succeeded, what `evaluate(metrics)` returned (`run_summary` gives the common part: dofs,
cells, phase times, Newton iterations) or else `error` (one line). Used by
demos/convergence_study.py and benchmarks/work_precision.py.
"""

import json
import math
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from dolfinx_forms.analysis import analytic

__all__ = [
    "PHASES",
    "run_demo",
    "run_summary",
    "relative_errors",
    "loglog_rate",
    "decreasing",
    "convergence",
    "run_line",
    "plot_errors",
    "print_errors",
    "write_study",
    "CASE",
    "VARIANTS",
    "BULKS",
    "PATHS",
    "ENFORCEMENTS",
    "VARIANT",
    "bulk_args",
    "CONVERGENCE_DEFINITIONS",
    "ERRORS",
    "CIRCLE_ERROR",
    "ERROR_LABELS",
    "variant_path",
    "hertz_reference",
    "hertz_errors",
    "run_hertz",
]

PHASES = ("mesh", "assembly", "contact", "solve")  # metrics.json timing_s, without total


def last_line(text, fallback):
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    return lines[-1] if lines else fallback


def run_demo(
    script,
    args=(),
    *,
    cwd,
    evaluate,
    timeout=None,
    keep=None,
    files=("metrics.json", "tractions.csv"),
):
    """Run `script` (a path relative to `cwd`) with `--out` in a scratch folder and `args`, in
    its own process; returns the run record. evaluate(metrics) -> dict of record fields (it
    raises KeyError, TypeError, ValueError or ZeroDivisionError on an unusable metrics.json:
    the run is then failed). keep: a folder that receives `files` of a successful run."""
    rec = {}
    with tempfile.TemporaryDirectory(prefix=f"{Path(script).stem}_run.") as tmp:
        out = Path(tmp) / Path(script).stem
        cmd = [sys.executable, str(script), "--out", str(out), *args]
        rec["command"] = " ".join(cmd[1:])
        t0 = time.perf_counter()
        try:
            proc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            rec.update(
                ok=False,
                returncode=None,
                wall_s=time.perf_counter() - t0,
                error=f"killed after the {timeout:g} s timeout",
            )
            return rec
        rec["wall_s"] = time.perf_counter() - t0
        rec["returncode"] = proc.returncode
        if proc.returncode != 0:
            rec.update(ok=False, error=last_line(proc.stderr, f"exit status {proc.returncode}"))
            return rec
        try:
            rec.update(ok=True, **evaluate(json.loads((out / "metrics.json").read_text())))
        except (OSError, KeyError, TypeError, ValueError, ZeroDivisionError) as e:
            rec.update(
                ok=False,
                error=f"{Path(script).name} exited 0 but metrics.json is " f"unusable: {e}",
            )
            return rec
        if keep is not None:
            Path(keep).mkdir(parents=True, exist_ok=True)
            for f in files:
                shutil.copy2(out / f, Path(keep) / f)
    return rec


def run_summary(m):
    """The size and cost of a run from its metrics.json: dofs, cells, phase times, Newton."""
    its = m["solver"]["newton_iterations"]
    return dict(
        num_dofs=int(m["mesh"]["num_dofs"]),
        num_cells=int(m["mesh"]["num_cells"]),
        timing_s={k: float(m["timing_s"][k]) for k in ("total", *PHASES)},
        newton_iterations=its,
        newton_iterations_total=int(sum(its)),
        converged=m["solver"].get("converged"),
        cutbacks=m["solver"].get("cutbacks"),
    )


def finite_errors(errors):
    """`errors` ({name: value}) if every value is a finite number, else ValueError."""
    if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in errors.values()):
        raise ValueError(f"non-finite error in metrics.json: {errors}")
    return errors


def relative_errors(m, relative, direct=()):
    """A run's errors against the analytic values of its metrics.json: the computed values
    results[key] and analytic[key] of relative {error name: key}, and errors {name:
    |results[key] - analytic[key]| / analytic[key]} plus the errors `direct` that results
    holds itself. ValueError if an error is not a finite number."""
    res, ana = m["results"], m["analytic"]
    computed, reference = ({k: d[k] for k in relative.values()} for d in (res, ana))
    errors = {e: abs(computed[k] - reference[k]) / reference[k] for e, k in relative.items()}
    errors.update({e: res[e] for e in direct})
    return dict(**computed, analytic=reference, errors=finite_errors(errors))


def loglog_rate(x, y):
    """Least-squares slope of log y vs log x (None with fewer than 2 distinct usable x)."""
    pts = [(xi, yi) for xi, yi in zip(x, y) if xi > 0 and yi > 0]
    if len({xi for xi, _ in pts}) < 2:
        return None
    return float(np.polyfit(np.log([p[0] for p in pts]), np.log([p[1] for p in pts]), 1)[0])


def decreasing(values):
    """Strictly decreasing (None with fewer than 2 values)."""
    return all(b < a for a, b in zip(values, values[1:])) if len(values) > 1 else None


def convergence(runs, errors, checked, label, min_rate, theory=1):
    """Fitted and local (consecutive h) rates in h and monotonicity of each error of the
    successful runs, and the check: `checked` decreases monotonically at a fitted rate
    >= min_rate (label: its name in the criterion)."""
    ok = sorted((r for r in runs if r["ok"]), key=lambda r: -r["h"])  # coarse to fine
    hs = [r["h"] for r in ok]
    out = dict(
        runs_ok=len(ok),
        runs_failed=len(runs) - len(ok),
        rates_vs_h={},
        local_rates_vs_h={},
        errors_decrease_monotonically={},
    )
    for k in errors:
        e = [r["errors"][k] for r in ok]
        out["rates_vs_h"][k] = loglog_rate(hs, e)
        out["local_rates_vs_h"][k] = [
            loglog_rate(hs[i : i + 2], e[i : i + 2]) for i in range(len(ok) - 1)
        ]
        out["errors_decrease_monotonically"][k] = decreasing(e)
    rate = out["rates_vs_h"][checked]
    mono = out["errors_decrease_monotonically"][checked]
    out["check"] = dict(
        criterion=f"{label} decreases monotonically and its fitted rate in h is "
        f">= {min_rate} (theory {theory}), over >= 2 successful runs",
        passed=bool(len(ok) >= 2 and mono and rate is not None and rate >= min_rate),
    )
    return out


def run_line(rec, error, label):
    """One line on a run: its dofs, time and `error` (named `label`), or why it failed."""
    if not rec["ok"]:
        return f"FAILED: {rec['error']}"
    e = rec["errors"][error]
    return f"{rec['num_dofs']} dofs, {rec['timing_s']['total']:.2f} s, {label} {e:.3%}"


def plot_errors(path, panels, labels, title, reference):
    """One log-log panel per group: the errors (labels {key: legend}) in % vs h with their
    fitted rates, and slopes 1 and 2 through the coarsest `reference` error. panels: [(title,
    runs, summary)]; a run's x label is "a/<h_divisor>" over its h."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, NullFormatter

    fig, axes = plt.subplots(
        1, len(panels), figsize=(6 * len(panels), 4.8), squeeze=False, sharey=True
    )
    colors = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple")
    for ax, (name, runs, s) in zip(axes[0], panels):
        ok = sorted((r for r in runs if r["ok"]), key=lambda r: -r["h"])
        for k, color in zip(labels, colors):
            if not ok:
                break
            rate = s["rates_vs_h"][k]
            ax.loglog(
                [r["h"] for r in ok],
                [100 * r["errors"][k] for r in ok],
                "o-",
                color=color,
                label=f"{labels[k]}" + (f" (rate {rate:.2f})" if rate is not None else ""),
            )
        if ok:  # reference slopes through the coarsest reference error
            h = np.array([ok[0]["h"], ok[-1]["h"]])
            e0 = 100 * ok[0]["errors"][reference]
            for slope, ls in ((1, "--"), (2, ":")):
                ax.loglog(
                    h, e0 * (h / h[0]) ** slope, ls, color="k", lw=0.9, label=f"slope {slope}"
                )
        ax.invert_xaxis()  # refinement to the right
        ax.set_xticks([r["h"] for r in ok])
        ax.set_xticklabels([f"a/{r['h_divisor']}\n{r['h']:.3g}" for r in ok])
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("mesh size at the contact h (mm)")
        ax.set_title(name + ("" if s["check"]["passed"] else "  [check failed]"), fontsize=10)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=8)
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axes[0][0].set_ylabel("relative error against Hertz (%)")
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def print_errors(runs, summaries, labels, group="discretization"):
    """The runs as a table (h, dofs, time, the errors labels {key: name}) and per group its
    fitted rates and check."""
    cols = {k: f"{labels[k]} err" for k in labels}
    w = {k: max(8, len(c)) for k, c in cols.items()}
    print(
        f"{group:14} {'h':>8} {'dofs':>8} {'time s':>7} "
        + " ".join(f"{c:>{w[k]}}" for k, c in cols.items())
    )
    for r in runs:
        head = f"{r[group]:14} {r['h']:8.5f}"
        if not r["ok"]:
            print(f"{head}  FAILED: {r['error']}")
            continue
        print(
            f"{head} {r['num_dofs']:8d} {r['timing_s']['total']:7.2f} "
            + " ".join(f"{r['errors'][k]:{w[k]}.3%}" for k in labels)
        )
    for d, s in summaries.items():
        rates = ", ".join(
            f"{labels[k]} " + ("-" if v is None else f"{v:.2f}") for k, v in s["rates_vs_h"].items()
        )
        check = "passed" if s["check"]["passed"] else "FAILED"
        print(f"{d}: rates in h: {rates}; check {check} ({s['check']['criterion']})")


def write_study(out, data, runs=(), runs_from=None, plot=None, *, name="convergence", force=False):
    """The study's folder `out`, replaced atomically (folders.py): runs/<run name>/ copied from
    runs_from/<run name> for the successful runs, plot(path of <name>.png), <name>.json.
    Raises OutputFolderError (one line starting with --out:, nothing written)."""
    from dolfinx_forms.io.folders import OutputFolderError, atomic_output_dir

    try:
        with atomic_output_dir(out, force=force) as tmp:
            for r in runs:
                if r["ok"]:
                    shutil.copytree(Path(runs_from) / r["name"], tmp / "runs" / r["name"])
            if plot is not None:
                plot(tmp / f"{name}.png")
            with open(tmp / f"{name}.json", "w") as f:
                json.dump(data, f, indent=2, allow_nan=False)
                f.write("\n")
    except OutputFolderError:
        raise
    except OSError as e:
        raise OutputFolderError(f"--out: cannot write {out}: {e}") from e


# The Hertz case of demos/hertz.py, run over mesh sizes by demos/convergence_study.py and
# benchmarks/work_precision.py (one runner for both).

# The Hertz case (the defaults of demos/hertz.py), passed explicitly to every run so that the
# mesh sizes a/k placed here and the case solved there cannot drift apart.
CASE = dict(R=10.0, E=1.0e4, nu=0.3, load=430.0)
AL_LUMPED_CUT = [
    "--discretization",
    "cut",
    "--enforcement",
    "augmented",
    "--multiplier-mass",
    "lumped",
]
# Each variant names its settings in full: hertz.py's defaults are the fastest accurate settings
# of each path (meshes/hertz.py path_defaults), which are the variants p1-tri-layers and
# q1-cut-al-z1; p1-tri and q1-cut are the gmsh mesh and the penalty they replaced.
VARIANTS = {  # name -> hertz.py arguments selecting the discretisation
    "p1-tri": ["--mesher", "gmsh"],
    "p2-tri": ["--degree", "2"],
    "p1-quad": ["--quads"],
    "p2-quad": ["--degree", "2", "--quads"],
    "q1-cut": ["--discretization", "cut", "--enforcement", "penalty"],
    # the augmented Lagrangian (P1 multipliers, point-wise traction) on the default meshes,
    # with the lumped projection: the closest pressure (the default hybrid projection zeroes
    # the weighted gap for a coarser one: cut zone 1.0 a, a/20 / a/24 / a/28 1.30 / 0.96 /
    # 0.87 % against 1.11 / 0.78 / 0.75 %)
    "p1-tri-al": ["--mesher", "gmsh", "--enforcement", "augmented", "--multiplier-mass", "lumped"],
    "q1-cut-al": [*AL_LUMPED_CUT, "--zone", "1.2"],
    # the same with the fine zone just covering the contact (hertz.py --zone 1.0 a, default
    # 1.2 a): fewer dofs and, with the augmented Lagrangian, a smaller error against Hertz and
    # the fine reference at every h (a/20 ... a/40: 1.11 / 0.78 / 0.75 / 0.76 / 0.64 % against
    # 1.19 / 0.89 / 0.83 / 0.85 / 0.72 % at 1.2 a, loads 350 and 520 alike); the penalty's error
    # grows there instead (1.92 / 1.67 / 1.44 % against 1.78 / 1.52 / 1.33 % at a/20 ... a/28)
    "q1-cut-al-z1": [*AL_LUMPED_CUT, "--zone", "1.0"],
    # body-fitted P1 triangles meshed in layers around the contact (meshes/layers.py, no gmsh:
    # gmsh's library load and meshing were 0.3-0.5 s of a 0.6 s run at a/20), the fine zone
    # just covering the contact and the size doubling every 2 layers away from it (a/20 ...
    # a/32: 1.03 / 0.86 / 0.80 / 0.66 % against 1.06 / 0.91 / 0.79 / 0.67 % with the demo's
    # zone 1.2 a and slope 0.25, at 2/3 of the dofs)
    "p1-tri-layers": ["--mesher", "layers", "--zone", "1.0", "--grading", "0.5"],
    # the augmented Lagrangian as hertz.py runs it (the hybrid projection) on p1-tri-layers's
    # and q1-cut's meshes: demos/convergence_study.py's augmented runs
    "p1-tri-layers-aug": [
        *("--mesher", "layers", "--zone", "1.0", "--grading", "0.5"),
        *("--enforcement", "augmented"),
    ],
    "q1-cut-aug": ["--discretization", "cut", "--enforcement", "augmented"],
}
# the bulk of a convergence study (demos/convergence_study.py --bulk): hertz.py's own meshes
# ("demo": far cells of 100 h in a 40 a x 20 a block down to a/20, below that shrinking like h^2
# in a block growing as sqrt(a / h): meshes/hertz.py far_cell_size, block_growth), or a bulk
# whose error stays below the contact's at every h ("resolved": cells at most a/4 anywhere near,
# an 80 a x 40 a block; at R = 40, a/80, body-fitted, a finer bulk moves the augmented p(x) error
# by 0.004 %). At R = 40, body-fitted, augmented, a/20 -> a/80: 0.92 -> 0.18 % demo (rate 1.22),
# 0.69 -> 0.17 % resolved (1.08), the demo's at 8.4k dofs at a/20 against 131k. hertz.py's
# former bulk (100 h and the a/20 block at every h) floored it at 0.39 % (rate 0.64;
# docs/demos/convergence_study.md)
BULKS = ("resolved", "demo")
PATHS, ENFORCEMENTS = ("conforming", "cut"), ("penalty", "augmented")
# demos/convergence_study.py's variant of each path and enforcement: hertz.py's own meshes
# (body-fitted: in layers, its default for P1 triangles; gmsh's unstructured meshes move the
# augmented error by up to +-20 % from one h to the next, R = 40: a/40 0.27 %, a/56 0.30 %)
VARIANT = {
    ("conforming", "penalty"): "p1-tri-layers",
    ("cut", "penalty"): "q1-cut",
    ("conforming", "augmented"): "p1-tri-layers-aug",
    ("cut", "augmented"): "q1-cut-aug",
}


def bulk_args(bulk, a, h, cut):
    """hertz.py arguments of the bulk `bulk` (BULKS) for Hertz half-width a and contact size h."""
    if bulk == "demo":
        return []
    sizes = ["--width", repr(80 * a), "--depth", repr(40 * a), "--h-far", repr(max(a / 4, h))]
    return sizes + (["--grading", "1.5"] if cut else [])


ERROR_LABELS = {
    "half_width_rel_error": "a",
    "peak_pressure_rel_error": "p0",
    "pressure_rel_l2_error": "p(x) L2",
}
ERRORS = tuple(ERROR_LABELS)
# p(x) against the circle to O((a/R)^4) (`compare.hertz`): recorded with a run when its
# metrics.json has it (not a GetFEM run's), so work_precision's ERRORS stay comparable
CIRCLE_ERROR = "pressure_rel_l2_error_circle"
RELATIVE = {
    "half_width_rel_error": "contact_half_width",
    "peak_pressure_rel_error": "peak_pressure",
}
# metrics.json parameters recorded with each run (the settings that change the errors)
HERTZ_PARAMETERS = "discretization degree quads eps0 ghost_penalty grid_refine gauss width depth"


# the measures of demos/convergence_study.py's convergence.json
CONVERGENCE_DEFINITIONS = dict(
    errors_definition=dict(
        half_width_rel_error="|a - a_H| / a_H, a: half the distance between the zeros of the "
        "interpolated gap at the two ends of the active zone, a_H: Hertz at the computed load",
        peak_pressure_rel_error="|p0 - p0_H| / p0_H, p0: the largest point pressure",
        pressure_rel_l2_error="||p - p_H|| / ||p_H|| over the contact points "
        "(results.pressure_rel_l2_error of metrics.json)",
        pressure_rel_l2_error_circle="||p - p_C|| / ||p_C||, p_C: the circle's pressure to "
        "O((a/R)^4) at the computed load (analytic.circle_pressure; "
        "results.pressure_rel_l2_error_circle)",
    ),
    rates_definition="rates_vs_h: least-squares slope of log(error) vs log(h) over the "
    "successful runs (positive: converging); local_rates_vs_h: the slope between consecutive sizes",
)


def variant_path(variant):
    """'cut' or 'conforming': the discretisation path of a variant."""
    return "cut" if "cut" in VARIANTS[variant] else "conforming"


def _case(case):
    """CASE updated with `case` (a dict of some of its keys, or None)."""
    return {**CASE, **(case or {})}


def hertz_reference(case=None):
    """Hertz half-width and peak pressure of CASE (updated with `case`) at the requested load."""
    c = _case(case)
    E_star = analytic.effective_modulus(c["E"], c["nu"], c["E"], c["nu"])
    a, p0 = analytic.hertz_line(c["load"], c["R"], E_star)
    return float(a), float(p0)


def hertz_errors(m):
    """The run record of a hertz.py metrics.json: its settings, size and cost, a, p0, Hertz at
    the computed load and the errors (ERRORS)."""
    direct = ERRORS[2:] + ((CIRCLE_ERROR,) if CIRCLE_ERROR in m.get("results", {}) else ())
    prm, errors = m.get("parameters", {}), relative_errors(m, RELATIVE, direct)
    settings = {k: prm.get(k) for k in HERTZ_PARAMETERS.split()}
    return dict(hertz_parameters=settings, **run_summary(m), **errors)


def run_hertz(script, h, variant_args=(), timeout=None, keep=None, case=None):
    """Run the Hertz demo `script` (demos/hertz.py: the caller names it, the package does not
    know the repository's scripts) on CASE (updated with `case`), mesh size h at the contact,
    extra arguments, in its own process (run_demo, from the script's repository); `keep`: a
    folder that receives its metrics.json and tractions.csv."""
    script = Path(script).resolve()
    root = script.parents[1]
    args = ["--h", repr(h), *(a for k, v in _case(case).items() for a in (f"--{k}", repr(v)))]
    args = [*args, *variant_args]
    rec = run_demo(
        script.relative_to(root), args, cwd=root, evaluate=hertz_errors, timeout=timeout, keep=keep
    )
    return dict(h=h, **rec)
