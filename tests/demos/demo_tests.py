"""What the in-process demo tests share: loading a demo script as a module, and the bad-input
contract (one line naming the parameter, exit 2, nothing written)."""

import importlib.util
from pathlib import Path

import pytest

DEMOS = Path(__file__).resolve().parents[2] / "demos"


def load_demo(name):
    """demos/<name>.py as a module (its main(argv) runs the demo in this process)."""
    spec = importlib.util.spec_from_file_location(name, DEMOS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def assert_refused(demo, args, word, tmp_path, capsys):
    """demo.main(args) exits 2 with an error naming `word`, and writes no result folder."""
    with pytest.raises(SystemExit) as e:
        demo.main(args + ["--out", str(tmp_path / "x")])
    assert e.value.code == 2
    assert word in capsys.readouterr().err
    assert not (tmp_path / "x").exists()
