#!/usr/bin/python3
"""A column of N identical discs between rigid platens, frictionless (issue: particle
assemblies, acceptance "disc column"): every contact carries the applied force, and each
contact's half-width against Hertz, a = 2 sqrt(F R (1 - nu^2) / (pi E)) for disc-disc
(R* = R/2, E* = E / (2 (1 - nu^2))) and disc-platen (R* = R, E* = E / (1 - nu^2)) alike.
Writes benchmarks/results/disc_column.{csv,json,png}.

Run: /usr/bin/python3 benchmarks/disc_column.py [--n 5] [--h 0.25] [--steps 80]
"""

import argparse
import csv
import json
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from dolfinx_forms.fem.boundary import Dirichlet
from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
from meshes.mpm import disc_column

ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
ap.add_argument("--n", type=int, default=5)
ap.add_argument("--R", type=float, default=10.0)
ap.add_argument("--h", type=float, default=0.25)
ap.add_argument("--step", type=float, default=0.05)
ap.add_argument("--steps", type=int, default=80)
ap.add_argument("--eps0", type=float, default=0.2)
ap.add_argument("--out", default="benchmarks/results")
a = ap.parse_args()
E, nu = 100e3, 0.3
comm = MPI.COMM_WORLD
grid, bodies, platens, build = disc_column(comm, a.n, a.R, a.h, a.step, a.steps)
sim = ImplicitMPM(
    comm,
    grid,
    [MPMBody(n, t, (E, nu), s) for n, t, s in bodies],
    build,
    obstacles=platens,
    dirichlet=[Dirichlet(lambda x: np.isclose(x[0], 0.0), 0, 0.0)],
    eps0=a.eps0,
    log=lambda *x, **k: None,
)
rows, t0 = [], time.perf_counter()
for k in range(a.steps):
    rec = sim.step()
    F = np.array([abs(p["fy"]) for p in rec["pairs"]])
    for p, f in zip(rec["pairs"], F):
        aH = 2 * np.sqrt(f * a.R * (1 - nu**2) / (np.pi * E))
        rows.append(
            dict(
                step=rec["step"],
                pair=f"{p['body_i']}-{p['body_j']}",
                force=f,
                force_spread=float(np.ptp(F) / F.max()),
                half_width=p["half_width"],
                hertz=aH,
                rel_error=p["half_width"] / aH - 1,
                a_over_h=p["half_width"] / a.h,
                newton=rec["newton_iterations"],
                wall_s=rec["wall_s"],
            )
        )
    if comm.rank == 0:
        print(
            f"step {k + 1}: F = {F.max():.5g}, spread {np.ptp(F) / F.max():.1e}, a/h "
            f"{min(r['a_over_h'] for r in rows[-len(F):]):.2f}.."
            f"{max(r['a_over_h'] for r in rows[-len(F):]):.2f}, "
            f"max |a/aH - 1| {max(abs(r['rel_error']) for r in rows[-len(F):]):.3f}, "
            f"Newton {rec['newton_iterations']}, {rec['wall_s']:.2f} s",
            flush=True,
        )
if comm.rank == 0:
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "disc_column.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    judged = [r for r in rows if r["a_over_h"] > 5]
    summary = dict(
        params=vars(a),
        num_dofs=rec["num_dofs"],
        total_s=time.perf_counter() - t0,
        force_spread_max=max(r["force_spread"] for r in rows),
        judged=len(judged),
        rel_error_max_a_gt_5h=max((abs(r["rel_error"]) for r in judged), default=None),
        timing_s=dict(sim.timer.timing) if sim.timer else None,
    )
    (out / "disc_column.json").write_text(json.dumps(summary, indent=1))
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 4))
    for pair in sorted({r["pair"] for r in rows}):
        rr = [r for r in rows if r["pair"] == pair]
        ax.plot([r["a_over_h"] for r in rr], [r["rel_error"] for r in rr], ".-", ms=3, label=pair)
    ax.axvline(5, color="0.6", ls=":")
    ax.axhspan(-0.05, 0.05, color="0.9")
    ax.set(xlabel="a / h", ylabel="a / a_Hertz - 1", title=f"column of {a.n} discs")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "disc_column.png", dpi=120)
    print(json.dumps(summary))
