#!/usr/bin/python3
"""Broad-phase time against the number of grains (issue: particle assemblies, "broad-phase
time linear in N"): `_cpp.candidate_pairs` on jittered lattices of grain boxes
(meshes.grains.lattice_boxes), the minimum of 30 runs per N. Writes
benchmarks/results/broad_phase.{json,png}.

Run: /usr/bin/python3 benchmarks/broad_phase.py
"""

import json
import time
from pathlib import Path

import numpy as np

from dolfinx_forms import _cpp
from meshes.grains import lattice_boxes

rng = np.random.default_rng(0)
rows = []
for n in (25, 100, 400, 1600, 6400, 25600):
    b = lattice_boxes(n, rng)
    times = []
    for _ in range(30):
        t0 = time.perf_counter()
        p = _cpp.candidate_pairs(b, 0.02)
        times.append(time.perf_counter() - t0)
    rows.append(dict(n=n, pairs=len(p), min_s=min(times), median_s=float(np.median(times))))
    print(
        f"N = {n:6d}: {len(p):6d} pairs, {1e6 * min(times):9.1f} us "
        f"({1e6 * min(times) / n:.3f} us per grain)"
    )
out = Path(__file__).resolve().parent / "results"
out.mkdir(exist_ok=True)
(out / "broad_phase.json").write_text(json.dumps(rows, indent=1))
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

fig, ax = plt.subplots(figsize=(5, 4))
n = np.array([r["n"] for r in rows])
ax.loglog(n, [r["min_s"] for r in rows], "o-", label="candidate_pairs")
ax.loglog(n, rows[0]["min_s"] * n / n[0], "k:", label="linear")
ax.set(xlabel="grains N", ylabel="time (s)", title="broad phase")
ax.legend()
fig.tight_layout()
fig.savefig(out / "broad_phase.png", dpi=120)
