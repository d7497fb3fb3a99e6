#!/usr/bin/python3
"""Small cut fractions: conditioning and accuracy of the cut-cell patch test, with and without
ghost penalty.

Set-up. The contact patch test of demos/patch_test.py (E = 1, nu = 0.3, plane strain, bottom
held vertically, top moved down by d = 0.01, the points (0, 0) and (0, 1) held horizontally,
frictionless penalty contact with eps_n = eps0 h / E, eps0 = 1e-3) on the cut scene
`meshes.cut.patch_cut_scene(n)`: a uniform n x n grid of [0, 1]^2, the interface at
y = (k + eta) h (h = 1 / n, k = n // 2). The lower body's top row is then cut with inside
fraction eta and the upper body's bottom row with 1 - eta ("tiny": lower); the mirrored case
y = (k + 1 - eta) h gives the upper body the fraction eta ("tiny": upper).

Per (eta, gamma, tiny body) the record holds
  * cond_K, lambda_min, lambda_max: the bulk stiffness K (cut forms, ghost penalty gamma) with
    the Dirichlet rows and columns of the patch test replaced by the identity (K is symmetric:
    eigenvalues by eigvalsh, the condition number sigma_max / sigma_min by a dense SVD);
    K_singular: lambda_min <= 1e-14 lambda_max (the pinned points and the held bottom/top
    remove every rigid mode of both bodies, so it should be False);
  * cond_J: the same for the contact Jacobian J = K + contact tangent at the solution (bc rows
    AND columns replaced by the identity; the solver zeroes the rows only);
  * newton_iterations, failed, error: the contact solve (MUMPS LU), ContactSolverError caught;
  * pressure_max_rel_deviation: max |p - p_pen| / p_pen over the contact points,
    p_pen = E' d / (H + E' eps_n), E' = E / (1 - nu^2), H = 1;
  * reaction_rel_error: |F_y(upper_top) + p_pen W| / (p_pen W), W = 1;
  * u_error_physical / u_error_all: max |u_h - u| / max |u| over the nodes with phi <= 0 of
    their body / over every node, u the exact (linear) solution of the penalised problem:
      lower body u = (c x, -p y / E'),  upper body u = (c x, -d - p (y - H) / E'),
      c = nu (1 + nu) p / E  (sigma_yy = -p, sigma_xx = 0, no rotation: bottom/top held);
    the gap jump at the interface is p / E' - d = -p eps_n (the penalty law). Q1 reproduces
    this field exactly (also at the fictitious nodes, phi > 0), so the errors are round-off
    amplified by the conditioning;
  * eta_actual: the inside fraction of the tiny row from the level-set values at its nodes;
  * time_s: wall time of scene + problem + solve + spectra.

Outputs (replaced atomically): <out-dir>/small_cuts.json (parameters and records) and
<out-dir>/small_cuts.png (cond_K vs eta, log-log, one line per gamma and tiny body; solution
errors vs eta). A table is printed.

Usage: /usr/bin/python3 benchmarks/small_cuts.py [--out-dir benchmarks/results] [--n 5]
           [--fractions 0.5,1e-1,...,1e-8] [--gammas 0,0.1] [--quick]
"""

import json
import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from dolfinx_forms.analysis import analytic
from benchmarks.common import git_head, write_atomic
from dolfinx_forms.app.cli import DemoParser, bounded
from dolfinx_forms.solvers.newton import ContactSolverError
from dolfinx_forms.solvers.options import options
from dolfinx_forms.solvers.problem import ContactProblem
from meshes.cut import patch_cut_scene
from meshes.patch import patch_dirichlet


ROOT = Path(__file__).resolve().parents[1]

E, NU, D, EPS0 = 1.0, 0.3, 0.01, 1e-3
HEIGHT = WIDTH = 1.0
FRACTIONS = (0.5,) + tuple(10.0**-k for k in range(1, 9))
QUICK_FRACTIONS = (0.5, 1e-2, 1e-4, 1e-6, 1e-8)
GAMMAS = (0.0, 0.1)
SINGULAR = 1e-14  # lambda_min / lambda_max below this: numerically singular


