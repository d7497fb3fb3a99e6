#!/usr/bin/python3
"""The DEM peer of demos/granular_column.py: the same random disc samples and wall protocol
(meshes/column.py) run by LAMMPS's GRANULAR package (Debian's lmp) with rigid discs, so that the
material point method's deformable grains are compared with the rigid limit on the same table,
steps.csv (meshes.column.COLUMNS, a row every --interval).

What is compared, per seed (--seeds) and Young's modulus (--E): the stress ratio from the wall
forces, the coordination number, the grain-grain normal forces' mean and coefficient of
variation, and their mean in units of the sample's stress, force_mean_pd (meshes/column.py: the
mean with a rigid limit). summary.json: their mean and standard deviation (ddof 1) over the seeds
at the end of compression and of shear, each LAMMPS run's wall time, the LAMMPS version, and
("comparison") the --mpm runs' at the same E against the DEM's band; dem_peer.png: the DEM
mean with a +-1 std band against the shear strain (shear phase) and the time (all phases), and
the --mpm result folders of demos/granular_column.py grouped by their --E, each group a dashed
line with its own band over the runs.

The LAMMPS model: 2D, atom_style sphere, mass rho pi r^2 (`set density/disc`), a disc's inertia
(`fix nve/sphere disc`). Contacts: `pair_coeff * * hertz/material E e nu tangential mindlin NULL
1.0 mu damping tsuji` of `pair_style granular` (Mindlin's stiffness from E and nu, tangential
damping that of the normal). This LAMMPS (29 Sep 2021) has no `damping coeff_restitution`;
`tsuji` takes the same restitution coefficient e = --restitution 0.05: at t = 20 (seeds 1-10)
the walls carry the weight within 1.5 % (e = 0.1: 2.8 %, 0.3: 3.6 %; late rearrangements, rolling,
are what is left). Walls: four `fix wall/gran/region granular <the same model, mu = --wall-mu>
region R contacts`, R a `region plane` that `move`s by equal-style variables of the step,
Protocol.walls's formulas. After deposition the settled height H (max y + r above the bottom) is
frozen by an immediate variable and the top wall put on the sample as a new region (moving the
old one there would give it a huge velocity for a step: LAMMPS takes a region's velocity from
its displacement per step). `fix gravity`, `fix enforce2d`. Time step: the Hertz impact time
t_c = 2.87 (m*^2 / (R* E*^2 v))^(1/5) of the two smallest discs (m* = m / 2, R* = r / 2,
E* = E / (2 (1 - nu^2))) at the free-fall speed over the box, v = sqrt(2 g L); dt = t_c / 50,
rounded down to divide --interval.

Outputs every --interval: each wall's normal force, minus the sum of the forces its fix adds to
the particles (the fix's `contacts` per-atom array: exact); the grain-grain normal forces
(`compute pair/local force cutoff radius`: Fn of each overlapping pair, damping included; those
<= 0 are open for contact_statistics); the kinetic energy sum m v^2 / 2 + I omega^2 / 2.

Run: /usr/bin/python3 benchmarks/dem_peer.py [--seeds 1 2 3 4 5] [--E 1e4 ...] [--grains 100]
         [--out results/dem_peer] [--mpm DIR ...]     (Debian's lammps: `make bench`)
"""

import argparse
import csv
import json
import os
import shutil
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from meshes import column

# force_mean_pd: the force mean in units of the sample's stress (meshes/column.py), the one
# with a rigid limit
METRICS = ("stress_ratio", "coordination", "force_mean", "force_cv", "force_mean_pd")
PLOTTED = ("stress_ratio", "coordination", "force_mean_pd")  # dem_peer.png's rows
# fmt: off
OPTIONS = [  # option, type, accepted range, default, help
    ("--grains", int, "[2, 100000]", 100, "number of discs"),
    ("--radius", float, "(0, inf)", 1.0, "mean radius"),
    ("--polydispersity", float, "[0, 0.5]", 0.2, "radii uniform in radius (1 -+ this)"),
    ("--fraction", float, "(0, 0.5]", 0.35, "area fraction of the initial box"),
    ("--nu", float, "[0, 0.5)", 0.3, "Poisson's ratio"),
    ("--mu", float, "[0, 10]", 0.3, "friction coefficient"),
    ("--wall-mu", float, "[0, 10]", None, "the walls' friction coefficient (default --mu)"),
    ("--restitution", float, "(0, 1]", 0.05, "restitution coefficient (damping tsuji)"),
    ("--rho", float, "(0, inf)", 1.0, "density (mass per area)"),
    ("--g", float, "(0, inf)", 1.0, "gravity"),
    ("--t-deposit", float, "(0, inf)", 25.0, "deposition time"),
    ("--t-compress", float, "(0, inf)", 5.0, "compression time"),
    ("--t-shear", float, "(0, inf)", 10.0, "shear time"),
    ("--compression", float, "[0, 0.2]", 0.01, "top wall travel / settled height"),
    ("--shear-strain", float, "[0, 0.5]", 0.1, "eps_yy - eps_xx at the end"),
    ("--interval", float, "(0, inf)", 0.1, "time between rows"),
]
# fmt: on


