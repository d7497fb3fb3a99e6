#!/usr/bin/python3
"""The same orthotropic UFL law on a body-fitted and on a cut body: Hertz-type contact of a
half-ellipse on a block, both paths refined together.

Set-up (plane strain, frictionless, penalty eps_n = eps0 h / E1, eps0 = 0.5): the half-ellipse
of meshes/hertz.py (semi-axes R = 10 horizontal, Ry = 6 vertical: curvature radius
R^2 / Ry = 16.7 at the contact) on the block [-20, 20] x [-20, 0]; both bodies are the same
`OrthotropicElastic` (E1 = 2e4, E2 = E3 = 1e4, nu12 = 0.25, nu13 = nu23 = 0.3, G12 = 5e3,
material axes rotated by 0.3 rad, so the law couples normal and shear: the contact is slightly
asymmetric and the held indenter feels a horizontal reaction). The block bottom is clamped;
the indenter's flat top is held horizontally and moved down by the same approach `delta` on
both paths (contact half-width a ~ 1). The mesh size is h on the zone [-1.6, 1.6]^2 and grows
to h_far = 8 h outside (h_far proportional to h: every cell halves with h, so the difference of
the two discretisations measures their discretisation errors and not a fixed far-field mesh):
  * body-fitted path: meshes.hertz.hertz_scene (P1 triangles, gmsh, the arc an ellipse arc);
  * cut path: meshes.cut.hertz_cut_scene (Q1 on a graded grid, the indenter cut by its ellipse,
    moment-fitted weights on the cut cells).

Per h and path the record holds the dofs, the reaction (block bottom) [Fx, Fy], the contact
half-width a and centre (ends of the active zone, interpolated to the zero gap), the contact
points (x, p_n, w) and the wall time of scene + problem + solve. Per h the comparison holds
  * reaction_rel_diff  |Fy_fit - Fy_cut| / |Fy_fit|;
  * half_width_rel_diff |a_fit - a_cut| / a_fit, a from the zone ends (sampled at the contact
    points, h/4 apart: noisy at the 0.3 % level on unstructured triangles);
  * half_width_moment_rel_diff: the same for a_m = 2 sqrt(second central moment of p(x)) (= a
    for a Hertz profile), an integral measure;
  * pressure_rel_l2_diff: the cut path's p(x) interpolated (linearly) onto the body-fitted
    contact points, relative L2 (weights w) over them; and the same after averaging both over
    one cell width (output.window_average: removes the element-scale penalty ripple);
and the observed rates log2(diff(2h) / diff(h)).

Outputs (replaced atomically): <out-dir>/orthotropic_paths.json and .png (the differences
against h, log-log, and the table). A table is printed.

Usage: /usr/bin/python3 benchmarks/orthotropic_paths.py [--out-dir benchmarks/results]
           [--h 0.2,0.1,0.05,0.025]
"""

import json
import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from benchmarks.common import git_head, write_atomic
from dolfinx_forms.app.cli import DemoParser, bounded
from dolfinx_forms.fem.boundary import Dirichlet
from dolfinx_forms.fem.laws import LinearElastic, OrthotropicElastic
from dolfinx_forms.io.output import gather_points, window_average
from dolfinx_forms.solvers.options import options
from dolfinx_forms.solvers.problem import ContactProblem, zone_ends
from dolfinx_forms.solvers.protocol import ramp
from meshes.cut import hertz_cut_scene
from meshes.hertz import ellipse_sag, hertz_scene


ROOT = Path(__file__).resolve().parents[1]

GEOMETRY = dict(R=10.0, Ry=6.0, width=40.0, depth=20.0, zone=1.6)
# angle in degrees (0.3 rad)
ORTHO = dict(
    E1=2.0e4, E2=1.0e4, E3=1.0e4, nu12=0.25, nu13=0.3, nu23=0.3, G12=5.0e3,
    angle=float(np.degrees(0.3)),
)  # fmt: skip
ISO = dict(E=1.0e4, nu=0.3)
DELTA = 0.1  # approach of the indenter top (a ~ 1, Fy ~ 300 N/mm)
EPS0 = 0.5
H_FAR = 8.0  # h_far = H_FAR h
HS = (0.2, 0.1, 0.05, 0.025)
PATHS = ("fitted", "cut")


def ortho_law():
    return OrthotropicElastic(**ORTHO)


def iso_law():
    return LinearElastic(**ISO)