def floats(name, lo, hi, lo_open=False):
    """argparse type: comma-separated floats, each in the bounded range."""
    one = bounded(name, lo, hi, lo_open=lo_open)

    def parse(text):
        vals = [one(v) for v in text.split(",") if v.strip()]
        if not vals:
            raise ValueError
        return vals

    parse.__name__ = name
    return parse


def parse(argv):
    p = DemoParser(prog="small_cuts.py", description=__doc__.split("\n\n")[0])
    p.add_argument(
        "--out-dir",
        default=str(ROOT / "benchmarks" / "results"),
        help="folder of small_cuts.json and .png (default benchmarks/results)",
    )
    p.add_argument("--n", type=int, default=5, help="cells over the height, in [3, 40]")
    p.add_argument(
        "--fractions",
        type=floats("--fractions", 0, 0.5, lo_open=True),
        default=None,
        help="cut fractions eta in (0, 0.5] (default 0.5,1e-1,...,"
        "1e-8; 0.5, the reference of the ratios, is always added)",
    )
    p.add_argument(
        "--gammas",
        type=floats("--gammas", 0, None),
        default=None,
        help="ghost-penalty factors (default 0,0.1)",
    )
    p.add_argument(
        "--quick",
        action="store_true",
        help=f"fractions {','.join(f'{f:g}' for f in QUICK_FRACTIONS)} only",
    )
    a = p.parse_args(argv)
    if not 3 <= a.n <= 40:
        p.error(f"--n: must be in [3, 40] (dense SVD), got {a.n}")
    if a.quick and a.fractions is not None:
        p.error("--fractions: --quick sets the fractions; drop one of the two options")
    a.fractions = list(QUICK_FRACTIONS if a.quick else a.fractions or FRACTIONS)
    if 0.5 not in a.fractions:  # the reference of the growth ratios
        a.fractions.insert(0, 0.5)
    a.gammas = list(GAMMAS if a.gammas is None else a.gammas)
    # patch_cut_scene rejects an interface within 1e-9 cells of a grid line
    small = [f for f in a.fractions if f < 2e-9]
    if small:
        p.error(
            f"--fractions: {small[0]:g} is below 2e-9 (patch_cut_scene needs the interface "
            f"off the grid lines by more than 1e-9 cells)"
        )
    return a


# --------------------------------------------------------------------------- set-up
def interface_height(n, eta, tiny="lower"):
    """Interface y of the grid of n cells over HEIGHT such that the `tiny` body's cut row has
    inside fraction eta (row k = n // 2)."""
    k, h = n // 2, HEIGHT / n
    return (k + eta) * h if tiny == "lower" else (k + 1 - eta) * h


def patch_problem(n, interface, gamma, eps0=EPS0, comm=MPI.COMM_WORLD):
    """(scene, ContactProblem) of the cut patch test."""
    scene = patch_cut_scene(comm, n=n, width=WIDTH, height=HEIGHT, interface=interface)
    problem = ContactProblem(
        scene,
        {b.tag: (E, NU) for b in scene.bodies},
        dirichlet=patch_dirichlet(D, HEIGHT),
        log=lambda *a, **k: None,
        **options(mu=0.0, eps0=eps0, band=0.5 * HEIGHT / n, ghost_penalty=gamma),
    )
    return scene, problem


def penalised_pressure(eps_n, d=D, H=HEIGHT):
    """p = E' d / (H + E' eps_n)."""
    Ep = analytic.patch_pressure(E, NU, 1.0)
    return Ep * d / (H + Ep * eps_n)


def exact_displacement(x, upper, p, d=D, H=HEIGHT):
    """Exact (linear) displacement (m, 2) at points x (m, 2); upper: bool (m,) body flags."""
    Ep = analytic.patch_pressure(E, NU, 1.0)
    ux = NU * (1 + NU) * p / E * x[:, 0]
    uy = np.where(upper, -d - p * (x[:, 1] - H) / Ep, -p * x[:, 1] / Ep)
    return np.stack([ux, uy], axis=1)