class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line naming the option, exit 2
        self.exit(2, f"{self.prog}: {message}\n")


def ranged(kind, spec):
    """An argparse type: a `kind` in the interval spec, "(0, inf)", "[0, 1)", ..."""
    lo, hi = (float(s) for s in spec[1:-1].split(","))

    def parse(text):
        try:
            x = kind(text)
        except ValueError:
            x = None
        shut = (spec[0] == "(" and x == lo) or (spec[-1] == ")" and x == hi)
        if x is None or not lo <= x <= hi or shut:
            raise argparse.ArgumentTypeError(f"expected {kind.__name__} in {spec}, got {text!r}")
        return x

    return parse


def parse(argv):
    p = Parser(prog="dem_peer.py", description=__doc__.split("\n\n")[0])
    for name, kind, spec, default, text in OPTIONS:
        p.add_argument(name, type=ranged(kind, spec), default=default, help=f"{text} {spec}")
    p.add_argument("--seeds", type=ranged(int, "[0, 1e9]"), nargs="+", default=[1, 2, 3, 4, 5])
    p.add_argument("--E", type=ranged(float, "(0, inf)"), nargs="+", default=[1e4], help="moduli")
    p.add_argument("--out", default="results/dem_peer")
    p.add_argument("--mpm", nargs="+", default=[], help="demos/granular_column.py result folders")
    a = p.parse_args(argv)
    for name in ("t_deposit", "t_compress", "t_shear"):  # each phase ends on a row
        k = getattr(a, name) / a.interval
        if abs(k - round(k)) > 1e-6 * max(1.0, k):
            p.error(f"--{name.replace('_', '-')}: expected a multiple of --interval "
                    f"{a.interval:g}, got {getattr(a, name):g}")  # fmt: skip
    for d in a.mpm:
        if not (Path(d) / "steps.csv").is_file():
            p.error(f"--mpm: expected folders with a steps.csv, got {d}")
    return a


def time_step(sample, a, E):
    """(dt, steps per row): dt = t_c / 50 (module docstring), interval / dt whole."""
    r = sample.radius.min()
    m_eff, r_eff, e_eff = a.rho * np.pi * r**2 / 2, r / 2, E / (2 * (1 - a.nu**2))
    v = np.sqrt(2 * a.g * np.ptp(sample.box[:, 1]))
    t_c = 2.87 * (m_eff**2 / (r_eff * e_eff**2 * v)) ** 0.2
    k = int(np.ceil(a.interval / (t_c / 50)))
    return a.interval / k, k


def contact_model(a, E, mu):
    return (f"hertz/material {E!r} {a.restitution!r} {a.nu!r} "
            f"tangential mindlin NULL 1.0 {mu!r} damping tsuji")  # fmt: skip


