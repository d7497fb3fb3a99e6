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

ROOT = Path(__file__).resolve().parents[2]
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
    """The library installs no hook; the application's start-up in one process installs the
    one-line Ctrl-C hook (startup.interrupted), not the MPI one."""
    code = (
        "import sys, dolfinx_forms; a = sys.excepthook is sys.__excepthook__; "
        "import dolfinx_forms.app.startup as s; import dolfinx_forms.app; "
        "print(a, sys.excepthook is s.interrupted)"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0 and r.stdout.strip() == "True True", r.stderr


def test_solver_failure_on_one_rank_ends_all(tmp_path):
    """A ContactSolverError on rank 1 alone inside a demo's Run block (a step's geometry
    failing on that rank's part) while rank 0 goes on to its next collective: every rank ends
    within seconds, with the message, no traceback (it was a hang: the failing rank returned
    status 1 and the other waited)."""
    script = textwrap.dedent(
        """
        from mpi4py import MPI
        from dolfinx_forms.app.demo import Run
        from dolfinx_forms.solvers.newton import ContactSolverError
        comm = MPI.COMM_WORLD
        with Run("probe", {"out": "never"}, plot=False) as run:
            if comm.rank == 1:
                raise ContactSolverError("step 3: projection failed at point 7")
            comm.barrier()  # rank 0 would wait here forever
        """
    )
    (tmp_path / "fail_in_run.py").write_text(script)
    r, wall = mpirun(["fail_in_run.py"], timeout=120, cwd=tmp_path)
    assert r.returncode != 0
    assert wall < 30, f"took {wall:.1f} s"
    assert "fail_in_run.py: error on rank 1: step 3: projection failed at point 7" in r.stderr
    assert "Traceback" not in r.stderr
    assert not (tmp_path / "never").exists()


def test_ranks_given_different_command_lines_refused(tmp_path):
    """mpirun's MPMD form gives each rank its own arguments: refused on every rank, exit 2,
    nothing written (rank 1 alone given --h 0 used to hang)."""
    exe = shutil.which("mpirun")
    if exe is None or MPI.COMM_WORLD.size > 1:
        pytest.skip("no mpirun, or already under mpirun (no nested launch)")
    demo, out = str(ROOT / "demos" / "patch_test.py"), str(tmp_path / "out")
    t0 = time.perf_counter()
    r = subprocess.run(
        [exe, "-n", "1", sys.executable, demo, "--out", out, ":"]
        + ["-n", "1", sys.executable, demo, "--h", "0", "--out", out],
        capture_output=True,
        text=True,
        env=dict(os.environ, **MPI_ENV),
        timeout=120,
    )
    assert r.returncode == 2, r.stderr
    assert time.perf_counter() - t0 < 30
    lines = [ln for ln in r.stderr.splitlines() if "different command lines" in ln]
    assert len(lines) == 2, r.stderr
    assert list(tmp_path.iterdir()) == []


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


def test_the_condensed_solver_on_two_ranks_is_refused_on_every_rank(tmp_path):
    """MUMPS Schur complements are serial: the demos refuse --linear-solver condensed while
    parsing, the runner once the problem is built (every rank alike); exit 2, nothing written."""
    out = tmp_path / "never"
    demo = [str(ROOT / "demos" / "hertz.py"), "--linear-solver", "condensed", "--out", str(out)]
    scene = ["-m", "dolfinx_forms", "run", str(ROOT / "demos" / "scenes" / "hertz.toml")]
    scene += ["--out", str(out), "--set", 'solver.linear_solver="condensed"']
    for args, name in ((demo, "--linear-solver"), (scene, "solver.linear_solver")):
        r, wall = mpirun(args, timeout=120, cwd=tmp_path)
        assert r.returncode == 2, r.stderr[-2000:]
        lines = [ln for ln in r.stderr.splitlines() if ": error: " in ln]
        assert len(lines) == 2 and all(f"{name}: 'condensed'" in ln for ln in lines), r.stderr
        assert "Traceback" not in r.stderr and list(tmp_path.iterdir()) == []


def test_ranks_that_read_different_descriptions_stop(tmp_path):
    """The same command line, but each rank's folder holds another scene.toml (MPMD launch with
    one working folder per rank): every rank refuses (exit 2) within seconds, nothing written."""
    exe = shutil.which("mpirun")
    if exe is None or MPI.COMM_WORLD.size > 1:
        pytest.skip("no mpirun, or already under mpirun (no nested launch)")
    scene = (ROOT / "demos" / "scenes" / "brazilian_disc.toml").read_text()
    out = tmp_path / "out"
    app = [sys.executable, "-m", "dolfinx_forms", "run", "scene.toml", "--out", str(out)]
    cmd = [exe]
    for rank, E in enumerate(("100e3", "200e3")):
        (d := tmp_path / f"rank{rank}").mkdir()
        (d / "scene.toml").write_text(scene.replace("E = 100e3", f"E = {E}"))
        cmd += ([":"] if rank else []) + ["-n", "1", "--wdir", str(d), *app]
    env = dict(os.environ, **MPI_ENV, PYTHONPATH=str(ROOT))
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 2, r.stderr[-2000:]
    assert "rank 1 read another description than rank 0" in r.stderr
    assert not out.exists()


def test_system_exit_on_one_rank_mid_run_ends_all(tmp_path):
    """sys.exit(3) on rank 1 inside a run (demo.Run) while rank 0 waits in a collective: every
    rank ends within seconds with one line naming the rank."""
    script = textwrap.dedent(
        """
        import sys
        import time
        import dolfinx_forms.app  # noqa: F401
        from dolfinx_forms.app.demo import Run
        with Run("x", {}, plot=False) as run:
            if run.comm.rank == 1:
                sys.exit(3)
            run.comm.barrier()  # rank 0 would wait here forever
            time.sleep(300)
    """
    )
    (tmp_path / "exit_on_rank_1.py").write_text(script)
    r, wall = mpirun(["exit_on_rank_1.py"], timeout=120, cwd=tmp_path)
    assert r.returncode != 0
    assert wall < 20, f"took {wall:.1f} s"
    assert "exit_on_rank_1.py: rank 1 exited (3)" in r.stderr.splitlines()


def test_refusal_on_one_rank_only_ends_all(tmp_path):
    """The same command line, but --out names a foreign folder on rank 1's side only (one
    working folder per rank, MPMD): rank 1 refuses, rank 0 (which passed) exits 2 with it, within
    seconds, and nothing is written."""
    exe = shutil.which("mpirun")
    if exe is None or MPI.COMM_WORLD.size > 1:
        pytest.skip("no mpirun, or already under mpirun (no nested launch)")
    demo = [sys.executable, str(ROOT / "demos" / "patch_test.py"), "--out", "out"]
    cmd = [exe]
    for rank in (0, 1):
        (d := tmp_path / f"rank{rank}").mkdir()
        cmd += ([":"] if rank else []) + ["-n", "1", "--wdir", str(d), *demo]
    (tmp_path / "rank1" / "out").mkdir()
    (tmp_path / "rank1" / "out" / "mine.txt").write_text("not a result")  # a foreign folder
    env = dict(os.environ, **MPI_ENV, PYTHONPATH=str(ROOT))
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=120)
    assert time.perf_counter() - t0 < 30
    assert r.returncode == 2, r.stderr[-2000:]
    assert "--out" in r.stderr
    assert not (tmp_path / "rank0" / "out").exists()
    assert sorted(p.name for p in (tmp_path / "rank1" / "out").iterdir()) == ["mine.txt"]
