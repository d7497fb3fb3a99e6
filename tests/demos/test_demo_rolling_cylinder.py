"""demos/rolling_cylinder.py (Newmark dynamics on the material-point path, mpm/dynamics.py) on
a coarse grid: the fitted acceleration and the rotation against the rigid cylinder's, rolling
and slipping; a free fall exact; the bad-input contract."""

import csv
import json

import numpy as np
import pytest
from mpi4py import MPI
from demo_tests import assert_refused, load_demo

demo = load_demo("rolling_cylinder")
COARSE = ["--h", "0.2", "--dt", "0.1", "--t-end", "2", "--series-every", "20"]


@pytest.mark.parametrize("mu", ["0.5", "0.1"], ids=["rolls", "slips"])
def test_acceleration_and_rotation(mu, tmp_path):
    """Rolling: R / h = 5, dt = 0.1; slipping: R / h = 10, dt = 0.05. x(t) within 3 % of the
    final travel of the rigid cylinder's (measured 0.49 %, 0.93 %; slipping at R / h = 5:
    2.0 %), the fitted acceleration within 3 % (measured -1.6 %, -1.4 %), the rotation R
    within 3 % of x when it rolls (measured +0.11 %); the columns of steps.csv."""
    out = tmp_path / mu
    grid = COARSE if mu == "0.5" else ["--h", "0.1", "--dt", "0.05", "--t-end", "2"]
    assert demo.main([*grid, "--mu", mu, "--out", str(out)]) == 0
    rows = list(csv.DictReader(open(out / "steps.csv")))
    assert list(rows[0]) == demo.COLUMNS and len(rows) == (20 if mu == "0.5" else 40)
    m = json.load(open(out / "metrics.json"))
    r = m["results"]
    assert r["x_rel_error_max"] < 0.03 and abs(r["acceleration_rel_error"]) < 0.03
    assert r["rolling"] == (mu == "0.5")
    if r["rolling"]:
        assert abs(r["rotation_vs_x"]) < 0.03
    assert not [w for w in m["solver"]["warnings"] if "differs" in w]


def test_free_fall_is_exact():
    """A disc in free fall (no contact, no condition: the mass holds the step): the centre
    falls g t^2 / 2 to round-off (a_0 = g, Newmark exact for constant acceleration)."""
    import dolfinx_forms as df
    from dolfinx_forms.fem.laws import NeoHookean
    from dolfinx_forms.mpm.dynamics import PointNewmark
    from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
    from meshes.mpm import grid_scene, uniform_lines

    xl, yl = uniform_lines(-1.5, 1.5, 0.1), uniform_lines(-2.5, 1.5, 0.1)
    dyn = PointNewmark({1: 1.0}, 0.05, gravity=(0.0, -1.0))
    sim = ImplicitMPM(MPI.COMM_SELF, (xl, yl), [MPMBody("d", 1, NeoHookean(1e3, 0.3),
                      df.Circle((0.0, 0.0), 1.0))], grid_scene(MPI.COMM_SELF, xl, yl, [("d", 1)]),
                      dynamics=dyn, log=lambda *a, **k: None)  # fmt: skip
    for _ in range(8):
        t = sim.step()["time"]
        p = sim.points[1]
        y = np.average(p.x[:, 1], weights=p.vol0)
        assert y == pytest.approx(-0.5 * t**2, rel=1e-9)
        assert np.allclose(p.v[:, 1], -t, rtol=1e-9)


@pytest.mark.parametrize(
    "args, word",
    [
        (["--theta", "0"], "--theta"),
        (["--theta", "70"], "--theta"),
        (["--h", "0.5"], "--h"),
        (["--dt", "1"], "--dt"),
        (["--mu", "-0.1"], "--mu"),
        (["--integrator", "euler"], "--integrator"),
        (["--t-end", "100"], "--t-end"),
    ],
)
def test_bad_input_exits_2_naming_the_parameter(args, word, tmp_path, capsys):
    assert_refused(demo, args, word, tmp_path, capsys)
