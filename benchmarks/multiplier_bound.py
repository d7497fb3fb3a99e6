#!/usr/bin/python3
"""How well can a multiplier space carry the Hertz pressure? The best L2 approximation of
p(x) = p0 sqrt(1 - x^2 / a^2) (zero for |x| > a) by continuous piecewise polynomials on uniform
elements, as a floor under the p(x) error of any contact pressure that lives in that space
(the augmented enforcement's P1 multipliers, `contact.multiplier_nodes`).

Issue 11 asks the augmented Hertz run at h = a/20 for a p(x) L2 error at most the penalty's
(1.16 % body-fitted, 1.85 % cut). The penalty's pressure is point-wise (eps times the gap of the
traces at each Gauss point), not bound to a multiplier space; the augmented one is P1 on
elements about h (body-fitted) or 1.5 h (cut) long. This script gives the floor of each space:
for element length H = f h (f in --factors) and degree 1 or 2, the relative L2 error of the
best approximation on [-1.6 a, 1.6 a] (where Gamma_c of the demo lies), minimum and maximum
over 10 offsets of the element ends against the contact centre (a run does not choose them).
Integrals: 40-point Gauss-Legendre per element, split at x = +-a (the kink), so exact to
round-off for the square root's smooth pieces; the normal equations are solved directly.

Writes (replaced atomically) <out-dir>/multiplier_bound.json and multiplier_bound.png, and
prints a table. Numpy only: nothing is solved.

Usage: /usr/bin/python3 benchmarks/multiplier_bound.py [--out-dir benchmarks/results]
           [--divisor 20] [--factors 0.5,0.75,1,1.5,2,3]
"""

import argparse
import io
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def hertz(x):
    """The Hertz pressure of unit p0 and a."""
    return np.sqrt(np.clip(1.0 - x**2, 0.0, None))


def best_approximation(degree, H, offset, f=hertz, kinks=(-1.0, 1.0), extent=1.6, gauss=40):
    """Relative L2 error of the best approximation of f (smooth between its `kinks`) on
    [-extent, extent] by continuous Lagrange polynomials of `degree` on elements of length H
    whose ends lie on offset + H Z (the domain covered by whole elements)."""
    xg, wg = np.polynomial.legendre.leggauss(gauss)
    first = offset + np.floor((-extent - offset) / H) * H
    ends = np.arange(first, extent + H, H)
    n_el = len(ends) - 1
    M = np.zeros((n_el * degree + 1,) * 2)
    b = np.zeros(n_el * degree + 1)
    norm2 = 0.0
    nodes = np.linspace(-1.0, 1.0, degree + 1)
    for e in range(n_el):
        x0, x1 = ends[e], ends[e + 1]
        cuts = [x0] + [c for c in kinks if x0 < c < x1] + [x1]
        for lo, hi in zip(cuts[:-1], cuts[1:]):
            x = 0.5 * (lo + hi) + 0.5 * (hi - lo) * xg
            w = 0.5 * (hi - lo) * wg
            s = 2.0 * (x - x0) / (x1 - x0) - 1.0
            N = np.array(
                [
                    np.prod(
                        [
                            (s - nodes[m]) / (nodes[k] - nodes[m])
                            for m in range(degree + 1)
                            if m != k
                        ],
                        axis=0,
                    )
                    for k in range(degree + 1)
                ]
            )
            p = f(x)
            idx = e * degree + np.arange(degree + 1)
            M[np.ix_(idx, idx)] += (N * w) @ N.T
            b[idx] += (N * w) @ p
            norm2 += w @ p**2
    c = np.linalg.solve(M, b)
    return float(np.sqrt(max(norm2 - b @ c, 0.0) / norm2))


def table(divisor, factors, offsets=10):
    h = 1.0 / divisor
    rows = []
    for degree in (1, 2):
        for f in factors:
            H = f * h * degree  # P2 on elements f * 2h: the nodes f * h apart, like P1's
            e = [best_approximation(degree, H, o) for o in np.linspace(0.0, H, offsets + 1)[:-1]]
            rows.append(
                dict(degree=degree, node_spacing_h=f, element_h=f * degree, min=min(e), max=max(e))
            )
    return rows


def plot(rows, divisor, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    for degree, c in ((1, "tab:blue"), (2, "tab:green")):
        r = [x for x in rows if x["degree"] == degree]
        f = [x["node_spacing_h"] for x in r]
        lo, hi = [100 * x["min"] for x in r], [100 * x["max"] for x in r]
        ax.fill_between(f, lo, hi, color=c, alpha=0.25)
        ax.plot(f, lo, "o-", color=c, label=f"P{degree}: best approximation (range over offsets)")
        ax.plot(f, hi, "o--", color=c)
    for v, lab in ((1.16, "penalty, body-fitted"), (1.85, "penalty, cut")):
        ax.axhline(v, color="0.4", ls=":", lw=1)
        ax.text(ax.get_xlim()[0], v, f" {lab} {v} %", va="bottom", fontsize=8)
    ax.set_xlabel("node spacing / h")
    ax.set_ylabel("relative L2 error of p(x) (%)")
    ax.set_title(f"Hertz pressure in a multiplier space, h = a/{divisor}", fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    return buf.getvalue()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out-dir", type=Path, default=ROOT / "benchmarks" / "results")
    ap.add_argument("--divisor", type=float, default=20.0, help="h = a / divisor (20)")
    ap.add_argument("--factors", default="0.5,0.75,1,1.5,2,3", help="node spacings / h")
    a = ap.parse_args(argv)
    try:
        factors = [float(v) for v in a.factors.split(",")]
    except ValueError:
        ap.error(f"--factors: comma-separated numbers, got {a.factors!r}")
    if not all(0.05 <= f <= 10 for f in factors) or not 2 <= a.divisor <= 200:
        ap.error("--factors each in [0.05, 10], --divisor in [2, 200]")
    if not a.out_dir.is_dir():
        ap.error(f"--out-dir {a.out_dir}: not a folder")
    rows = table(a.divisor, sorted(factors))
    print("degree  node spacing/h  best L2 error (min .. max over offsets)")
    for r in rows:
        print(
            f"P{r['degree']}      {r['node_spacing_h']:5.2f}           "
            f"{100 * r['min']:.2f} .. {100 * r['max']:.2f} %"
        )
    from benchmarks.common import write_atomic, write_json

    write_json(a.out_dir / "multiplier_bound.json", dict(divisor=a.divisor, rows=rows))
    png = plot(rows, a.divisor, None)

    def writer(tmp):
        with open(tmp, "wb") as f:
            f.write(png)

    write_atomic(a.out_dir / "multiplier_bound.png", writer)
    print(f"results in {a.out_dir}/multiplier_bound.json, .png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