# --------------------------------------------------------------------------- spectra
def dense(mat):
    """A (sequential) AIJ PETSc matrix as a dense numpy array (mat untouched)."""
    indptr, cols, vals = mat.getValuesCSR()
    A = np.zeros(mat.getSize())
    A[np.repeat(np.arange(len(indptr) - 1), np.diff(indptr)), cols] = vals
    return A


def with_identity(A, dofs):
    """A copy of A with the rows and columns `dofs` replaced by those of the identity."""
    B = A.copy()
    B[dofs, :] = 0.0
    B[:, dofs] = 0.0
    B[dofs, dofs] = 1.0
    return B


def spectrum(A):
    """cond (dense SVD: sigma_max / sigma_min), and for a symmetric A its extreme eigenvalues."""
    s = np.linalg.svd(A, compute_uv=False)
    out = dict(
        cond=float(s[0] / s[-1]) if s[-1] > 0 else float("inf"),
        sigma_min=float(s[-1]),
        sigma_max=float(s[0]),
    )
    if np.allclose(A, A.T, rtol=0, atol=1e-12 * s[0]):
        lam = np.linalg.eigvalsh(0.5 * (A + A.T))
        out.update(
            lambda_min=float(lam[0]),
            lambda_max=float(lam[-1]),
            singular=bool(lam[0] <= SINGULAR * lam[-1]),
        )
    return out


def stiffness_spectrum(problem):
    """spectrum() of the bulk stiffness K with the Dirichlet rows/columns -> identity."""
    return spectrum(with_identity(dense(problem.K), problem.bc_owned))


# --------------------------------------------------------------------------- one case
def dof_data(scene, problem):
    """(coordinates (m, 2), upper-body flags (m,), phi of the owning body (m,)) per node."""
    V = problem.V
    x = V.tabulate_dof_coordinates()[:, :2]
    ncells = len(scene.cell_tags.values)
    cdofs = V.dofmap.list.array.reshape(ncells, -1)
    tag = np.zeros(len(x), np.int32)
    tag[cdofs.ravel()] = np.repeat(scene.cell_tags.values, cdofs.shape[1])
    phi = np.empty(len(x))
    for t, shape in scene.cut.levelsets.items():
        sel = tag == t
        phi[sel] = np.asarray(shape(np.ascontiguousarray(x[sel])))
    upper = tag == scene.bodies[1].tag
    return x, upper, phi


def actual_fraction(n, interface, x, upper, phi, tiny):
    """Inside fraction of the tiny body's cut row from phi at its bottom and top node lines."""
    k, h = n // 2, HEIGHT / n
    sel = upper if tiny == "upper" else ~upper
    bottom = phi[sel & np.isclose(x[:, 1], k * h)].mean()
    top = phi[sel & np.isclose(x[:, 1], (k + 1) * h)].mean()
    t = bottom / (bottom - top)  # zero crossing, from the bottom line
    return float(t if tiny == "lower" else 1 - t)