def scene(path, h, comm=MPI.COMM_WORLD, geometry=GEOMETRY, h_far=H_FAR):
    g = dict(geometry)
    if path == "fitted":
        return hertz_scene(comm, h=h, h_far=h_far * h, **g)
    if path == "cut":
        return hertz_cut_scene(comm, h=h, h_far=h_far * h, **g)
    raise ValueError(f"path must be 'fitted' or 'cut', got {path!r}")


def run_path(
    path,
    h,
    law=None,
    delta=DELTA,
    geometry=GEOMETRY,
    eps0=EPS0,
    h_far=H_FAR,
    steps=1,
    comm=MPI.COMM_WORLD,
):
    """One solve: the indenter top moved down by delta (held horizontally), frictionless.
    Returns the record (see the module docstring); points on rank 0 only."""
    law = ortho_law() if law is None else law
    t0 = time.perf_counter()
    sc = scene(path, h, comm, geometry, h_far)
    top_y = Dirichlet("cylinder_top", 1, 0.0)
    g = geometry
    band = ellipse_sag(g["R"], g["Ry"], g["zone"])  # the initial gap at x = +-zone
    problem = ContactProblem(
        sc,
        {b.tag: law for b in sc.bodies},
        dirichlet=[Dirichlet("block_bottom", None, 0.0), Dirichlet("cylinder_top", 0, 0.0), top_y],
        log=lambda *a, **k: None,
        **options(mu=0.0, eps0=eps0, band=band),
    )
    ramp(problem, top_y, -delta, steps=steps)
    reaction = problem.reaction("block_bottom")
    pts = gather_points(problem)
    rec = dict(
        path=path,
        h=float(h),
        dofs=int(problem.num_dofs),
        cells=int(sc.mesh.topology.index_map(2).size_global),
        newton_iterations=int(sum(s.iterations for s in problem.steps)),
        reaction=[float(f) for f in reaction],
        time_s=time.perf_counter() - t0,
    )
    if pts is not None:
        xl, xr = zone_ends(pts["x"], pts["state"] != 0, pts["gap_n"])
        rec.update(
            half_width=0.5 * (xr - xl),
            centre=0.5 * (xr + xl),
            half_width_moment=moment_half_width(pts["x"], pts["p_n"], pts["w"]),
            x=pts["x"].tolist(),
            p=pts["p_n"].tolist(),
            w=pts["w"].tolist(),
            contact_force=float(np.sum(pts["w"] * pts["p_n"])),
        )
    return rec


def moment_half_width(x, p, w):
    """2 sqrt(second central moment of p(x)): the half-width a for a Hertz profile
    p0 sqrt(1 - x^2/a^2); an integral measure, free of the zone ends' sampling."""
    m0 = np.sum(w * p)
    c = np.sum(w * p * x) / m0
    return float(2 * np.sqrt(np.sum(w * p * (x - c) ** 2) / m0))


def pressure_diff(ref, other, average=None):
    """Relative L2 difference of p(x): `other` interpolated onto `ref`'s points (weights w of
    ref); average: a width over which both are first averaged (window_average)."""
    x, p, w = (np.asarray(ref[k]) for k in ("x", "p", "w"))
    xo, po = np.asarray(other["x"]), np.asarray(other["p"])
    if average:
        p, po = window_average(x, p, average), window_average(xo, po, average)
    q = np.interp(x, xo, po, left=0.0, right=0.0)
    return float(np.sqrt(np.sum(w * (q - p) ** 2) / np.sum(w * p**2)))


def compare(fit, cut):
    """The path differences at one h (see the module docstring)."""
    P_f, P_c = fit["reaction"][1], cut["reaction"][1]
    return dict(
        h=fit["h"],
        reaction_rel_diff=abs(P_f - P_c) / abs(P_f),
        reaction_x_diff=abs(fit["reaction"][0] - cut["reaction"][0]) / abs(P_f),
        half_width_rel_diff=abs(fit["half_width"] - cut["half_width"]) / fit["half_width"],
        half_width_moment_rel_diff=abs(fit["half_width_moment"] - cut["half_width_moment"])
        / fit["half_width_moment"],
        centre_diff=abs(fit["centre"] - cut["centre"]) / fit["half_width"],
        pressure_rel_l2_diff=pressure_diff(fit, cut),
        pressure_rel_l2_diff_averaged=pressure_diff(fit, cut, average=fit["h"]),
    )


DIFFS = (
    "reaction_rel_diff",
    "half_width_rel_diff",
    "half_width_moment_rel_diff",
    "pressure_rel_l2_diff",
    "pressure_rel_l2_diff_averaged",
)


