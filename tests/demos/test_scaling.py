"""benchmarks/scaling.py end to end at one coarse size (the benchmark's children run the demo and
the reference through a wrapper that must see the benchmark's folder, as `python3 script` does)."""

import csv
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_scaling_one_size(tmp_path):
    p = subprocess.run(
        [
            sys.executable,
            "benchmarks/scaling.py",
            "--divisors",
            "10",
            "--paths",
            "cut",
            "--out-dir",
            str(tmp_path),
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert p.returncode == 0, p.stderr
    rows = list(csv.DictReader(open(tmp_path / "scaling.csv")))
    assert len(rows) == 1 and rows[0]["path"] == "cut"
    r = rows[0]
    # the run and its reference both ran: a Hertz error of a coarse run, a positive ratio
    assert 0 < float(r["pressure_error"]) < 0.1
    assert float(r["ref_factor"]) > 0 and float(r["ratio"]) > 0
    assert int(r["dofs"]) > 1000 and int(r["factorisations"]) == 1
