"""--petsc options are tried on a scratch KSP when the arguments are parsed: an unknown type or a
malformed value is one line naming the option, exit 2, nothing written (it used to be a PETSc
traceback after the mesh was built)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from dolfinx_forms.app import cli

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(
    "items, culprit",
    [
        (["ksp_type=bogus"], "ksp_type=bogus"),
        (["ksp_type=cg", "pc_type=nonsense"], "pc_type"),
        (["ksp_rtol=abc"], "ksp_rtol=abc"),
    ],
)
def test_refused_options_name_the_culprit(items, culprit, capsys):
    parser = cli.DemoParser(prog="demo")
    with pytest.raises(SystemExit) as e:
        cli.petsc_options(parser, items)
    assert e.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("demo: error: --petsc: PETSc refuses " + culprit), err


def test_accepted_options_pass_and_leave_no_trace():
    from petsc4py import PETSc

    opts = cli.petsc_options(
        cli.DemoParser(prog="demo"), ["ksp_type=cg", "pc_type=gamg", "ksp_rtol=1e-10"]
    )
    assert opts == {"ksp_type": "cg", "pc_type": "gamg", "ksp_rtol": "1e-10"}
    assert not any(k.startswith("ils_check_") for k in PETSc.Options().getAll())


def test_demo_refuses_before_writing(tmp_path):
    out = tmp_path / "out"
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    r = subprocess.run(
        [
            sys.executable,
            str(ROOT / "demos" / "patch_test.py"),
            "--petsc",
            "ksp_type=bogus",
            "--out",
            str(out),
        ],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert not out.exists()
