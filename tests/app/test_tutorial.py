"""docs/tutorial.md runs as written: its Python blocks in order, its TOML through the runner."""

import os
import re
import subprocess
import sys
from pathlib import Path

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
    (toml,) = blocks("toml")
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
