"""demos/grain_assembly.py end to end on a small assembly (in-process): compression then shear,
equilibrium of every grain and of the plates at every step, the plate-force columns; bad
input."""

import csv
import importlib.util
import json
from pathlib import Path

import pytest

_spec = importlib.util.spec_from_file_location(
    "grain_assembly", Path(__file__).resolve().parents[2] / "demos" / "grain_assembly.py"
)
demo = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(demo)


def test_compression_then_shear(tmp_path):
    out = tmp_path / "ga"
    args = ["--grains", "9", "--steps", "6", "--shear-steps", "2", "--out", str(out)]
    assert demo.main(args) == 0
    m = json.load(open(out / "metrics.json"))
    assert m["results"]["equilibrium_rel_max"] <= 1e-8 and m["solver"]["warnings"] == []
    rows = list(csv.DictReader(open(out / "steps.csv")))
    assert list(rows[0]) == demo.COLUMNS
    assert [r["phase"] for r in rows] == ["compression"] * 6 + ["shear"] * 2
    top = [float(r["plate_top_normal"]) for r in rows]
    assert all(b > a for a, b in zip(top[:6], top[1:6])) and top[0] > 0  # compression loads
    for f in ("contacts.csv", "bodies.csv", "force_chains.png", "plate_forces.png"):
        assert (out / f).exists(), f


@pytest.mark.parametrize(
    "args, word",
    [
        (["--grains", "1"], "--grains"),
        (["--friction-angle", "0"], "--friction-angle"),
        (["--compression", "1"], "--compression"),
        (["--h", "5"], "--h"),
    ],
)
def test_bad_input(args, word, tmp_path, capsys):
    with pytest.raises(SystemExit) as e:
        demo.main(args + ["--out", str(tmp_path / "x")])
    assert e.value.code == 2 and word in capsys.readouterr().err
    assert not (tmp_path / "x").exists()