def run_case(n, eta, gamma, tiny="lower", eps0=EPS0):
    """One record (see the module docstring)."""
    t0 = time.perf_counter()
    interface = interface_height(n, eta, tiny)
    scene, problem = patch_problem(n, interface, gamma, eps0)
    x, upper, phi = dof_data(scene, problem)
    rec = dict(
        n=n,
        eta=eta,
        gamma=gamma,
        tiny=tiny,
        interface=interface,
        eta_actual=actual_fraction(n, interface, x, upper, phi, tiny),
        num_dofs=int(problem.num_dofs),
        num_bc_dofs=int(len(problem.bc_owned)),
        eps_n=problem.eps_n,
    )
    K = stiffness_spectrum(problem)
    rec.update(
        cond_K=K["cond"],
        lambda_min=K["lambda_min"],
        lambda_max=K["lambda_max"],
        K_singular=K["singular"],
    )
    try:
        problem.solve(1, label=f"eta={eta:g} gamma={gamma:g}")
        rec.update(failed=False, error=None, newton_iterations=problem.steps[-1].iterations)
    except ContactSolverError as e:
        rec.update(failed=True, error=str(e), newton_iterations=None)
    if not rec["failed"]:
        J = spectrum(with_identity(dense(problem.J), problem.bc_owned))
        rec["cond_J"] = J["cond"]
        p_pen = penalised_pressure(problem.eps_n)
        pts = problem.contact_points()
        p = np.concatenate([q["p_n"] for q in pts])
        rec["pressure_max_rel_deviation"] = float(np.max(np.abs(p - p_pen)) / p_pen)
        Fy = problem.reaction("upper_top")[1]
        rec["reaction_rel_error"] = float(abs(Fy + p_pen * WIDTH) / (p_pen * WIDTH))
        u = problem.u.x.array.reshape(-1, 2)
        err = np.abs(u - exact_displacement(x, upper, p_pen)).max(axis=1)
        scale = np.abs(exact_displacement(x, upper, p_pen)).max()
        rec["u_error_physical"] = float(err[phi <= 0].max() / scale)
        rec["u_error_all"] = float(err.max() / scale)
        rec["pressure_penalised"] = p_pen
    rec["time_s"] = time.perf_counter() - t0
    return rec


def run_all(n, fractions, gammas, mirrored=True):
    tinies = ("lower", "upper") if mirrored else ("lower",)
    return [
        run_case(n, eta, gamma, tiny)
        for gamma in gammas
        for tiny in tinies
        for eta in fractions
        if not (tiny == "upper" and eta == 0.5)
    ]


def growth(records):
    """Per (gamma, tiny): cond_K(eta) / cond_K(0.5), the fit exponent of cond_K ~ eta^-s."""
    out = []
    ref = {(r["gamma"]): r["cond_K"] for r in records if r["eta"] == 0.5 and r["tiny"] == "lower"}
    for g in sorted({r["gamma"] for r in records}):
        for tiny in ("lower", "upper"):
            rs = sorted(
                (r for r in records if r["gamma"] == g and (r["tiny"] == tiny or r["eta"] == 0.5)),
                key=lambda r: -r["eta"],
            )
            if len(rs) < 2 or g not in ref:
                continue
            e = np.array([r["eta"] for r in rs])
            c = np.array([r["cond_K"] for r in rs])
            small = e <= 1e-2
            slope = (
                float(-np.polyfit(np.log(e[small]), np.log(c[small]), 1)[0])
                if small.sum() >= 2
                else None
            )
            out.append(
                dict(
                    gamma=g,
                    tiny=tiny,
                    exponent_small_eta=slope,
                    max_ratio_to_eta_half=float(c.max() / ref[g]),
                )
            )
    return out


# --------------------------------------------------------------------------- output
COLUMNS = [
    ("eta", "{:8.0e}"),
    ("gamma", "{:5g}"),
    ("tiny", "{:>5s}"),
    ("cond_K", "{:9.2e}"),
    ("lambda_min", "{:10.2e}"),
    ("lambda_max", "{:10.2e}"),
    ("cond_J", "{:9.2e}"),
    ("newton_iterations", "{:3d}"),
    ("pressure_max_rel_deviation", "{:9.1e}"),
    ("reaction_rel_error", "{:9.1e}"),
    ("u_error_physical", "{:9.1e}"),
    ("u_error_all", "{:9.1e}"),
    ("time_s", "{:6.3f}"),
]
HEADERS = [
    "eta",
    "gamma",
    "tiny",
    "cond(K)",
    "lam_min",
    "lam_max",
    "cond(J)",
    "its",
    "dp/p",
    "dR/R",
    "du phys",
    "du all",
    "t (s)",
]


def table(records):
    widths = [
        max(len(h), len(fmt.format(1e-8) if "e" in fmt else h))
        for h, (_, fmt) in zip(HEADERS, COLUMNS)
    ]
    lines = ["  ".join(h.rjust(w) for h, w in zip(HEADERS, widths))]
    for r in records:
        cells = []
        for (key, fmt), w in zip(COLUMNS, widths):
            v = r.get(key)
            cells.append(("-" if v is None else fmt.format(v)).rjust(w))
        lines.append("  ".join(cells) + ("  FAILED: " + r["error"] if r.get("failed") else ""))
    return "\n".join(lines)


