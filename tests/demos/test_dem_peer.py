"""benchmarks/dem_peer.py, LAMMPS's rigid-disc peer of demos/granular_column.py, on a small
column: 12 discs, two seeds, 20 time units of deposition, 1 of compression, 1 of shear (~2 s).
Skipped without LAMMPS's lmp (`make bench` installs Debian's lammps).

Frictionless walls (--wall-mu 0; the grains' mu 0.3): then the bottom alone carries the weight
once at rest, and the lateral walls' forces balance. With wall friction the lateral walls carry
a part that depends on the last slips (Janssen): the bottom carried 0.95 ... 1.06 of the weight
(100 discs, seeds 1-10) while all walls together carried it within 1.5 %. Measured here, seeds
1-8: the bottom carries 0.9976 ... 1.0006 of the weight, |left - right| <= 1 % of it, kinetic
energy <= 8e-4 (weight x radius: 35 ... 39); what is left moving is an almost free rocking.
"""

import csv
import json
import shutil

import numpy as np
import pytest

if shutil.which("lmp") is None:
    pytest.skip("LAMMPS (lmp) not installed: `make bench` installs it", allow_module_level=True)

from benchmarks import dem_peer  # noqa: E402
from meshes import column  # noqa: E402

ARGS = ["--grains", "12", "--seeds", "1", "2", "--wall-mu", "0", "--t-deposit", "20",
        "--t-compress", "1", "--t-shear", "1"]  # fmt: skip
T_DEPOSIT, T_COMPRESS = 20.0, 1.0


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("dem_peer")
    summary = dem_peer.main(ARGS + ["--out", str(out)])
    tables = {}
    for seed in (1, 2):
        with open(out / "E10000" / f"seed{seed}" / "steps.csv") as f:
            tables[seed] = list(csv.reader(f))
    return out, summary, tables


def rows_of(table):
    """steps.csv rows as dicts of numbers (an empty stress ratio: nan), phase a string."""
    header, *rows = table
    return [{k: v if k == "phase" else float(v or "nan") for k, v in zip(header, q)} for q in rows]


def test_columns_are_the_shared_ones(run):
    out, summary, tables = run
    for table in tables.values():
        assert table[0] == column.COLUMNS
        assert len(table) - 1 == round((T_DEPOSIT + T_COMPRESS + 1.0) / 0.1) + 1
    text = (out / "summary.json").read_text()
    assert json.loads(text) == json.loads(json.dumps(summary))
    json.loads(text, parse_constant=_not_json)
    assert (out / "dem_peer.png").stat().st_size > 0


def _not_json(name):
    """json.loads's parse_constant: NaN and Infinity are not JSON (jq, JavaScript reject them)."""
    raise ValueError(f"summary.json holds {name}")


def test_summary_holds_null_where_a_value_is_missing(tmp_path):
    """Two time units of deposition: the discs still fall, the lateral walls carry nothing at
    the end, so there is no stress ratio there. summary.json says null (it wrote NaN)."""
    args = ["--grains", "12", "--seeds", "1", "2", "--t-deposit", "2", "--t-compress", "1",
            "--t-shear", "1", "--out", str(tmp_path)]  # fmt: skip
    summary = dem_peer.main(args)
    assert summary["moduli"]["10000"]["end_of_shear"]["stress_ratio"]["mean"] is None
    json.loads((tmp_path / "summary.json").read_text(), parse_constant=_not_json)


def test_deposit_rests_on_the_bottom(run):
    """At the end of deposition the bottom carries the discs' weight, the lateral walls hold
    each other (frictionless walls: nothing else is horizontal), the top is untouched, nothing
    moves."""
    out, summary, tables = run
    for (seed, table), record in zip(tables.items(), summary["moduli"]["10000"]["runs"]):
        sample = column.random_sample(12, 1.0, 0.2, 0, 0, 0.35, seed=seed)
        weight = np.pi * np.sum(sample.radius**2)  # rho = g = 1
        assert record["weight"] == pytest.approx(weight, rel=1e-12)
        q = next(r for r in rows_of(table) if r["t"] == T_DEPOSIT)
        assert q["phase"] == "deposition"
        assert q["force_bottom"] == pytest.approx(weight, rel=0.02)
        assert abs(q["force_left"] - q["force_right"]) < 0.02 * weight
        # sigma_xx = K sigma_yy, K < 2 even with arches: F_left < K W h / (2 L) < 0.6 W (h < L)
        assert 0 < q["force_left"] < 0.6 * weight
        assert q["force_top"] == 0.0
        assert q["kinetic_energy"] < 1e-3 * weight * 1.0  # x the mean radius: 1e-4 of the fall
        assert q["coordination"] > 1.5


def test_walls_follow_the_protocol(run):
    """The walls LAMMPS moved are Protocol.walls at the settled height it measured, which lies
    between the dense and the loose height of the discs."""
    out, summary, tables = run
    for (seed, table), record in zip(tables.items(), summary["moduli"]["10000"]["runs"]):
        sample = column.random_sample(12, 1.0, 0.2, 0, 0, 0.35, seed=seed)
        protocol = column.Protocol(sample.box, T_DEPOSIT, T_COMPRESS, 1.0, 0.01, 0.1)
        width = np.ptp(sample.box[:, 0])
        settled = record["settled_height"]
        assert np.pi * np.sum(sample.radius**2) / width < settled < 0.8 * np.ptp(sample.box[:, 1])
        rows = rows_of(table)
        for q in rows:
            want = protocol.walls(q["t"], settled)
            for k in ("left", "right", "top"):
                assert q[k] == pytest.approx(want[k], abs=1e-9), (q["t"], k)
        end = rows[-1]
        assert (end["right"] - end["left"]) * (end["top"] - sample.box[0, 1]) == pytest.approx(
            width * 0.99 * settled, rel=1e-9
        )  # constant area from the end of compression


