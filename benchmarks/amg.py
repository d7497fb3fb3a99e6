#!/usr/bin/python3
"""The iterative linear solver (CG + GAMG with the rigid-body modes, dolfinx_forms.solvers.linear.
Iterative) against the direct ones on Hertz, and its iteration counts against the smallest cut
fraction (issue 12, item 5).

Table "hertz": per path (conforming, cut) and mesh divisor (h = a/divisor, the demo's scene
otherwise), one subprocess per solver runs demos/hertz.py's scene, problem and stages
(frictionless, force control): "direct" is today's choice (the condensed bulk, else a MUMPS
LU per changed J), "iterative" the AMG solver (GAMG), "hypre" the same with BoomerAMG (HYPRE),
"factorised" a MUMPS LU per changed J (what a nonlinear law, slip or MPI get today).
Recorded: dofs, Newton iterations, AMG set-ups, Krylov iterations per solve (mean, max),
solve-phase and total time (without meshing), AMG set-up and Krylov time, peak resident
memory, p(x) error and reaction P, and for the other solvers the differences to the direct
one: |u - u_direct|_max / |u_direct|_max, the p(x) error and P, and the time ratios.

Table "cuts": the contact patch test of benchmarks/small_cuts.py (`patch_cut_scene`, the
interface at y = (k + eta) h so that the lower body's top row has inside fraction eta) on an
n x n grid, solved with linear_solver="iterative", for eta = 0.5 ... 1e-8, ghost penalty
gamma in {0, 0.01 (default), 0.1}, the patch test's penalty eps0 = 1e-3 and Hertz's 0.5, and
three set-ups: "tuned" (GAMG, linear.ITERATIVE_OPTIONS), "petsc" (PETSc's GAMG defaults with
the same near-null space) and "hypre" (BoomerAMG, HYPRE). Recorded: Krylov iterations per
solve (max, mean), Newton iterations, failure.

Table "bodies": where GAMG stalls on the cut Hertz (`bodies_table`): iterations on the whole
Jacobian and on each body's block, for the demo's grid grading and a milder one.

Writes (atomically) <out-dir>/amg.json, amg_hertz.csv, amg_cuts.csv, amg_bodies.csv, amg.png.
Usage: /usr/bin/python3 benchmarks/amg.py [--conforming 20,40,80,160,190] [--cut 20,40,80,160]
           [--conforming-solvers direct,iterative,factorised] [--cut-solvers direct,iterative,hypre]
           [--n 60] [--quick] [--skip-hertz] [--skip-cuts]
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

import numpy as np

from benchmarks.common import child, git_head, hertz_demo, write_atomic, write_text

ROOT = Path(__file__).resolve().parents[1]

ETAS = (0.5, 1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
GAMMAS = (0.0, 0.01, 0.1)
EPS0S = (1e-3, 0.5)
# PETSc's GAMG defaults (3.18), to set against linear.ITERATIVE_OPTIONS
PETSC_GAMG = {
    "pc_gamg_threshold": "0",
    "pc_gamg_use_sa_esteig": "1",
    "mg_levels_ksp_chebyshev_esteig_steps": "10",
}
# the remedy tried for the cut path: BoomerAMG (no near-null space), HMIS coarsening, ext+i
# interpolation, strong threshold 0.7 (0.25, hypre's 2D default: 219 iterations on the cut
# Hertz at 28k dofs, 0.7: 75; GAMG: 428)
HYPRE = {
    "pc_type": "hypre",
    "pc_hypre_boomeramg_strong_threshold": "0.7",
    "pc_hypre_boomeramg_coarsen_type": "HMIS",
    "pc_hypre_boomeramg_interp_type": "ext+i",
    "pc_hypre_boomeramg_P_max": "4",
}
SETUPS = {"tuned": None, "petsc": PETSC_GAMG, "hypre": HYPRE}


# --------------------------------------------------------------------------- hertz
def hertz_child(path, divisor, solver, npy):
    """One Hertz run in this process; prints a JSON record, saves u to npy."""
    from dolfinx_forms.app.demo import Run

    hertz = hertz_demo()
    kinds = {"direct": ["condensed", "factorised"], "hypre": ["iterative"]}.get(solver, [solver])
    for kind in kinds:
        p = vars(hertz.parse(["--discretization", path, "--linear-solver", kind]))
        p["h"] = hertz.estimate(p)[1] / divisor
        p["petsc"] = HYPRE if solver == "hypre" else {}
        try:
            run = Run("hertz", p, plot=False)
            hertz.solve(run, SimpleNamespace(**p))
            run.close()
            break
        except ValueError as e:  # condensed does not apply: a full factorisation
            if "does not apply" not in str(e):
                raise
    pb, m = run.problem, run.metrics
    np.save(npy, pb.u.x.array)
    its = list(getattr(pb.linear, "iterations", []))
    t = m["timing_s"]
    print(
        json.dumps(
            dict(
                path=path,
                divisor=divisor,
                solver=solver,
                linear_solver=pb.linear.name,
                dofs=pb.num_dofs,
                newton=sum(m["solver"]["newton_iterations"]),
                setups=int(pb.factorisations),
                solves=len(its),
                its_mean=float(np.mean(its)) if its else None,
                its_max=max(its) if its else None,
                iterations=its,
                t_solve=t["solve"],
                t_amg_setup=getattr(pb.linear, "t_setup", None),
                t_krylov=getattr(pb.linear, "t_krylov", None),
                t_run=t["total"] - t["mesh"],
                pressure_error=m["results"]["pressure_rel_l2_error"],
                P=abs(m["results"]["reaction"][1]),
            )
        )
    )


def hertz_table(runs, timeout, tmp):
    """runs: [(path, divisor, solvers)], solvers: "direct" first."""
    rows = []
    for path, d, solvers in runs:
        if True:
            recs = {}
            for solver in solvers:
                npy = Path(tmp) / f"u_{path}_{d}_{solver}.npy"
                cmd = [str(Path(__file__)), "--child", path, str(d), solver, str(npy)]
                rc, so, se, wall, rss = child(cmd, timeout)
                if rc:
                    r = dict(path=path, divisor=d, solver=solver, error=se.strip()[-300:])
                else:
                    r = json.loads(so.strip().splitlines()[-1])
                    r.update(wall=wall, peak_rss_mb=rss)
                recs[solver] = r
            di = recs["direct"]
            for solver in solvers[1:]:
                it = recs[solver]
                if "error" in di or "error" in it:
                    continue
                ud = np.load(Path(tmp) / f"u_{path}_{d}_direct.npy")
                ui = np.load(Path(tmp) / f"u_{path}_{d}_{solver}.npy")
                it.update(
                    u_rel_diff=float(np.abs(ui - ud).max() / np.abs(ud).max()),
                    pressure_error_diff=abs(it["pressure_error"] - di["pressure_error"]),
                    P_rel_diff=abs(it["P"] / di["P"] - 1),
                    time_ratio=it["t_run"] / di["t_run"],
                    solve_ratio=it["t_solve"] / di["t_solve"],
                )
            for r in recs.values():
                rows.append(r)
                print(json.dumps({k: v for k, v in r.items() if k != "iterations"}), flush=True)
    return rows


# --------------------------------------------------------------------------- cuts
def cuts_table(n, etas, gammas, eps0s):
    from small_cuts import interface_height, patch_problem

    from dolfinx_forms.solvers.newton import ContactSolverError

    rows = []
    for eps0 in eps0s:
        for gamma in gammas:
            for setup, opts in SETUPS.items():
                for eta in etas:
                    t0 = time.perf_counter()
                    sc, pb = _patch(patch_problem, n, interface_height(n, eta), gamma, eps0, opts)
                    failed = ""
                    try:
                        pb.solve()
                    except ContactSolverError as e:
                        failed = str(e).splitlines()[0][:200]
                    its = pb.linear.iterations
                    r = dict(
                        n=n,
                        dofs=pb.num_dofs,
                        eps0=eps0,
                        gamma=gamma,
                        gamg=setup,
                        eta=eta,
                        its_max=max(its) if its else None,
                        its_mean=float(np.mean(its)) if its else None,
                        solves=len(its),
                        setups=pb.linear.setups,
                        newton=sum(s.iterations for s in pb.steps),
                        failed=failed,
                        time_s=time.perf_counter() - t0,
                    )
                    rows.append(r)
                    print(json.dumps(r), flush=True)
    return rows


def _patch(patch_problem, n, interface, gamma, eps0, petsc_options):
    """small_cuts.patch_problem with the iterative solver (and petsc_options)."""
    from dolfinx_forms.solvers import problem as solver

    orig = solver.ContactProblem

    def iterative(*a, **kw):
        return orig(*a, **kw, linear_solver="iterative", petsc_options=petsc_options)

    import small_cuts

    small_cuts.ContactProblem = iterative
    try:
        return patch_problem(n, interface, gamma, eps0=eps0)
    finally:
        small_cuts.ContactProblem = orig


# --------------------------------------------------------------------------- bodies
def bodies_table(divisors, gradings=(None, 1.2)):
    """Where CG + GAMG stalls on the cut Hertz: the Jacobian at the solution (Dirichlet rows
    and columns eliminated) and its diagonal blocks of each body (the block has no cut cell;
    the cylinder is cut), each with its own rigid-body modes, a random right-hand side,
    rtol 1e-10, linear.ITERATIVE_OPTIONS; for the demo's grid grading (2: cells of aspect
    ratio up to h_far / h where a fine row crosses a coarse column) and a milder 1.2."""
    from dolfinx import la
    from petsc4py import PETSc

    from dolfinx_forms.app.demo import Run
    from dolfinx_forms.solvers import linear

    hertz = hertz_demo()
    rows = []
    for d in divisors:
        for grading in gradings:
            argv = ["--discretization", "cut", "--linear-solver", "factorised"]
            argv += [] if grading is None else ["--grading", str(grading)]
            p = vars(hertz.parse(argv))
            p["h"] = hertz.estimate(p)[1] / d
            run = Run("hertz", p, plot=False)
            hertz.solve(run, SimpleNamespace(**p))
            pb = run.problem
            pb.residual(pb.lam, with_tangent=True)
            A = pb.J.copy()
            A.zeroRowsColumns(pb.bc_global, diag=1.0)
            X = pb.V.tabulate_dof_coordinates()[:, :2]
            cells = pb.V.dofmap.list.array.reshape(-1, 4)
            parts = {"both": np.arange(len(X))}
            for b in pb.scene.bodies:
                parts[b.name] = np.unique(cells[pb.scene.cell_tags.find(b.tag)])
            for name, nodes in parts.items():
                dofs = (nodes[:, None] * 2 + np.arange(2)).ravel().astype(np.int32)
                iset = PETSc.IS().createGeneral(dofs)
                M = A.createSubMatrix(iset, iset)
                M.setBlockSize(2)
                modes = [M.createVecLeft() for _ in range(3)]
                Xc = X[nodes] - X[nodes].mean(axis=0)
                modes[0].array.reshape(-1, 2)[:, 0] = modes[1].array.reshape(-1, 2)[:, 1] = 1
                r = modes[2].array.reshape(-1, 2)
                r[:, 0], r[:, 1] = -Xc[:, 1], Xc[:, 0]
                la.orthonormalize(modes)
                M.setNearNullSpace(PETSc.NullSpace().create(vectors=modes))
                ksp = PETSc.KSP().create(PETSc.COMM_SELF)
                ksp.setOptionsPrefix("bodies_")
                o = PETSc.Options()
                for k, v in {"ksp_type": "cg", **linear.ITERATIVE_OPTIONS}.items():
                    o["bodies_" + k] = v
                ksp.setFromOptions()
                ksp.setTolerances(rtol=1e-10)
                ksp.setOperators(M)
                b = M.createVecLeft()
                b.setRandom()
                x = b.duplicate()
                ksp.solve(b, x)
                grid = pb.scene.cut
                hx, hy = np.diff(grid.xlines), np.diff(grid.ylines)
                aspect = max(hx.max() / hy.min(), hy.max() / hx.min())
                r = dict(
                    divisor=d,
                    grading=grading or 2.0,
                    part=name,
                    dofs=len(dofs),
                    its=ksp.getIterationNumber(),
                    reason=ksp.getConvergedReason(),
                    max_aspect=float(aspect),
                )
                rows.append(r)
                print(json.dumps(r), flush=True)
    return rows


# --------------------------------------------------------------------------- output
def write_csv(rows, path):
    keys = list(dict.fromkeys(k for r in rows for k in r if k != "iterations"))
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=keys, extrasaction="ignore")
    w.writeheader()
    w.writerows(rows)
    write_text(path, buf.getvalue())


def plot(hertz, cuts, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(15, 5.2))
    for (p, solver), mk in zip(
        [(p, s) for p in ("conforming", "cut") for s in ("iterative", "hypre", "factorised")],
        "osDv^d",
    ):
        rr = [r for r in hertz if r.get("path") == p and r.get("solver") == solver]
        rr = [r for r in rr if "dofs" in r]
        name = {"iterative": "GAMG", "hypre": "BoomerAMG", "factorised": "MUMPS LU"}[solver]
        if rr and solver == "factorised":
            rr = [r for r in rr if "time_ratio" in r]
            ax[1].semilogx([r["dofs"] for r in rr], [r["time_ratio"] for r in rr], mk + ":",
                           label=f"{p} {name}")  # fmt: skip
        elif rr:
            n = [r["dofs"] for r in rr]
            ax[0].loglog(n, [r["its_max"] for r in rr], mk + "-", label=f"{p} {name}: max")
            ax[0].loglog(n, [r["its_mean"] for r in rr], mk + "--", label=f"{p} {name}: mean")
            rr = [r for r in rr if "time_ratio" in r]
            ax[1].semilogx([r["dofs"] for r in rr], [r["time_ratio"] for r in rr], mk + "-",
                           label=f"{p} {name}")  # fmt: skip
    ax[0].set(xlabel="dofs", ylabel="CG iterations per solve", title="Hertz, CG + AMG")
    ax[1].axhline(1.0, color="gray", lw=0.8)
    ax[1].set_yscale("log")
    ax[1].set(xlabel="dofs", ylabel="run time: iterative / direct", title="Hertz")
    colours = {"tuned": "C0", "petsc": "C3", "hypre": "C2"}
    styles = {0.0: ":", 0.01: "-", 0.1: "--"}
    for eps0, gamma, setup in sorted({(r["eps0"], r["gamma"], r["gamg"]) for r in cuts}):
        rr = [r for r in cuts if (r["eps0"], r["gamma"], r["gamg"]) == (eps0, gamma, setup)]
        its = [r["its_max"] if not r["failed"] else np.nan for r in rr]
        ax[2].loglog([r["eta"] for r in rr], its, styles.get(gamma, "-."), color=colours[setup],
                     marker="o" if eps0 >= 0.1 else "x", ms=3,
                     label=f"eps0 {eps0:g}, gamma {gamma:g}, {setup}")  # fmt: skip
    ax[2].set(xlabel="cut fraction eta", ylabel="max CG iterations per solve",
              title="cut patch test (failed: gap)")  # fmt: skip
    for a in ax[:2]:
        a.legend(fontsize=6)
    ax[2].legend(fontsize=5, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.15))
    for a in ax:
        a.grid(True, which="both", lw=0.3)
    fig.tight_layout()
    write_atomic(path, lambda tmp: fig.savefig(tmp, dpi=110, format="png"))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--conforming", default="20,40,80,160,190", help="divisors (h = a/d)")
    ap.add_argument("--cut", default="20,40,80,160", help="divisors of the cut path")
    ap.add_argument("--conforming-solvers", default="direct,iterative,factorised")
    ap.add_argument("--cut-solvers", default="direct,iterative,hypre")
    ap.add_argument("--n", type=int, default=60, help="patch grid: n x n cells")
    ap.add_argument("--quick", action="store_true", help="eta 0.5, 1e-4, 1e-8; gamma 0, 0.01")
    ap.add_argument(
        "--skip-hertz", action="store_true", help="keep the hertz table of <out-dir>/amg.json"
    )
    ap.add_argument("--skip-cuts", action="store_true", help="keep its cuts table")
    ap.add_argument("--replot", action="store_true", help="only redraw amg.png from amg.json")
    ap.add_argument("--out-dir", default=str(ROOT / "benchmarks" / "results"))
    ap.add_argument("--timeout", type=float, default=900.0)
    ap.add_argument("--child", nargs=4, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.replot:  # redraw amg.png from amg.json
        t = json.loads((Path(args.out_dir) / "amg.json").read_text())
        return plot(t["hertz"], t["cuts"], Path(args.out_dir) / "amg.png")
    if args.child:
        path, d, solver, npy = args.child
        return hertz_child(path, int(d), solver, npy)
    out = Path(args.out_dir)
    hertz = []
    if args.skip_hertz and (out / "amg.json").exists():  # keep the last run's table
        hertz = json.loads((out / "amg.json").read_text()).get("hertz", [])
    if not args.skip_hertz:
        with tempfile.TemporaryDirectory() as tmp:
            solvers = {
                p: ["direct"]
                + [x for x in getattr(args, p + "_solvers").split(",") if x != "direct"]
                for p in ("conforming", "cut")
            }
            runs = [
                (path, int(d), solvers[path])
                for path in ("conforming", "cut")
                for d in getattr(args, path).split(",")
                if d
            ]
            hertz = hertz_table(runs, args.timeout, tmp)
    etas = (0.5, 1e-4, 1e-8) if args.quick else ETAS
    gammas = (0.0, 0.01) if args.quick else GAMMAS
    last = json.loads((out / "amg.json").read_text()) if (out / "amg.json").exists() else {}
    if args.skip_cuts:  # keep the last run's table
        cuts = last.get("cuts", [])
    else:
        cuts = cuts_table(args.n, etas, gammas, EPS0S)
    bodies = bodies_table([20, 40])
    head = git_head()
    tables = dict(
        commits=dict(
            hertz=last.get("commits", {}).get("hertz") if args.skip_hertz else head,
            cuts=last.get("commits", {}).get("cuts") if args.skip_cuts else head,
            bodies=head,
        ),
        hertz=hertz,
        cuts=cuts,
        bodies=bodies,
    )
    write_text(out / "amg.json", json.dumps(tables, indent=1))
    write_csv(bodies, out / "amg_bodies.csv")
    write_csv(hertz, out / "amg_hertz.csv")
    write_csv(cuts, out / "amg_cuts.csv")
    plot(hertz, cuts, out / "amg.png")
    print(f"results in {out}/amg.{{json,png}}, amg_hertz.csv, amg_cuts.csv, amg_bodies.csv")
    return 0


if __name__ == "__main__":
    sys.exit(main())