def lammps_input(sample, a, E, dt, k):
    """The LAMMPS input of one run (module docstring); the discs in grains.data."""
    (x0, y0), (x1, y1) = sample.box.tolist()
    w2, grains = (x1 - x0) / 2, contact_model(a, E, a.mu)
    model = contact_model(a, E, a.mu if a.wall_mu is None else a.wall_mu)  # the walls'
    steps = [round(t / dt) for t in (a.t_deposit, a.t_compress, a.t_shear)]
    walls = "\n".join(
        f"region {w} plane {p}\n"
        f"fix {w} all wall/gran/region granular {model} region {w} contacts"
        for w, p in (("wl", f"{x0!r} 0 0 1 0 0 move v_dleft NULL NULL"),
                     ("wr", f"{x1!r} 0 0 -1 0 0 move v_dright NULL NULL"),
                     ("wb", f"0 {y0!r} 0 0 1 0"), ("wt", f"0 {y1!r} 0 0 -1 0"))
    )  # fmt: skip
    return f"""# benchmarks/dem_peer.py: {len(sample.radius)} discs, E {E!r}
units lj
dimension 2
atom_style sphere
boundary f f p
comm_modify vel yes
read_data grains.data
set group all density/disc {a.rho!r}
neighbor {0.2 * a.radius!r} bin
neigh_modify delay 0 every 1 check yes
pair_style granular
pair_coeff * * {grains}
timestep {dt!r}
# the walls, Protocol.walls (u, v: the phases' progress by steps, clamped to [0, 1] in s,
# strain; dtop: the top wall from the settled top, H, measured after deposition)
variable H equal 0.0
variable u equal (step-{steps[0]})/{steps[1]}
variable v equal (step-{steps[0]}-{steps[1]})/{steps[2]}
variable s equal v_u*(v_u>0.0)*(v_u<1.0)+(v_u>=1.0)
variable strain equal {a.shear_strain!r}*(v_v*(v_v>0.0)*(v_v<1.0)+(v_v>=1.0))
variable dright equal {w2!r}*(exp(0.5*v_strain)-1.0)
variable dleft equal -v_dright
variable dtop equal v_H*((1.0-{a.compression!r}*v_s)*exp(-0.5*v_strain)-1.0)
variable top equal (v_u<=0.0)*{y1!r}+(v_u>0.0)*({y0!r}+v_H+v_dtop)
{walls}
fix gravity all gravity {a.g!r} vector 0 -1 0
fix integrate all nve/sphere disc
fix 2d all enforce2d
# outputs: the walls' normal forces (minus the particles' wall forces), kinetic energy, Fn
compute f all reduce sum f_wl[2] f_wr[2] f_wb[3] f_wt[3] f_wl[3] f_wr[3]
compute atom all property/atom radius omegaz
variable ke atom 0.5*mass*(vx*vx+vy*vy+0.5*(c_atom[1]*c_atom[2])^2)
compute ke all reduce sum v_ke
variable ytop atom y+c_atom[1]
compute ytop all reduce max v_ytop
compute pair all pair/local force cutoff radius
fix out all print {k} "$(step) $({x0!r}+v_dleft) $({x1!r}+v_dright) $(v_top) \
$(c_f[1]) $(-c_f[2]) $(c_f[3]) $(-c_f[4]) $(c_f[3]+c_f[4]+c_f[5]+c_f[6]) $(c_ke)" \
file walls.txt screen no
dump pairs all local {k} pairs.txt c_pair
dump_modify pairs format float %.12g
thermo {50 * k}
thermo_style custom step time c_ytop c_ke
run {steps[0]}
variable H equal $(c_ytop-{y0!r})
print "$(v_H:%.17g)" file settled.txt screen no
# the top wall put on the sample (a new region: no jump in its velocity), enforce2d last
unfix wt
unfix 2d
region wt2 plane 0 $({y0!r}+v_H) 0 0 -1 0 move NULL v_dtop NULL
fix wt all wall/gran/region granular {model} region wt2 contacts
fix 2d all enforce2d
run {steps[1]}
run {steps[2]}
"""


def read_local(path):
    """{step: the entries of that snapshot} of a one-column `dump local` file."""
    lines, out, i = Path(path).read_text().split("\n"), {}, 0
    while i + 8 < len(lines) and lines[i].startswith("ITEM: TIMESTEP"):
        step, n = int(lines[i + 1]), int(lines[i + 3])
        out[step] = np.array(lines[i + 9 : i + 9 + n], float)
        i += 9 + n
    return out