def test_compression_loads_the_top(run):
    out, summary, tables = run
    for table in tables.values():
        rows = rows_of(table)
        top = [q["force_top"] for q in rows if q["phase"] == "compression"]
        deposit = next(q for q in rows if q["t"] == T_DEPOSIT)
        assert deposit["force_top"] == 0.0  # the top wall waits above the deposit,
        assert min(top) > 0 and top[-1] > 0.1 * deposit["force_bottom"]  # then presses on it
        ends = summary["moduli"]["10000"]["end_of_compression"]
        assert ends["coordination"]["mean"] > 0 and ends["coordination"]["std"] >= 0


def test_bad_options_and_missing_lammps(tmp_path, capsys, monkeypatch):
    for argv, word in ((["--E", "-1"], "--E"), (["--t-deposit", "0.05"], "--t-deposit"),
                       (["--grains", "two"], "--grains")):  # fmt: skip
        with pytest.raises(SystemExit) as e:
            dem_peer.main(argv + ["--out", str(tmp_path / "x")])
        assert e.value.code == 2
        err = capsys.readouterr().err
        assert word in err and len(err.strip().splitlines()) == 1
    monkeypatch.setattr(dem_peer.shutil, "which", lambda name: None)
    with pytest.raises(SystemExit) as e:
        dem_peer.main(["--out", str(tmp_path / "x")])
    assert e.value.code == 2 and "make bench" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


def test_plot_with_an_mpm_run(run, tmp_path):
    """--mpm folders (steps.csv and metrics.json of demos/granular_column.py) plot as lines."""
    out, summary, tables = run
    mpm = tmp_path / "mpm"
    mpm.mkdir()
    shutil.copy(out / "E10000" / "seed1" / "steps.csv", mpm / "steps.csv")
    (mpm / "metrics.json").write_text(json.dumps({"parameters": {"E": 1e4}}))
    dem = {1e4: [rows_of(t) for t in tables.values()]}
    dem_peer.plot(tmp_path / "p.png", dem, [str(mpm)])
    assert (tmp_path / "p.png").stat().st_size > 0


def test_force_mean_in_units_of_the_stress(run):
    """force_mean_pd = force_mean / (p d): p the mean of the walls' two stresses, d the sample's
    mean diameter; empty while no wall is loaded."""
    out, summary, tables = run
    for seed, table in tables.items():
        d = 2.0 * np.mean(column.random_sample(12, 1.0, 0.2, 0, 0, 0.35, seed=seed).radius)
        loaded = [q for q in rows_of(table) if q["stress_xx"] + q["stress_yy"] > 0]
        assert loaded and all(q["force_mean_pd"] > 0 for q in loaded if q["contacts"] > 0)
        for q in loaded:
            p = 0.5 * (q["stress_xx"] + q["stress_yy"])
            assert q["force_mean_pd"] == pytest.approx(q["force_mean"] / (p * d), rel=1e-12)


def test_mpm_runs_compared_with_the_band(run, tmp_path):
    """`compare`: --mpm runs at a DEM modulus against the DEM's band. The DEM's own two seeds
    given as MPM runs have its mean (inside the band) and its per-seed values; a run without
    the force_mean_pd column (older steps.csv) gets it from its stresses and sample."""
    out, summary, tables = run
    folders = []
    for seed, table in tables.items():
        d = tmp_path / f"seed{seed}"
        d.mkdir()
        header, *rows = table
        keep = [i for i, k in enumerate(header) if k != "force_mean_pd" or seed == 1]
        with open(d / "steps.csv", "w", newline="") as f:
            csv.writer(f).writerows([[q[i] for i in keep] for q in table])
        par = dict(E=1e4, grains=12, radius=1.0, polydispersity=0.2, elongation=0.0,
                   roughness=0.0, seed=seed)  # fmt: skip
        (d / "metrics.json").write_text(json.dumps({"parameters": par}))
        folders.append(str(d))
    got = dem_peer.compare(summary["moduli"], folders)["10000"]
    for end, picked in (("end_of_compression", "compression"), ("end_of_shear", None)):
        for key in dem_peer.METRICS:
            c, dem = got[end][key], summary["moduli"]["10000"][end][key]
            per_seed = [[q for q in rows_of(t) if picked in (None, q["phase"])][-1][key]
                        for t in tables.values()]  # fmt: skip
            if not np.isfinite(dem["mean"]):  # no stress ratio at that row: no verdict
                assert c["inside_lammps_band"] is None
                continue
            assert c["mpm_runs"] == pytest.approx(per_seed, rel=1e-12)
            assert c["mpm_mean"] == pytest.approx(dem["mean"], rel=1e-12)
            assert c["inside_lammps_band"] is True
