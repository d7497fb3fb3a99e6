"""dolfinx_forms/solvers/blas.py: the BLAS thread count follows the problem size, the user's
OPENBLAS_NUM_THREADS wins."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

SCRIPT = """
import os
from dolfinx_forms.solvers import blas
if blas.num_threads() is None:
    print("no-openblas")
else:
    first = blas.num_threads()
    print(blas.threads_for(True), blas.num_threads(), blas.threads_for(False) == first,
          blas.num_threads() == first)
"""


def run(env_extra):
    import os

    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    env.update(env_extra, PYTHONPATH=str(ROOT))
    r = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    return r.stdout.split()


def test_small_one_thread_large_restored():
    out = run({})
    if out == ["no-openblas"]:
        pytest.skip("another BLAS: nothing to set (Debian's default is OpenBLAS)")
    assert out == ["1", "1", "True", "True"]


def test_user_setting_wins():
    out = run({"OPENBLAS_NUM_THREADS": "2"})
    if out == ["no-openblas"]:
        pytest.skip("another BLAS")
    assert out == ["None", "2", "False", "True"]
