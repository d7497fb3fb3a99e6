#!/usr/bin/python3
"""The multi-step (material-point) path at the cost of its linear solves (issue 32, item 4):
the Brazilian disc at the demo's defaults against 50 assembly + LU solves of a plain
elasticity problem of the same dofs, side by side in one run.

One child process runs demos/brazilian_disc.py (its in-process total and phases from
metrics.json); another the reference: Q1 elasticity on a structured square grid with as many
dofs, clamped at its bottom, whose stiffness is assembled, MUMPS-factorised and solved `steps`
times (what one linear solve per load step of that size costs). The reference runs before and
after the demo and the faster of the two counts (the machine is shared). ratio = demo total /
reference total; issue 32 asks for at most 3 (goal 2).

Writes (atomically) <out-dir>/mpm_cost.json, mpm_cost.csv (one row per phase) and
mpm_cost.png. Usage: /usr/bin/python3 benchmarks/mpm_cost.py [--out-dir benchmarks/results]
[--timeout 900] [demo options after --, e.g. -- --steps 20]
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

from benchmarks.common import child, git_head, huge_pages_env, write_json, write_text

ROOT = Path(__file__).resolve().parents[1]


def reference_main(dofs, steps):
    """The reference in this process: prints one JSON line."""
    import numpy as np
    import ufl
    from dolfinx import fem, mesh
    from dolfinx.fem.petsc import assemble_matrix, assemble_vector
    from mpi4py import MPI
    from petsc4py import PETSc

    n = max(2, int(round(np.sqrt(dofs / 2.0))) - 1)  # 2 (n + 1)^2 dofs
    msh = mesh.create_rectangle(
        MPI.COMM_WORLD, [[0.0, 0.0], [1.0, 1.0]], [n, n], mesh.CellType.quadrilateral
    )
    V = fem.VectorFunctionSpace(msh, ("Lagrange", 1))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    E, nu = 1e5, 0.3
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))

    def sigma(w):
        e = ufl.sym(ufl.grad(w))
        return 2 * mu * e + lam * ufl.tr(e) * ufl.Identity(2)

    a = fem.form(ufl.inner(sigma(u), ufl.grad(v)) * ufl.dx)
    L = fem.form(ufl.inner(ufl.as_vector((0.0, -1.0)), v) * ufl.dx)
    bottom = mesh.locate_entities_boundary(msh, 1, lambda x: np.isclose(x[1], 0.0))
    zero = np.zeros(2, dtype=PETSc.ScalarType)
    bc = fem.dirichletbc(zero, fem.locate_dofs_topological(V, 1, bottom), V)
    uh = fem.Function(V)
    t = dict(assembly=0.0, factor=0.0, solve=0.0)
    for _ in range(steps):
        t0 = time.perf_counter()
        A = assemble_matrix(a, bcs=[bc])
        A.assemble()
        b = assemble_vector(L)
        fem.petsc.apply_lifting(b, [a], [[bc]])
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        fem.petsc.set_bc(b, [bc])
        t1 = time.perf_counter()
        ksp = PETSc.KSP().create(msh.comm)
        ksp.setOperators(A)
        ksp.setType("preonly")
        ksp.getPC().setType("lu")
        ksp.getPC().setFactorSolverType("mumps")
        ksp.setUp()
        t2 = time.perf_counter()
        ksp.solve(b, uh.vector)
        t3 = time.perf_counter()
        t["assembly"] += t1 - t0
        t["factor"] += t2 - t1
        t["solve"] += t3 - t2
        ksp.destroy()
        A.destroy()
        b.destroy()
    num = V.dofmap.index_map.size_global * 2
    print(json.dumps(dict(dofs=num, steps=steps, total=sum(t.values()), **t)))
    return 0


def reference(dofs, steps, timeout):
    cmd = [str(ROOT / "benchmarks" / "mpm_cost.py"), "--reference", str(dofs), str(steps)]
    rc, so, se, _, rss = child(cmd, timeout, huge_pages_env())  # the demo's allocator
    if rc:
        raise RuntimeError(f"reference failed: {se.strip().splitlines()[-1:]}")
    return dict(json.loads(so.strip().splitlines()[-1]), peak_rss_mb=rss)


def plot(result, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    phases = {k: v for k, v in result["demo"]["phases"].items() if k != "total"}
    ref = result["reference"]
    fig, ax = plt.subplots(figsize=(7, 3.2))
    left = 0.0
    for k, v in phases.items():
        ax.barh(1, v, left=left, label=k)
        left += v
    left = 0.0
    for k in ("assembly", "factor", "solve"):
        ax.barh(0, ref[k], left=left, hatch="//", label=f"reference {k}")
        left += ref[k]
    ax.set_yticks([0, 1], [f"{ref['steps']} LU solves", "Brazilian disc"])
    ax.set_xlabel("seconds (in-process)")
    ax.set_title(f"MPM step cost: {result['ratio']:.2f}x the linear solves ({ref['dofs']} dofs)")
    ax.legend(fontsize=7, ncol=3, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    extra = argv[argv.index("--") + 1 :] if "--" in argv else []
    argv = argv[: argv.index("--")] if "--" in argv else argv
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out-dir", default=str(ROOT / "benchmarks" / "results"))
    ap.add_argument("--timeout", type=float, default=900.0)
    ap.add_argument("--reference", nargs=2, type=int, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.reference:
        return reference_main(*args.reference)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "disc"
        demo = [str(ROOT / "demos" / "brazilian_disc.py"), "--out", str(out), *extra]
        rc, so, se, wall, rss = child(demo, args.timeout, huge_pages_env())
        if rc:
            print(se, file=sys.stderr)
            return 1
        m = json.loads((out / "metrics.json").read_text())
    steps = m["solver"]["load_steps"]
    dofs = m["mesh"]["num_dofs"]
    refs = [reference(dofs, steps, args.timeout) for _ in range(2)]
    ref = min(refs, key=lambda r: r["total"])
    t = m["timing_s"]
    result = dict(
        git=git_head(),
        environment=huge_pages_env(),  # both children's (the demo's start-up restart)
        demo=dict(
            args=extra,
            dofs=dofs,
            steps=steps,
            newton_per_step=sum(m["solver"]["newton_iterations"]) / steps,
            factorisations=sum(m["solver"]["factorisations"]),
            phases=t,
            wall=wall,
            peak_rss_mb=rss,
        ),
        reference=ref,
        reference_runs=[r["total"] for r in refs],
        ratio=t["total"] / ref["total"],
    )
    d = Path(args.out_dir)
    write_json(d / "mpm_cost.json", result)
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(["phase", "seconds", "per_step", "fraction_of_reference"])
    for k, v in t.items():
        w.writerow([k, f"{v:.4f}", f"{v / steps:.5f}", f"{v / ref['total']:.4f}"])
    write_text(d / "mpm_cost.csv", buf.getvalue())
    plot(result, d / "mpm_cost.png")
    print(
        f"Brazilian disc: {t['total']:.2f} s in-process ({steps} steps, {dofs} dofs); "
        f"{steps} assembly + LU solves: {ref['total']:.2f} s; ratio {result['ratio']:.2f}"
    )
    print("phases: " + ", ".join(f"{k} {v:.2f}" for k, v in t.items() if k != "total"))
    print(f"results in {d}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