def plot(path, records):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(13, 5))
    gammas = sorted({r["gamma"] for r in records})
    colors = {g: f"C{i}" for i, g in enumerate(gammas)}

    def series(g, tiny, key):
        rs = sorted(
            (
                r
                for r in records
                if r["gamma"] == g and not r["failed"] and (r["tiny"] == tiny or r["eta"] == 0.5)
            ),
            key=lambda r: r["eta"],
        )
        return [r["eta"] for r in rs], [max(r[key], 1e-17) for r in rs]

    left = [
        ("cond_K", "lower", "-o", "cond(K), eta in the lower body"),
        ("cond_K", "upper", "--s", "cond(K), eta in the upper body"),
        ("cond_J", "lower", ":^", "cond(J) at the solution, eta in the lower body"),
    ]
    right = [
        ("u_error_physical", "-o", "u at physical nodes"),
        ("u_error_all", ":^", "u at all nodes (incl. fictitious)"),
        ("pressure_max_rel_deviation", "--x", "contact pressure vs penalised exact"),
    ]
    for g in gammas:
        for key, tiny, style, lab in left:
            ax0.loglog(
                *series(g, tiny, key), style, color=colors[g], ms=4, label=f"gamma={g:g}: {lab}"
            )
        for key, style, lab in right:
            for i, tiny in enumerate(("lower", "upper")):  # both bodies, one legend entry
                ax1.loglog(
                    *series(g, tiny, key),
                    style,
                    color=colors[g],
                    ms=4,
                    alpha=1.0 if i == 0 else 0.5,
                    label=f"gamma={g:g}: {lab}" if i == 0 else None,
                )
    e = np.array(sorted({r["eta"] for r in records}))
    ref = min(r["cond_K"] for r in records if r["eta"] == 0.5)
    ax0.loglog(e, ref * 0.5 / e, ":", color="gray", label="~ 1/eta")
    ax0.set(
        xlabel="cut fraction eta",
        ylabel="condition number (Dirichlet dofs -> identity)",
        title=f"n = {records[0]['n']}: stiffness K and contact Jacobian J",
    )
    ax1.set(
        xlabel="cut fraction eta",
        ylabel="max relative error",
        title="patch test errors (faint: eta in the upper body)",
    )
    for ax in (ax0, ax1):
        ax.invert_xaxis()
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    write_atomic(path, lambda tmp: fig.savefig(tmp, dpi=110, format="png"))
    plt.close(fig)


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    if MPI.COMM_WORLD.size > 1:
        sys.stderr.write("small_cuts.py: run on one process (dense spectra)\n")
        return 2
    t0 = time.perf_counter()
    records = run_all(args.n, args.fractions, args.gammas)
    data = dict(
        benchmark="small_cuts",
        git=git_head(),
        parameters=dict(
            n=args.n,
            row=args.n // 2,
            E=E,
            nu=NU,
            d=D,
            eps0=EPS0,
            width=WIDTH,
            height=HEIGHT,
            fractions=args.fractions,
            gammas=args.gammas,
            quick=args.quick,
        ),
        growth=growth(records),
        records=records,
        total_time_s=time.perf_counter() - t0,
    )
    out = Path(args.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    json_path, png_path = out / "small_cuts.json", out / "small_cuts.png"

    def write_json(tmp):
        with open(tmp, "w") as f:
            json.dump(data, f, indent=2)

    write_atomic(json_path, write_json)
    plot(png_path, records)
    print(table(records))
    for g in data["growth"]:
        s = g["exponent_small_eta"]
        print(
            f"gamma={g['gamma']:g}, eta in {g['tiny']} body: cond_K ~ eta^-"
            f"{'n/a' if s is None else f'{s:.2f}'}, max cond_K / cond_K(0.5) = "
            f"{g['max_ratio_to_eta_half']:.3g}"
        )
    print(f"results in {json_path.resolve()} and {png_path.resolve()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
