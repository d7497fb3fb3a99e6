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
    """R / h = 5, dt = 0.02, 4 s, dissipative Newmark: over the last fifth the floor force is
    the weight within 1 % (measured 1.0012-1.0013), the kinetic energy below 1e-5 of m g drop
    (measured 3e-8), contact never lost, the lowest point's acceleration below g; the first
    impact within two steps of the free-fall time."""
    out = tmp_path / "b"
    args = ["--h", "0.2", "--dt", "0.02", "--t-end", "4", "--series-every", "200"]
    assert demo.main([*args, "--out", str(out)]) == 0
    rows = list(csv.DictReader(open(out / "steps.csv")))
    assert list(rows[0]) == demo.COLUMNS and len(rows) == 200
    r = json.load(open(out / "metrics.json"))["results"]
    assert np.allclose(r["force_over_weight_rest"], 1.0, rtol=0, atol=0.01)
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
