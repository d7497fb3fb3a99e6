"""demos/bouncing_disc.py (inertia, contact and Kelvin-Voigt damping on the material-point
path) on a coarse grid: the disc comes to rest on the floor carrying its weight, without chatter
or loss of contact; the bad-input contract."""

import csv
import json

import numpy as np
import pytest
from demo_tests import assert_refused, load_demo

demo = load_demo("bouncing_disc")


def test_comes_to_rest_on_the_floor(tmp_path):
    """R / h = 5, dt = 0.02 (the largest), 4 s, dissipative Newmark, a stiff penalty
    (eps0 = 1e-4, the steps halved at the impacts): over the last fifth the floor force is
    the weight within 1 % (measured 1.00001-1.00003), the kinetic energy below 1e-5 of m g
    drop (measured 3.4e-7), contact never lost, the lowest point's acceleration below g, the
    penetration below 1e-5 R (the penalty's compliance eps = eps0 h / E_c: 1.3e-6 R measured
    at this h, 6.5e-7 R at h = 0.1); the first impact within two steps of the free-fall time.
    The steps (15 retries seen) cover the 4 s exactly."""
    out = tmp_path / "b"
    args = ["--h", "0.2", "--dt", "0.02", "--t-end", "4", "--eps0", "1e-4", "--series-every", "200"]
    assert demo.main([*args, "--out", str(out)]) == 0
    rows = list(csv.DictReader(open(out / "steps.csv")))
    assert list(rows[0]) == demo.COLUMNS and len(rows) >= 200
    dt = np.array([float(q["dt"]) for q in rows])
    assert np.all(dt <= 0.02 * (1 + 1e-12)) and np.isclose(dt.sum(), 4.0, rtol=1e-12)
    assert np.allclose(np.cumsum(dt), [float(q["t"]) for q in rows], rtol=1e-12)
    r = json.load(open(out / "metrics.json"))["results"]
    assert np.allclose(r["force_over_weight_rest"], 1.0, rtol=0, atol=0.01)
    assert -1e-5 < min(r["gap_rest_over_R"]) <= max(r["gap_rest_over_R"]) < 0
    assert r["kinetic_energy_rest"] < 1e-5 and r["contact_lost_at_rest"] == 0
    assert r["acceleration_rest_over_g"] < 1
    assert abs(r["first_impact"] - np.sqrt(2 * 0.1)) <= 2 * 0.02


@pytest.mark.parametrize(
    "args, word",
    [
        (["--drop", "2"], "--drop"),
        (["--viscosity", "-1"], "--viscosity"),
        (["--h", "0.5"], "--h"),
        (["--dt", "1"], "--dt"),
        (["--integrator", "bdf"], "--integrator"),
    ],
)
def test_bad_input_exits_2_naming_the_parameter(args, word, tmp_path, capsys):
    assert_refused(demo, args, word, tmp_path, capsys)
