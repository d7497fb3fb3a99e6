"""docs/tutorial.md runs as written: its Python blocks in order, its TOML through the runner."""

import csv
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
TEXT = (ROOT / "docs" / "tutorial.md").read_text()


def blocks(lang):
    return re.findall(rf"```{lang}\n(.*?)```", TEXT, flags=re.S)


def test_python_blocks_run(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "tutorial"}
    code = "\n".join(blocks("python"))
    assert "assert" in code  # the tutorial checks something
    exec(compile(code, str(ROOT / "docs" / "tutorial.md"), "exec"), namespace)
    out = capsys.readouterr().out
    assert "cut:" in out and "fitted:" in out


def test_toml_block_runs(tmp_path):
    toml = blocks("toml")[0]
    scene = tmp_path / "grain.toml"
    scene.write_text(toml)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    r = subprocess.run(
        [sys.executable, "-m", "dolfinx_forms", "run", str(scene), "--out", str(tmp_path / "out")],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr[-2000:]
    assert (tmp_path / "out" / "metrics.json").exists()


def test_user_scene_from_the_tutorial(tmp_path):
    """demos/scenes/disc_squeeze.toml, written from the tutorial alone: a neo-Hookean disc
    between two stiff blocks, two contact pairs; its checks (Johnson's line load within 3 %,
    both zones carry it, symmetry, Hertz half-width within 10 %) must pass."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "dolfinx_forms",
            "run",
            str(ROOT / "demos" / "scenes" / "disc_squeeze.toml"),
            "--out",
            str(tmp_path / "out"),
        ],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
        timeout=900,
    )
    assert r.returncode == 0, r.stderr[-2000:]


def _run_punch(tmp_path, out, ranks):
    """The tutorial's multi-step scene (section 6) on `ranks` processes."""
    (scene := tmp_path / "punch.toml").write_text(blocks("toml")[1])
    cmd = [sys.executable, "-m", "dolfinx_forms", "run", str(scene), "--out", str(out)]
    env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1")
    if ranks > 1:
        from mpi4py import MPI

        exe = shutil.which("mpirun")
        if exe is None or MPI.COMM_WORLD.size > 1:
            pytest.skip("no mpirun, or already under mpirun (no nested launch)")
        cmd = [exe, "-n", str(ranks)] + cmd
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                   OMPI_MCA_rmaps_base_oversubscribe="1")  # fmt: skip
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=tmp_path, timeout=600)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return r


def test_multi_step_scene_same_on_one_and_two_ranks(tmp_path):
    """Section 6's scene (an ellipse between a rigid floor and a turning polygon punch, a
    user's scene, not a demo's) passes its checks, and 2 ranks give 1 rank's steps, contacts
    and bodies to 1e-10 of each column's scale (forces: of the largest contact force)."""
    one, two = tmp_path / "one", tmp_path / "two"
    _run_punch(tmp_path, one, 1)
    _run_punch(tmp_path, two, 2)

    def rows(folder, name):
        with open(folder / name) as f:
            return list(csv.DictReader(f))

    force = max(float(r["normal_force"]) for r in rows(one, "contacts.csv"))
    for name in ("steps.csv", "contacts.csv", "bodies.csv"):
        a, b = rows(one, name), rows(two, name)
        assert len(a) == len(b) > 0
        for key in a[0]:
            if key in ("wall_s", "equilibrium_rel"):  # a time; round-off (its own check)
                continue
            try:
                x, y = (np.array([float(r[key]) for r in t]) for t in (a, b))
            except ValueError:
                assert [r[key] for r in a] == [r[key] for r in b], (name, key)
                continue
            forceish = any(k in key for k in ("force", "fx", "fy", "moment"))
            scale = max(np.abs(x).max(), force if forceish else 1e-300)
            assert np.abs(x - y).max() <= 1e-10 * scale, (name, key)
