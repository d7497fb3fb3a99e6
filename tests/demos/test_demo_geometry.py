"""The geometry demo's contract: outputs checked against formulas computed from the
outputs themselves, one-line errors with exit status 2 and nothing written."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

DEMO = Path(__file__).resolve().parents[2] / "demos" / "contact_geometry.py"


def run(*args):
    return subprocess.run([sys.executable, str(DEMO), *args], capture_output=True, text=True)


def test_demo_outputs_match_exact_gap(tmp_path):
    out = tmp_path / "cg"
    R, gap, h = 5.0, 0.03, 0.05
    r = run("--out", str(out), "--R", str(R), "--gap", str(gap), "--h", str(h), "--width", "1.5")
    assert r.returncode == 0, r.stderr
    m = json.loads((out / "metrics.json").read_text())
    assert m["parameters"]["R"] == R and m["timing_s"]["total"] > 0
    data = np.loadtxt(out / "contact_points.csv", delimiter=",", skiprows=1)
    x, y, g_n0 = data[:, 0], data[:, 1], data[:, 9]
    # Equidistant parabola between the flat face and the circle; exact normal gap there
    assert np.abs(y - (x**2 + 2 * R * gap + gap**2) / (2 * (2 * R + gap))).max() < 0.02 * h**2
    c = np.array([0.0, R + gap])
    n_cyl = (data[:, :2] - c) / np.linalg.norm(data[:, :2] - c, axis=1)[:, None]
    exact = y * np.linalg.norm(np.array([0.0, 1.0]) - n_cyl, axis=1)
    assert (
        np.abs(g_n0 - exact).max() < 0.02 * h**2
    )  # chord error ~ h^2/(8 R_eff) measured 8e-3 h^2
    assert g_n0.min() == pytest.approx(gap, rel=1e-3)  # at the apex the gap is the given gap
    assert (out / "contact_geometry.png").stat().st_size > 0


@pytest.mark.parametrize(
    "bad, name",
    [
        (("--R", "-1"), "--R"),
        (("--h", "0"), "--h"),
        (("--gap", "nan"), "--gap"),
        (("--bogus", "1"), "bogus"),
    ],
)
def test_bad_input_one_line_exit_2_nothing_written(tmp_path, bad, name):
    out = tmp_path / "never"
    r = run("--out", str(out), *bad)
    assert r.returncode == 2
    assert len(r.stderr.strip().splitlines()) == 1 and name in r.stderr
    assert not out.exists() and list(tmp_path.iterdir()) == []
