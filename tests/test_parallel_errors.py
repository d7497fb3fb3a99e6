"""Under mpirun an error on one rank ends every rank (dolfinx_forms/app/mpi_errors.py), and a bad
argument gives exit status 2 on every rank. Serial tests that start `mpirun -n 2`."""

import os
import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
from mpi4py import MPI

ROOT = Path(__file__).resolve().parents[1]
MPI_ENV = dict(
    OMPI_ALLOW_RUN_AS_ROOT="1",
    OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
    OMPI_MCA_rmaps_base_oversubscribe="1",
)


def mpirun(args, timeout, cwd=None):
    exe = shutil.which("mpirun")
    if exe is None or MPI.COMM_WORLD.size > 1:
        pytest.skip("no mpirun, or already under mpirun (no nested launch)")
    t0 = time.perf_counter()
    r = subprocess.run(
        [exe, "-n", "2", sys.executable, *args],
        capture_output=True,
        text=True,
        env=dict(os.environ, **MPI_ENV),
        timeout=timeout,
        cwd=cwd,
    )
    return r, time.perf_counter() - t0


def test_error_on_one_rank_ends_all(tmp_path):
    script = textwrap.dedent(
        """
        import time
        import dolfinx_forms.app  # noqa: F401  (the start-up installs the hook under mpirun)
        from mpi4py import MPI
        comm = MPI.COMM_WORLD
        if comm.rank == 1:
            raise ValueError("bad thing\\non two lines")
        comm.barrier()  # rank 0 would wait here forever
        time.sleep(300)
    """
    )
    (tmp_path / "fail_on_rank_1.py").write_text(script)
    r, wall = mpirun(["fail_on_rank_1.py"], timeout=120, cwd=tmp_path)
    assert r.returncode != 0
    assert wall < 20, f"took {wall:.1f} s"
    ours = [ln for ln in r.stderr.splitlines() if "error on rank" in ln]
    assert ours == ["fail_on_rank_1.py: error on rank 1: ValueError: bad thing on two lines"]
    assert "Traceback" not in r.stderr


def test_hook_only_in_parallel():
    r = subprocess.run(
        [
            sys.executable,
            "-c",
            "import sys, dolfinx_forms; " "print(sys.excepthook is sys.__excepthook__)",
        ],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0 and r.stdout.strip() == "True", r.stderr


def test_bad_argument_exit_2_on_every_rank(tmp_path):
    out = tmp_path / "never"
    r, wall = mpirun(
        [str(ROOT / "demos" / "patch_test.py"), "--h", "-1", "--out", str(out)], timeout=120
    )
    assert r.returncode == 2, r.stderr
    lines = [ln for ln in r.stderr.splitlines() if "patch_test.py: error" in ln]
    assert len(lines) == 2 and all("--h" in ln for ln in lines)  # one line per rank
    assert not out.exists() and list(tmp_path.iterdir()) == []
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "keep.txt").write_text("x")
    r, _ = mpirun([str(ROOT / "demos" / "patch_test.py"), "--out", str(foreign)], timeout=120)
    assert r.returncode == 2, r.stderr
    assert sorted(p.name for p in foreign.iterdir()) == ["keep.txt"]
