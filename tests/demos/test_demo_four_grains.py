"""demos/four_grains.py end to end on a coarse grid (in-process): its files, the equilibrium of
every body and the four contacts of every grain; the scene's overlaps; the bad-input contract."""

import csv
import json

import numpy as np
import pytest

from meshes.four_grains import grain_outlines, overlap
from demo_tests import assert_refused, load_demo

demo = load_demo("four_grains")


def test_every_contact_starts_with_the_overlap():
    ov = 1e-3
    gs, (xl, xr, yb, yt), scale, _ = grain_outlines(2.0, 1, ov)
    for i, j in ((0, 1), (0, 2), (1, 3), (2, 3)):  # neighbours, along the line of centres
        assert abs(overlap(gs[i], gs[j]) - ov) < 1e-9, (i, j)
    # plates: penetration across the inner face
    for g, a, face, sign in (
        (0, 0, xl, -1),
        (2, 0, xl, -1),
        (1, 0, xr, 1),
        (3, 0, xr, 1),
        (0, 1, yb, -1),
        (1, 1, yb, -1),
        (2, 1, yt, 1),
        (3, 1, yt, 1),
    ):
        depth = sign * (gs[g][:, a].max() if sign > 0 else gs[g][:, a].min()) - sign * face
        assert abs(depth - ov) < 1e-12, (g, a)
    assert overlap(gs[0], gs[3]) < 0 and overlap(gs[1], gs[2]) < 0  # diagonals apart
    assert 0.4 < scale < 1.5


def test_coarse_run_writes_the_contract(tmp_path):
    out = tmp_path / "fg"
    assert demo.main(["--h", "0.2", "--steps", "1", "--out", str(out)]) == 0
    for f in (
        "steps.csv",
        "contacts.csv",
        "bodies.csv",
        "metrics.json",
        "force_chains.png",
        "max_principal_stress.png",
    ):
        assert (out / f).exists(), f
    rows = list(csv.DictReader(open(out / "steps.csv")))
    assert list(rows[0]) == demo.COLUMNS and len(rows) == 1
    m = json.load(open(out / "metrics.json"))
    r = m["results"]
    assert m["benchmark"] == "four_grains" and m["solver"]["warnings"] == []
    assert r["equilibrium_rel"] < 1e-8
    assert all(n >= 2 for n in r["contacts_per_grain"].values()), r["contacts_per_grain"]
    assert r["contacts"] == 12  # 4 grain-grain + 8 grain-plate, all closed
    pf = r["plate_forces"]  # the assembly as a whole: opposite plates balance
    assert pf["left"] > 0 and pf["bottom"] > 0
    assert np.isclose(pf["left"], pf["right"], rtol=1e-8)
    assert np.isclose(pf["bottom"], pf["top"], rtol=1e-8)
    assert all(0 <= v <= 1 for v in r["stick_fraction"].values())
    # --linear-solver reaches the MPM's problem (it was accepted and ignored): the default
    # factorises (its contact block is too large to condense, defaults.TUNING.condensed_cost), the
    # condensed solver gives the same plate forces
    assert m["solver"]["linear_solver"] == "factorised"
    out2 = tmp_path / "fg_condensed"
    args = ["--h", "0.2", "--steps", "1", "--out", str(out2), "--linear-solver", "condensed"]
    assert demo.main(args) == 0
    m2 = json.load(open(out2 / "metrics.json"))
    assert m2["solver"]["linear_solver"] == "condensed" and m2["solver"]["condensed_dofs"] > 0
    for k, v in m2["results"]["plate_forces"].items():
        assert np.isclose(v, pf[k], rtol=1e-8), k


@pytest.mark.parametrize(
    "args, word",
    [
        (["--h", "0"], "--h"),
        (["--h", "1"], "--h"),
        (["--mu", "0"], "--mu"),
        (["--overlap", "0.2"], "--overlap"),
        (["--seed", "3"], "--seed"),  # grains 0 and 3 come within 0.1 radius diagonally
        (["--steps", "0"], "--steps"),
    ],
)
def test_bad_input_exits_2_naming_the_parameter(args, word, tmp_path, capsys):
    assert_refused(demo, args, word, tmp_path, capsys)
