"""Newton's convergence test is scale-free: the patch test at E = 1e-12, 1 and 1e12 takes the
same Newton iterations and gives the penalised exact pressure E' d / (H + E' eps_n) to
round-off (an absolute residual floor used to accept the initial guess at E = 1e-12: zero
pressure, exit 0)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def patch(tmp_path, E, disc):
    out = tmp_path / f"patch_{E:g}_{disc}"
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    r = subprocess.run(
        [
            sys.executable,
            str(ROOT / "demos" / "patch_test.py"),
            "--E",
            str(E),
            "--discretization",
            disc,
            "--out",
            str(out),
        ],
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr[-2000:]
    return json.loads((out / "metrics.json").read_text())


@pytest.mark.parametrize("disc", ["conforming", "cut"])
def test_patch_pressure_is_scale_free(tmp_path, disc):
    runs = {E: patch(tmp_path, E, disc) for E in (1e-12, 1.0, 1e12)}
    its = {E: m["solver"]["newton_iterations"] for E, m in runs.items()}
    assert its[1e-12] == its[1.0] == its[1e12] and its[1.0][0] >= 1, its
    for E, m in runs.items():
        res = m["results"]
        assert res["pressure_max_rel_deviation"] < 1e-8, (E, res)
        # the pressure scales with E (eps_n = eps0 h / E keeps E' eps_n fixed)
        ratio = res["pressure_mean"] / runs[1.0]["results"]["pressure_mean"]
        assert ratio == pytest.approx(E, rel=1e-8)
