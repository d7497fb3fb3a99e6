"""demos/brazilian_disc.py end to end on a coarse grid (in-process), its files and columns, and
its bad-input contract."""

import csv
import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

_spec = importlib.util.spec_from_file_location(
    "brazilian_disc", Path(__file__).resolve().parents[2] / "demos" / "brazilian_disc.py"
)
demo = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(demo)


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
    with pytest.raises(SystemExit) as e:
        demo.main(args + ["--out", str(tmp_path / "x")])
    assert e.value.code == 2
    assert word in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


def test_time_series_reference_their_data(tmp_path):
    """The XDMF series are well-formed and every Binary item names a file of its size."""
    import xml.etree.ElementTree as ET

    out = tmp_path / "bd"
    assert demo.main(["--h", "1", "--steps", "2", "--series-every", "1", "--out", str(out)]) == 0
    for name in ("material_points_disc.xdmf", "levelsets.xdmf"):
        root = ET.parse(out / name).getroot()
        frames = root.findall(".//Grid[@GridType='Uniform']")
        assert len(frames) == 2
        for item in root.iter("DataItem"):
            dims = [int(d) for d in item.get("Dimensions").split()]
            size = (out / item.text).stat().st_size
            assert size == 8 * int(np.prod(dims)), item.text