def rates(comparisons):
    """log2 of the ratio of consecutive differences (h halves between records)."""
    out = []
    for c0, c1 in zip(comparisons[:-1], comparisons[1:]):
        r = {"h": c1["h"]}
        for k in DIFFS:
            r[k] = float(np.log(c0[k] / c1[k]) / np.log(c0["h"] / c1["h"])) if c1[k] > 0 else None
        out.append(r)
    return out


def run_all(hs=HS, comm=MPI.COMM_WORLD):
    records, comparisons = [], []
    for h in hs:
        fit, cut = run_path("fitted", h, comm=comm), run_path("cut", h, comm=comm)
        records += [fit, cut]
        if comm.rank == 0:
            comparisons.append(compare(fit, cut))
    return records, comparisons


def table(records, comparisons):
    by = {(r["path"], r["h"]): r for r in records}
    lines = [
        f"{'h':>6} {'dofs fit':>9} {'dofs cut':>9} {'Fy fit':>10} {'Fy cut':>10} "
        f"{'dFy/Fy':>9} {'a fit':>7} {'a cut':>7} {'da/a':>9} {'dam/am':>9} {'dp L2':>8} "
        f"{'dp avg':>8} {'t fit s':>7} {'t cut s':>7}"
    ]
    for c in comparisons:
        f, k = by[("fitted", c["h"])], by[("cut", c["h"])]
        lines.append(
            f"{c['h']:6.3g} {f['dofs']:9d} {k['dofs']:9d} {f['reaction'][1]:10.2f} "
            f"{k['reaction'][1]:10.2f} {c['reaction_rel_diff']:9.2e} "
            f"{f['half_width']:7.4f} {k['half_width']:7.4f} "
            f"{c['half_width_rel_diff']:9.2e} {c['half_width_moment_rel_diff']:9.2e} "
            f"{c['pressure_rel_l2_diff']:8.2e} "
            f"{c['pressure_rel_l2_diff_averaged']:8.2e} {f['time_s']:7.2f} "
            f"{k['time_s']:7.2f}"
        )
    return "\n".join(lines)


def plot(path, records, comparisons, rate_rows, iso=None):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, axt) = plt.subplots(2, 1, figsize=(12, 9), gridspec_kw=dict(height_ratios=[3, 2]))
    h = np.array([c["h"] for c in comparisons])
    labels = {
        "reaction_rel_diff": "reaction |dFy|/Fy",
        "half_width_rel_diff": "half-width |da|/a",
        "half_width_moment_rel_diff": "moment half-width |da_m|/a_m",
        "pressure_rel_l2_diff": "p(x) rel. L2",
        "pressure_rel_l2_diff_averaged": "p(x) rel. L2, averaged over h",
    }
    for k, lab in labels.items():
        ax.loglog(h, [c[k] for c in comparisons], "o-", label=lab)
    ax.loglog(
        h, comparisons[0]["reaction_rel_diff"] * (h / h[0]) ** 2, "k:", lw=0.8, label="slope 2"
    )
    ax.loglog(
        h, comparisons[0]["pressure_rel_l2_diff"] * (h / h[0]), "k--", lw=0.8, label="slope 1"
    )
    if iso is not None:
        ax.axhline(iso, color="r", lw=0.8, label="|Fy(orthotropic) - Fy(isotropic)| / Fy")
    ax.set_xlabel("h (mm)")
    ax.set_ylabel("body-fitted vs cut, relative difference")
    ax.set_title(
        "Same OrthotropicElastic law, half-ellipse on a block: body-fitted (P1) vs " "cut (Q1)",
        fontsize=10,
    )
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    axt.axis("off")
    by = {(r["path"], r["h"]): r for r in records}
    rows = []
    rate_by = {r["h"]: r for r in rate_rows}
    for c in comparisons:
        f, k = by[("fitted", c["h"])], by[("cut", c["h"])]
        rr = rate_by.get(c["h"], {})

        def rate(key):
            v = rr.get(key)
            return "" if v is None else f" ({v:.2f})"

        rows.append(
            [
                f"{c['h']:g}",
                f"{f['dofs']}",
                f"{k['dofs']}",
                f"{f['reaction'][1]:.2f}",
                f"{k['reaction'][1]:.2f}",
                f"{c['reaction_rel_diff']:.2e}" + rate("reaction_rel_diff"),
                f"{c['half_width_rel_diff']:.2e}" + rate("half_width_rel_diff"),
                f"{c['half_width_moment_rel_diff']:.2e}" + rate("half_width_moment_rel_diff"),
                f"{c['pressure_rel_l2_diff']:.2e}" + rate("pressure_rel_l2_diff"),
                f"{f['time_s']:.1f}",
                f"{k['time_s']:.1f}",
            ]
        )
    tab = axt.table(
        cellText=rows,
        colLabels=[
            "h",
            "dofs fit",
            "dofs cut",
            "Fy fit",
            "Fy cut",
            "dFy/Fy (rate)",
            "da/a (rate)",
            "da_m/a_m (rate)",
            "dp L2 (rate)",
            "t fit (s)",
            "t cut (s)",
        ],
        loc="center",
    )
    tab.auto_set_font_size(False)
    tab.set_fontsize(8)
    tab.scale(1, 1.4)
    fig.tight_layout()
    write_atomic(path, lambda tmp: fig.savefig(tmp, dpi=110, format="png"))
    plt.close(fig)