def run_one(sample, a, E, folder):
    """LAMMPS on one sample and modulus in folder: (steps.csv rows, the run's record)."""
    folder.mkdir(parents=True, exist_ok=True)
    dt, k = time_step(sample, a, E)
    discs = zip(sample.radius.tolist(), sample.centre.tolist())
    atoms = "\n".join(f"{i} 1 {2 * r!r} {a.rho!r} {x!r} {y!r} 0.0"
                      for i, (r, (x, y)) in enumerate(discs, 1))  # fmt: skip
    pad = 0.25 * np.ptp(sample.box[:, 0]) + 4 * sample.radius.max()  # room for moving walls
    lo, hi = (sample.box[0] - pad).tolist(), (sample.box[1] + pad).tolist()
    (folder / "grains.data").write_text(
        f"dem_peer.py discs\n\n{len(sample.radius)} atoms\n1 atom types\n\n{lo[0]!r} {hi[0]!r} "
        f"xlo xhi\n{lo[1]!r} {hi[1]!r} ylo yhi\n-0.5 0.5 zlo zhi\n\nAtoms # sphere\n\n{atoms}\n"
    )
    (folder / "in.lammps").write_text(lammps_input(sample, a, E, dt, k))
    t0 = time.perf_counter()
    proc = subprocess.run(["lmp", "-in", "in.lammps", "-log", "log.lammps", "-screen", "none",
                           "-nocite"], cwd=folder, env=dict(os.environ, OMP_NUM_THREADS="1"),
                          capture_output=True, text=True)  # fmt: skip
    seconds = time.perf_counter() - t0
    log = (folder / "log.lammps").read_text() if (folder / "log.lammps").exists() else ""
    if proc.returncode != 0:
        error = [q for q in (log + proc.stdout + proc.stderr).splitlines() if "ERROR" in q]
        raise SystemExit(f"dem_peer.py: LAMMPS failed in {folder}: {error or proc.returncode}")
    protocol = column.Protocol(sample.box, a.t_deposit, a.t_compress, a.t_shear,
                               a.compression, a.shear_strain)  # fmt: skip
    w = np.loadtxt(folder / "walls.txt", ndmin=2)
    steps, first = np.unique(w[:, 0].astype(int), return_index=True)  # each run's setup repeats
    w, pairs = w[first], read_local(folder / "pairs.txt")
    rows = []
    for step, (left, right, top, *f, vertical, ke) in zip(steps, w[:, 1:]):
        walls = dict(left=left, right=right, bottom=float(sample.box[0, 1]), top=top)
        t = round(step / k * a.interval, 9)
        rows.append(column.row(protocol, t, walls, dict(zip(walls, f)), pairs.get(step, ()), sample,
                               ke))  # fmt: skip
        if abs(t - a.t_deposit) < 1e-6:  # the deposit: what the walls carry
            deposited = dict(rows[-1], vertical=vertical)
    weight = a.rho * a.g * np.pi * float(np.sum(sample.radius**2))
    record = dict(E=E, dt=dt, steps=int(steps[-1]), run_time_s=seconds, weight=weight,
                  settled_height=float((folder / "settled.txt").read_text()),
                  bottom_over_weight=deposited["force_bottom"] / weight,
                  walls_vertical_over_weight=deposited["vertical"] / weight,
                  kinetic_energy_deposited=deposited["kinetic_energy"],
                  version=log.splitlines()[0].strip() if log else "")  # fmt: skip
    return rows, record


def spread(values):
    """(mean, std over the seeds, ddof 1, 0 for one seed) along axis 0, nan-aware."""
    v = np.asarray(values, float)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-nan rows: the free fall
        mean = np.nanmean(v, axis=0)
        return mean, np.nanstd(v, axis=0, ddof=1) if len(v) > 1 else np.zeros_like(mean)


def mpm_curves(folders, dt=0.1):
    """The MPM runs (demos/granular_column.py result folders) grouped by their --E: per group
    the mean and spread over the runs (as for the DEM's seeds) of each run's rows sampled every
    `dt` (the last accepted step at or before each time: the runs' adaptive steps differ)."""
    groups = {}
    for d in folders:
        E, s = read_mpm(d)
        groups.setdefault(E, []).append(s)
    curves = []
    for E, runs in groups.items():
        t = np.arange(0.0, min(s["t"][-1] for s in runs) + 1e-9, dt)
        at = [np.maximum(np.searchsorted(s["t"], t + 1e-9, side="right") - 1, 0) for s in runs]
        c = {k: runs[0][k][at[0]] for k in ("phase", "shear_strain")}
        c["t"], std = t, {}
        for key in PLOTTED:
            c[key], std[key] = spread([s[key][i] for s, i in zip(runs, at)])
        label = f"MPM E={E:g}" if E is not None else "MPM"
        curves.append((f"{label} ({len(runs)} runs)", c, std if len(runs) > 1 else None))
    return curves


