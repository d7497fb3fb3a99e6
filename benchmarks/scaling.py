#!/usr/bin/python3
"""Scaling of the frictionless Hertz run with the mesh size, on both paths, against one linear
elastic solve of the same mesh (issue 12, item 6).

For h = a/20, a/40, a/80, ... (a: the Hertz half-width of the demo defaults, ~1 mm) and each
path, one subprocess runs demos/hertz.py with its defaults (force control in Newton, the bulk
factorised once where it applies, lean meshes) and a second one the reference: the same scene,
the bulk matrix assembled with its Dirichlet rows eliminated, one MUMPS LU factorisation and
one solve (what a user pays for a linear elastic problem on that mesh). Recorded per run: dofs,
contact (Schur) dofs, the demo's phase times, Newton iterations, factorisations, the p(x)
error, the peak resident memory of the process (getrusage of the child) and the reference's
assembly / factorisation / solve times. ratio = (demo total - mesh) / (reference assembly +
factorisation + solve): the price of contact over a linear solve of the same mesh.

Writes (atomically) <out-dir>/scaling.json, scaling.csv, scaling.png.
Usage: /usr/bin/python3 benchmarks/scaling.py [--divisors 20,40,80,160] [--paths conforming,cut]
                                              [--out-dir benchmarks/results] [--timeout 900]
Timings on a shared machine are noisy: compare the ratios of one run.
"""

import argparse
import csv
import io
import json
import sys
import tempfile
import time
from pathlib import Path
from types import SimpleNamespace

from benchmarks.common import child, hertz_demo, write_atomic, write_text


ROOT = Path(__file__).resolve().parents[1]


def measure(discretization, divisor, timeout, tmp):
    out = Path(tmp) / f"hertz_{discretization}_{divisor}"
    cmd = [str(ROOT / "benchmarks" / "scaling.py"), "--reference"]
    rc, so, se, _, rss_ref = child(cmd + [discretization, str(divisor)], timeout)
    if rc:
        return dict(path=discretization, divisor=divisor, error=se.strip().splitlines()[-1:])
    ref = json.loads(so.strip().splitlines()[-1])
    h = ref.pop("h")
    demo = [str(ROOT / "demos" / "hertz.py"), "--out", str(out), "--h", repr(h)]
    rc, so, se, wall, rss = child(demo + ["--discretization", discretization], timeout)
    if rc:
        return dict(path=discretization, divisor=divisor, error=se.strip().splitlines()[-1:])
    m = json.loads((out / "metrics.json").read_text())
    t, s = m["timing_s"], m["solver"]
    linear = ref["setup_assembly"] + ref["factor"] + ref["solve"]
    return dict(
        path=discretization,
        divisor=divisor,
        h=h,
        dofs=m["mesh"]["num_dofs"],
        contact_dofs=s.get("condensed_dofs", 0),
        linear_solver=s.get("linear_solver"),
        newton=sum(s["newton_iterations"]),
        factorisations=s["factorisations"],
        schur_updates=s.get("schur_factorisations", 0),
        pressure_error=m["results"]["pressure_rel_l2_error"],
        total=t["total"],
        **{f"t_{k}": t[k] for k in ("mesh", "assembly", "contact", "solve")},
        wall=wall,
        peak_rss_mb=rss,
        ref_peak_rss_mb=rss_ref,
        ref_assembly=ref["setup_assembly"],
        ref_factor=ref["factor"],
        ref_solve=ref["solve"],
        ratio=(t["total"] - t["mesh"]) / linear,
    )


def reference_main(discretization, divisor):
    from mpi4py import MPI

    from dolfinx_forms.io.results import PhaseTimer, new_metrics

    hertz = hertz_demo()

    metrics = new_metrics("reference", discretization, {})
    timer = PhaseTimer(metrics)
    args = vars(hertz.parse(["--discretization", discretization]))
    a = hertz.estimate(args)[1]
    r = _reference_timed(discretization, divisor, timer)
    r["h"] = a / divisor
    if MPI.COMM_WORLD.rank == 0:
        print(json.dumps(r))