def floats(text):
    vals = [bounded("--h", 0, None, lo_open=True)(v) for v in text.split(",") if v.strip()]
    if not vals:
        raise ValueError
    return vals


def parse(argv):
    p = DemoParser(prog="orthotropic_paths.py", description=__doc__.split("\n\n")[0])
    p.add_argument(
        "--out-dir",
        default=str(ROOT / "benchmarks" / "results"),
        help="folder of orthotropic_paths.json and .png (default benchmarks/results)",
    )
    p.add_argument(
        "--h",
        type=floats,
        default=list(HS),
        help="mesh sizes, each half the previous (default 0.2,0.1,0.05,0.025; the "
        "zone 1.6 must be a multiple of each)",
    )
    return p.parse_args(argv)


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    comm = MPI.COMM_WORLD
    t0 = time.perf_counter()
    records, comparisons = run_all(args.h, comm)
    # the law matters: isotropic E = E2, nu = 0.3 at the coarsest h, on both paths
    iso = {p: run_path(p, args.h[0], law=iso_law(), comm=comm) for p in PATHS}
    if comm.rank != 0:
        return 0
    ortho0 = {r["path"]: r for r in records if r["h"] == args.h[0]}
    iso_diffs = {
        p: abs(iso[p]["reaction"][1] - ortho0[p]["reaction"][1]) / abs(ortho0[p]["reaction"][1])
        for p in PATHS
    }
    iso_diff = min(iso_diffs.values())
    rate_rows = rates(comparisons)
    data = dict(
        benchmark="orthotropic_paths",
        git=git_head(),
        parameters=dict(
            geometry=GEOMETRY,
            orthotropic=ORTHO,
            isotropic=ISO,
            delta=DELTA,
            eps0=EPS0,
            h_far_over_h=H_FAR,
            h=args.h,
            mu=0.0,
        ),
        comparisons=comparisons,
        rates=rate_rows,
        isotropic={
            p: dict(
                h=args.h[0],
                reaction=iso[p]["reaction"],
                half_width=iso[p]["half_width"],
                reaction_rel_diff_to_orthotropic=iso_diffs[p],
            )
            for p in PATHS
        },
        records=[{k: v for k, v in r.items() if k not in ("x", "p", "w")} for r in records],
        total_time_s=time.perf_counter() - t0,
    )
    out = Path(args.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    json_path, png_path = out / "orthotropic_paths.json", out / "orthotropic_paths.png"

    def write_json(tmp):
        with open(tmp, "w") as f:
            json.dump(data, f, indent=2)

    write_atomic(json_path, write_json)
    plot(png_path, records, comparisons, rate_rows, iso=iso_diff)
    print(table(records, comparisons))
    for r in rate_rows:
        print(
            f"rates at h={r['h']:g}: "
            + ", ".join(f"{k} {'n/a' if r[k] is None else f'{r[k]:.2f}'}" for k in DIFFS)
        )
    print(
        f"isotropic (E={ISO['E']:g}, nu={ISO['nu']:g}) vs orthotropic reaction at h="
        f"{args.h[0]:g}: "
        + ", ".join(f"{p} {d:.2%}" for p, d in iso_diffs.items())
        + f"; Fx orthotropic {ortho0['fitted']['reaction'][0]:.4g} / "
        f"{ortho0['cut']['reaction'][0]:.4g}, isotropic {iso['fitted']['reaction'][0]:.2g} / "
        f"{iso['cut']['reaction'][0]:.2g}"
    )
    print(f"results in {json_path.resolve()} and {png_path.resolve()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