def read_mpm(folder):
    """(--E or None, steps.csv as {column: array}, phase a string and an empty cell nan) of a
    demos/granular_column.py result folder. A run older than the force_mean_pd column gets it
    from its stresses and its sample's mean diameter (its --grains, --radius, ..., --seed)."""
    folder = Path(folder)
    with open(folder / "steps.csv") as f:
        rows = list(csv.DictReader(f))
    s = {k: np.array([q[k] if k == "phase" else q[k] or "nan" for q in rows]) for k in rows[0]}
    s = {k: v if k == "phase" else v.astype(float) for k, v in s.items()}
    meta = folder / "metrics.json"
    par = json.loads(meta.read_text()).get("parameters", {}) if meta.exists() else {}
    if "force_mean_pd" not in s:
        names = ("grains", "radius", "polydispersity", "elongation", "roughness")
        d = np.nan
        if all(k in par for k in names + ("seed",)):
            sample = column.random_sample(*(par[k] for k in names), seed=par["seed"])
            d = 2.0 * float(np.mean(sample.radius))
        pd = [column.scaled_force_mean(*q, d) for q in
              zip(s["force_mean"], s["stress_xx"], s["stress_yy"])]  # fmt: skip
        s["force_mean_pd"] = np.array([np.nan if x is None else x for x in pd])
    return par.get("E"), s


def mpm_ends(folder):
    """(--E, {end: {metric: value}}) of a demos/granular_column.py result folder: the last
    steps.csv row of the compression and of the whole run, as the DEM's `ends`."""
    E, s = read_mpm(folder)
    last = dict(end_of_compression=np.flatnonzero(s["phase"] == "compression")[-1],
                end_of_shear=len(s["t"]) - 1)  # fmt: skip
    return E, {name: {k: float(s[k][i]) for k in METRICS} for name, i in last.items()}


def compare(moduli, folders):
    """The MPM runs against the DEM at the same E: per end and metric the MPM's mean and std
    over its runs, the DEM's, and whether the MPM's mean lies in the DEM's band (its mean +-
    one std over the seeds)."""
    groups = {}
    for d in folders:
        E, ends = mpm_ends(d)
        groups.setdefault(f"{E:g}", []).append(ends)
    out = {}
    for E, runs in groups.items():
        if E not in moduli:
            continue
        out[E] = {}
        for end in ("end_of_compression", "end_of_shear"):
            out[E][end] = {}
            for key in METRICS:
                vals = [r[end][key] for r in runs]
                mean, std = spread(vals)
                dem = moduli[E][end][key]  # None: no value (no stress ratio yet)
                dem_mean, dem_std = (np.nan if x is None else x for x in (dem["mean"], dem["std"]))
                gap = abs(mean - dem_mean)  # nan: no verdict
                inside = bool(gap <= dem_std) if np.isfinite(gap) else None
                out[E][end][key] = dict(mpm_mean=_finite(mean), mpm_std=_finite(std),
                                        mpm_runs=[_finite(x) for x in vals],
                                        lammps_mean=_finite(dem_mean),
                                        lammps_std=_finite(dem_std),
                                        inside_lammps_band=inside)  # fmt: skip
            verdict = {True: "inside", False: "outside", None: "n/a"}
            print(f"E {E} {end}, MPM ({len(runs)} runs) against LAMMPS: " + ", ".join(
                f"{k} {mean_std(v['mpm_mean'])} / {mean_std(v['lammps_mean'], v['lammps_std'])}"
                f" ({verdict[v['inside_lammps_band']]})" for k, v in out[E][end].items()))
    return out


def _finite(x):
    """x as a float, None where it is not finite (JSON has no NaN)."""
    return float(x) if np.isfinite(x) else None


def mean_std(mean, *std):
    """"m" or "m +- s" for the table (None: n/a)."""
    text = "n/a" if mean is None else f"{mean:.4g}"
    for s in std:
        text += " +- " + ("n/a" if s is None else f"{s:.2g}")
    return text


