"""demos/nine_discs.py end to end (in-process, defaults): D4 symmetry of the contact forces and
stresses, equilibrium of every body, the output files; bad input."""

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

_spec = importlib.util.spec_from_file_location(
    "nine_discs", Path(__file__).resolve().parents[2] / "demos" / "nine_discs.py"
)
demo = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(demo)


def test_defaults_are_symmetric_and_balanced(tmp_path):
    out = tmp_path / "nine"
    assert demo.main(["--out", str(out)]) == 0
    m = json.load(open(out / "metrics.json"))
    r = m["results"]
    assert r["contacts"] == 24
    assert r["symmetry_force_rel"] <= 1e-6 and r["symmetry_stress_rel"] <= 1e-6
    assert r["symmetry_points_compared"] > 0.9
    assert r["equilibrium_rel"] <= 1e-8
    assert m["solver"]["warnings"] == []
    for f in ("steps.csv", "contacts.csv", "bodies.csv", "force_chains.png"):
        assert (out / f).exists(), f


def test_later_steps_report_their_symmetry(tmp_path):
    """Two steps: the second step's stress comes from the MLS projection of point sets that
    are not D4-invariant (cut cells), so the points move D4-symmetrically only to ~1e-6 mm and
    mirror points are paired within 1e-4 h (the pairing to 1e-9 of |x| found none and ended in
    a traceback). The figures are finite and reported; a symmetry lost beyond 1e-6 is a
    warning, not an exit 0 in silence."""
    out = tmp_path / "nine2"
    assert demo.main(["--out", str(out), "--steps", "2"]) == 0
    m = json.load(open(out / "metrics.json"))
    r = m["results"]
    assert r["symmetry_points_compared"] > 0.9
    assert 0 <= r["symmetry_force_rel"] < 1 and 0 <= r["symmetry_stress_rel"] < 1
    broken = max(r["symmetry_force_rel"], r["symmetry_stress_rel"]) > 1e-6
    assert broken == any("D4 symmetry broken" in w for w in m["solver"]["warnings"])


def test_augmented_contact_points_are_mirror_symmetric(tmp_path, monkeypatch):
    """The augmented Lagrangian's mortar pieces are split where a closest point changes cell;
    a point on a grid line goes to the cell on its body's side. The discs overlap by 1e-3 and
    so cross the grid lines x, y = +-1.7 at a tangent, where a fixed tie direction (down-left)
    put mirrored pairs' splits 6e-7 apart. Mirrored pairs (disc0-disc1 and disc1-disc2 across
    x = 0, disc0-disc3 and disc3-disc6 across y = 0) now have the same points and weights to
    round-off. (Their forces still differ by ~4e-5 after the Uzawa loop: the D4 warning.)"""
    seen = {}
    evaluate = demo.evaluate
    monkeypatch.setattr(demo, "evaluate", lambda run: (seen.update(run=run), evaluate(run)))
    assert demo.main(["--enforcement", "augmented", "--out", str(tmp_path / "al")]) == 0
    cs = seen["run"].sim.problem.contact
    pairs = dict(zip(cs.names(seen["run"].sim.problem.scene), cs.pairs))
    for a, b, axis in [(("disc0", "disc1"), ("disc1", "disc2"), 0),
                       (("disc0", "disc3"), ("disc3", "disc6"), 1)]:  # fmt: skip
        pa, pb = pairs[a], pairs[b]
        mirrored = pa.points.copy()
        mirrored[:, axis] *= -1
        oa = np.lexsort(mirrored.T)
        ob = np.lexsort(pb.points.T)
        assert len(oa) == len(ob)
        assert np.abs(mirrored[oa] - pb.points[ob]).max() <= 1e-10
        assert np.abs(pa.weights[oa] - pb.weights[ob]).max() <= 1e-10


@pytest.mark.parametrize(
    "args, word",
    [(["--mu", "0"], "--mu"), (["--h", "0.3"], "--h"), (["--overlap", "1"], "--overlap")],
)
def test_bad_input(args, word, tmp_path, capsys):
    with pytest.raises(SystemExit) as e:
        demo.main(args + ["--out", str(tmp_path / "x")])
    assert e.value.code == 2 and word in capsys.readouterr().err
    assert not (tmp_path / "x").exists()
