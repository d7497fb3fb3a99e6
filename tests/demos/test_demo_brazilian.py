"""demos/brazilian_disc.py end to end on a coarse grid (in-process), its files and columns, and
its bad-input contract."""

import csv
import json

import numpy as np
import pytest
from demo_tests import assert_refused, load_demo

demo = load_demo("brazilian_disc")


def test_coarse_run_writes_the_contract(tmp_path):
    out = tmp_path / "bd"
    assert demo.main(["--h", "1", "--steps", "4", "--series-every", "2", "--out", str(out)]) == 0
    rows = list(csv.DictReader(open(out / "steps.csv")))
    assert list(rows[0]) == demo.COLUMNS and len(rows) == 4
    for r in rows:
        assert abs(float(r["force_top"]) / float(r["force_bottom"]) - 1) < 1e-6
    m = json.load(open(out / "metrics.json"))
    assert m["benchmark"] == "brazilian" and m["solver"]["load_steps"] == 4
    assert m["results"]["force_balance_rel_max"] < 1e-6 and m["results"]["mass_rel_change"] == 0
    for k in ("mls", "points", "evolution", "solve"):
        assert m["timing_s"][k] > 0
    with open(out / "contacts.csv") as f:
        assert next(csv.reader(f))[:3] == ["step", "body_i", "body_j"]
    for f in (
        "bodies.csv",
        "half_width.png",
        "sigma_yy.png",
        "levelsets.xdmf",
        "material_points_disc.xdmf",
    ):
        assert (out / f).exists(), f


def test_condensed_ldlt_with_friction_and_symmetry_line(tmp_path, monkeypatch):
    """The condensed bulk as LDL^T with friction (S^-1 handed to PETSc) and with the symmetry
    line's Dirichlet dofs among the contact dofs (their columns eliminated in S): the same
    steps as a full LU factorisation per Newton iteration. (This grid's n is too small for
    S^-1 to pay: `INVERT_COST` raised.)"""
    from dolfinx_forms.solvers import linear

    monkeypatch.setattr(linear, "INVERT_COST", 1e9)
    inverted, fixed = [], []
    invert, init = linear._invert, linear.Condensed.__init__
    monkeypatch.setattr(linear, "_invert", lambda S: inverted.append(len(S)) or invert(S))

    def spy(self, *a, **k):
        init(self, *a, **k)
        fixed.append(len(self.fixed))

    monkeypatch.setattr(linear.Condensed, "__init__", spy)
    rows = {}
    for solver in ("condensed", "factorised"):
        out = tmp_path / solver
        args = ["--h", "1", "--steps", "3", "--linear-solver", solver, "--out", str(out)]
        assert demo.main(args) == 0
        assert json.load(open(out / "metrics.json"))["solver"]["linear_solver"] == solver
        rows[solver] = list(csv.DictReader(open(out / "steps.csv")))
    assert inverted and min(fixed) > 0
    for a, b in zip(rows["condensed"], rows["factorised"]):
        assert a["newton_iterations"] == b["newton_iterations"]
        for k in ("force_top", "force_bottom", "half_width_top"):
            assert float(a[k]) == pytest.approx(float(b[k]), rel=1e-8), k


def test_a_split_step_is_one_row_with_its_substeps(tmp_path, monkeypatch):
    """A step whose solve fails whole (forced here at its second step) is done in halves: one
    steps.csv row with the platen at the step's full travel, `solver.substeps` [1, 2] and the
    iterations of both halves (through the demo's Steps: mpm_run)."""
    from dolfinx_forms.solvers.newton import ContactSolverError
    from dolfinx_forms.solvers.problem import ContactProblem

    solve, calls = ContactProblem.solve, []

    def failing(self, num_steps=1, lam_end=1.0, *a, **k):
        calls.append(lam_end)
        if len(calls) == 2:
            raise ContactSolverError("forced")
        return solve(self, num_steps, lam_end, *a, **k)

    rows = {}
    for split in (False, True):
        if split:
            monkeypatch.setattr(ContactProblem, "solve", failing)
        out = tmp_path / str(split)
        assert demo.main(["--h", "1", "--steps", "2", "--out", str(out)]) == 0
        rows[split] = list(csv.DictReader(open(out / "steps.csv")))
        m = json.load(open(out / "metrics.json"))
    assert calls == [1.0, 1.0, 0.5, 0.5]
    assert m["solver"]["substeps"] == [1, 2] and len(rows[True]) == 2
    a, b = rows[True][-1], rows[False][-1]
    assert a["displacement"] == b["displacement"]
    assert int(a["newton_iterations"]) > int(b["newton_iterations"])
    # balanced and loaded further (the halves' answer is a path of its own on this coarse grid:
    # 8 % off the whole step's at h = 1; two half steps equal it, tests/mpm/test_mpm.py)
    assert float(a["force_top"]) == pytest.approx(float(a["force_bottom"]), rel=1e-6)
    assert float(a["force_top"]) > float(rows[True][0]["force_top"]) > 0


@pytest.mark.parametrize(
    "args, word",
    [
        (["--h", "0"], "--h"),
        (["--h", "3"], "--h"),
        (["--nu", "0.5"], "--nu"),
        (["--mu", "-1"], "--mu"),
        (["--steps", "0"], "--steps"),
        (["--step-displacement", "0.5", "--steps", "10"], "--step-displacement"),
        (["--bogus", "1"], "bogus"),
    ],
)
def test_bad_input_exits_2_naming_the_parameter(args, word, tmp_path, capsys):
    assert_refused(demo, args, word, tmp_path, capsys)


def test_time_series_read_by_meshio_and_h5py(tmp_path):
    """One HDF5 file per series, paths relative to the .xdmf; meshio's TimeSeriesReader reads
    every frame, and its values are the run's: the points' positions are the seeded points
    moved by their displacement, and the last frame's volumes sum to the points' volume of
    steps.csv (issue 29, item 5)."""
    import h5py
    import meshio

    out = tmp_path / "bd"
    assert demo.main(["--h", "1", "--steps", "2", "--series-every", "1", "--out", str(out)]) == 0
    assert sorted(p.name for p in out.glob("*.h5")) == ["levelsets.h5", "material_points_disc.h5"]
    assert not list(out.glob("*.bin"))
    rows = list(csv.DictReader(open(out / "steps.csv")))
    with meshio.xdmf.TimeSeriesReader(out / "material_points_disc.xdmf") as r:
        points, cells = r.read_points_cells()
        assert r.num_steps == 2 and cells[0].type == "vertex"
        first = r.read_data(0)[1]
        t, data, _ = r.read_data(1)
    assert t == 2.0
    assert np.allclose(first["position"], points)  # frame 0's geometry is its positions
    volume = float(rows[-1]["volume_points"])
    assert data["volume"].sum() == pytest.approx(volume, rel=1e-12)
    with h5py.File(out / "material_points_disc.h5", "r") as f:
        assert np.array_equal(f["frame1/position"][()], data["position"])
    with meshio.xdmf.TimeSeriesReader(out / "levelsets.xdmf") as r:
        grid, cells = r.read_points_cells()
        assert cells[0].type == "quad" and r.num_steps == 2
        phi = r.read_data(1)[1]["phi_disc"]
    assert phi.shape == (len(grid),) and phi.min() < 0 < phi.max()