def plot(path, dem, mpm):
    """dem_peer.png: stress ratio, coordination and force_mean_pd against shear strain and
    time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    curves = []  # (label, {column: array}, {column: std over the seeds} or None)
    for E, runs in dem.items():
        s, std = {k: np.array([q[k] for q in runs[0]]) for k in ("t", "phase", "shear_strain")}, {}
        for key in PLOTTED:
            s[key], std[key] = spread([[q[key] for q in rows] for rows in runs])
        curves.append((f"LAMMPS E={E:g} ({len(runs)} seeds)", s, std))
    curves += mpm_curves(mpm)
    fig, ax = plt.subplots(len(PLOTTED), 2, figsize=(11, 10))
    top = 0.0  # the stress ratio's axis: after deposition (it diverges in the free fall)
    for label, s, std in curves:
        for i, key in enumerate(PLOTTED):
            band = std[key] if std else 0 * s[key]
            for j, (x, m) in enumerate(((s["shear_strain"], s["phase"] == "shear"), (s["t"], ...))):
                style = "--" if label.startswith("MPM") else "-"
                line = ax[i, j].plot(x[m], s[key][m], style, label=label)
                ax[i, j].fill_between(x[m], (s[key] - band)[m], (s[key] + band)[m],
                                      color=line[0].get_color(), alpha=0.25, lw=0)  # fmt: skip
        later = s["phase"] != "deposition"
        if later.any():
            band = std["stress_ratio"] if std else 0
            # the 95th percentile: a moment with the lateral walls nearly unloaded spikes
            top = max(top, np.nanpercentile((s["stress_ratio"] + band)[later], 95))
    for j in range(2):
        ax[0, j].set_ylim(0, 1.3 * top if top > 0 else None)
        ax[0, j].set_ylabel("stress ratio sigma_yy / sigma_xx")
        ax[1, j].set_ylabel("coordination number")
        ax[2, j].set_ylabel("force mean / (p d)")
        ax[2, j].set_yscale("log")  # the free fall's first contacts: large, before p settles
    ax[-1, 0].set_xlabel("shear strain eps_yy - eps_xx (shear phase)")
    ax[-1, 1].set_xlabel("time (all phases)")
    ax[0, 0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    a = parse(sys.argv[1:] if argv is None else argv)
    if shutil.which("lmp") is None:
        sys.stderr.write("dem_peer.py: lmp (LAMMPS) not found: run `make bench`\n")
        raise SystemExit(2)
    out, dem = Path(a.out), {}
    summary = dict(parameters=vars(a), moduli={})
    ends = dict(end_of_compression=lambda rows: [q for q in rows if q["phase"] == "compression"],
                end_of_shear=lambda rows: rows)  # fmt: skip
    for E in a.E:
        runs, records = [], []
        for seed in a.seeds:
            sample = column.random_sample(a.grains, a.radius, a.polydispersity, 0, 0,
                                          a.fraction, seed=seed)  # fmt: skip
            folder = out / f"E{E:g}" / f"seed{seed}"
            rows, record = run_one(sample, a, E, folder / "lammps")
            with open(folder / "steps.csv", "w", newline="") as f:
                writer = csv.DictWriter(f, fieldnames=column.COLUMNS)
                writer.writeheader()
                writer.writerows(rows)
            runs.append(rows)
            records.append(dict(seed=seed, **record))
            print(f"E {E:g} seed {seed}: LAMMPS {record['run_time_s']:.1f} s at dt "
                  f"{record['dt']:.3g}; after deposition the bottom carries "
                  f"{record['bottom_over_weight']:.4f} of the weight, all walls "
                  f"{record['walls_vertical_over_weight']:.4f}")  # fmt: skip
        summary["moduli"][f"{E:g}"] = m = {}
        for name, pick in ends.items():
            m[name] = {}
            for key in METRICS:
                mean, std = spread([pick(rows)[-1][key] for rows in runs])
                m[name][key] = dict(mean=_finite(mean), std=_finite(std))  # JSON: no NaN
            print(f"E {E:g} {name}: " + ", ".join(f"{key} {mean_std(v['mean'], v['std'])}"
                                                  for key, v in m[name].items()))  # fmt: skip
        m.update(pair_coeff=f"* * {contact_model(a, E, a.mu)}", runs=records)
        summary["lammps_version"] = records[0]["version"]
        dem[E] = runs
    summary["comparison"] = compare(summary["moduli"], a.mpm)
    (out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    plot(out / "dem_peer.png", dem, a.mpm)
    print(f"results: {out}/summary.json, {out}/dem_peer.png, {out}/E*/seed*/steps.csv")
    return summary


if __name__ == "__main__":
    main()