def _reference_timed(discretization, divisor, timer):
    """One linear elastic solve of the demo's mesh, timed (the ContactProblem's assembly phase:
    K; then one MUMPS LU factorisation and one solve)."""
    from mpi4py import MPI
    from petsc4py import PETSc

    from dolfinx_forms.fem.boundary import Dirichlet
    from dolfinx_forms.solvers.options import options
    from dolfinx_forms.solvers.problem import ContactProblem

    hertz = hertz_demo()
    p = vars(hertz.parse(["--discretization", discretization]))
    p["h"] = hertz.estimate(p)[1] / divisor
    sc = hertz.scene(MPI.COMM_WORLD, SimpleNamespace(**p))
    bcs = [Dirichlet("block_bottom", None, 0.0), Dirichlet("cylinder_top", None, -0.01)]
    laws = {b.tag: (p["E"], p["nu"]) for b in sc.bodies}
    pb = ContactProblem(sc, laws, dirichlet=bcs, timer=timer, **options(linear_solver="factorised"))
    t0 = time.perf_counter()
    K = pb.K.copy()
    K.zeroRows(pb.bc_global, diag=1.0)
    ksp = PETSc.KSP().create(MPI.COMM_WORLD)
    ksp.setOperators(K)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    b = K.createVecLeft()
    b.set(1.0)
    x = b.duplicate()
    ksp.setUp()
    t_factor = time.perf_counter() - t0
    t0 = time.perf_counter()
    ksp.solve(b, x)
    return dict(
        dofs=pb.num_dofs,
        setup_assembly=timer.timing["assembly"],
        factor=t_factor,
        solve=time.perf_counter() - t0,
    )


def plot(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for p, mk in (("conforming", "o"), ("cut", "s")):
        rr = [r for r in rows if r["path"] == p and "dofs" in r]
        if not rr:
            continue
        n = [r["dofs"] for r in rr]
        ax[0].loglog(n, [r["total"] - r["t_mesh"] for r in rr], mk + "-", label=f"{p}: Hertz run")
        ax[0].loglog(
            n,
            [r["ref_assembly"] + r["ref_factor"] + r["ref_solve"] for r in rr],
            mk + "--",
            label=f"{p}: one linear solve",
        )
        ax[1].semilogx(n, [r["ratio"] for r in rr], mk + "-", label=p)
    ax[0].set(xlabel="dofs", ylabel="time without meshing (s)")
    ax[1].set(xlabel="dofs", ylabel="Hertz run / one linear solve")
    ax[1].axhline(3.0, color="gray", lw=0.8)
    for a in ax:
        a.legend(fontsize=8)
        a.grid(True, which="both", lw=0.3)
    fig.tight_layout()
    write_atomic(path, lambda tmp: fig.savefig(tmp, dpi=120, format="png"))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--divisors", default="20,40,80,160")
    ap.add_argument("--paths", default="conforming,cut")
    ap.add_argument("--out-dir", default=str(ROOT / "benchmarks" / "results"))
    ap.add_argument("--timeout", type=float, default=900.0)
    ap.add_argument("--reference", nargs=2, metavar=("PATH", "DIVISOR"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.reference:
        return reference_main(args.reference[0], int(args.reference[1]))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for d in (int(x) for x in args.divisors.split(",")):
            for path in args.paths.split(","):
                r = measure(path, d, args.timeout, tmp)
                rows.append(r)
                print(json.dumps(r), flush=True)
    out = Path(args.out_dir)
    write_text(out / "scaling.json", json.dumps(rows, indent=1))
    keys = list(dict.fromkeys(k for r in rows for k in r))
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=keys)
    w.writeheader()
    w.writerows(rows)
    write_text(out / "scaling.csv", buf.getvalue())
    plot(rows, out / "scaling.png")
    print(f"results in {out}/scaling.{{json,csv,png}}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
