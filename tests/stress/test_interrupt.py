"""Stress suite (issue 11, item 6): SIGINT sent to a running demo (demos/patch_test.py, the
cheapest), while it computes and while it writes its result folder. Afterwards the exit status
is not 0, `--out` is absent or still the complete previous result, and no temporary folder
(`.out.*.partial`, folders.py) is left beside it.

The demo runs as a real process through a small wrapper that prints a line when the demo
reaches the phase (the load ramp, or metrics.json: the last file written into the temporary
folder, after solution.xdmf, tractions.csv and tractions.png) and, while writing, waits there,
so the signal arrives in that phase every time. With `gmsh first` the wrapper imports gmsh
before the demo, as a program that uses gmsh itself would: gmsh's import sets SIGINT to the
default action (a plain kill) and only gmsh.finalize restores it, which the cut path never
calls.
"""

import os
import select
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "demos" / "patch_test.py"
WRAPPER = textwrap.dedent(
    """
    import runpy, sys, time

    phase, gmsh_first, demo = sys.argv[1:4]
    if gmsh_first == "1":
        import gmsh  # noqa: F401  (SIGINT: default action from here on)
    sys.argv = [demo] + sys.argv[4:]
    if phase == "writing":
        import dolfinx_forms.io.results as results

        write_metrics = results.write_metrics

        def wait_then_write(*args, **kwargs):
            print("phase writing", flush=True)
            time.sleep(120)
            return write_metrics(*args, **kwargs)

        results.write_metrics = wait_then_write
    else:
        import dolfinx_forms.solvers.protocol as protocol

        ramp = protocol.ramp

        def announced_ramp(*args, **kwargs):
            print("phase computing", flush=True)
            return ramp(*args, **kwargs)

        protocol.ramp = announced_ramp
    runpy.run_path(demo, run_name="__main__")
    """
)
ARGS = {"conforming": ["--h", "0.03125"], "cut": ["--discretization", "cut", "--h", "0.0625"]}


def snapshot(d):
    """{relative path: content} of everything below d."""
    return {
        p.relative_to(d).as_posix(): (p.read_bytes() if p.is_file() else None)
        for p in sorted(Path(d).rglob("*"))
    }


def interrupt(tmp_path, phase, discretization, out, gmsh_first=False):
    """Run the demo into `out`, send SIGINT once it reports `phase`; returns (exit status,
    stdout, stderr, the names in out's parent when the signal was sent)."""
    wrapper = tmp_path / "wrapper.py"
    wrapper.write_text(WRAPPER)
    cmd = [sys.executable, str(wrapper), phase, "1" if gmsh_first else "0", str(DEMO)]
    cmd += ARGS[discretization] + ["--out", str(out)]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lines, seen = [], None
    try:
        deadline = time.monotonic() + 240
        while time.monotonic() < deadline:
            ready, _, _ = select.select([p.stdout], [], [], 5)
            line = p.stdout.readline() if ready else ""
            if ready and not line:
                break  # the demo ended before the phase
            lines.append(line)
            if line.strip() == f"phase {phase}":
                seen = sorted(os.listdir(out.parent))
                p.send_signal(signal.SIGINT)
                break
        assert seen is not None, f"never reached {phase}: {''.join(lines)}{p.stderr.read()}"
        stdout, stderr = p.communicate(timeout=120)
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    return p.returncode, "".join(lines) + stdout, stderr, seen


@pytest.fixture(scope="module")
def previous(tmp_path_factory):
    """A complete result folder of the demo (cut path, coarse)."""
    out = tmp_path_factory.mktemp("previous") / "out"
    r = subprocess.run(
        [sys.executable, str(DEMO), *ARGS["cut"], "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    return out


def partials(names):
    return [n for n in names if n.startswith(".out.") and n.endswith(".partial")]


@pytest.mark.parametrize("discretization", ["conforming", "cut"])
def test_sigint_while_computing(tmp_path, discretization):
    folder = tmp_path / "results"
    folder.mkdir()
    out = folder / "out"
    code, stdout, stderr, seen = interrupt(tmp_path, "computing", discretization, out)
    assert code != 0, stderr
    assert "results in" not in stdout
    assert seen == []  # computing: no result folder started yet
    assert os.listdir(folder) == []


@pytest.mark.parametrize("gmsh_first", [False, True], ids=["plain", "gmsh first"])
@pytest.mark.parametrize("before", ["absent", "previous result"])
def test_sigint_while_writing_cut(tmp_path, previous, before, gmsh_first):
    """The temporary folder holds solution.xdmf, tractions.csv and tractions.png when the
    signal comes; afterwards it is gone and --out is as before."""
    folder = tmp_path / "results"
    folder.mkdir()
    out = folder / "out"
    if before == "previous result":
        shutil.copytree(previous, out, symlinks=True)
    expected = snapshot(out) if out.exists() else None
    code, stdout, stderr, seen = interrupt(tmp_path, "writing", "cut", out, gmsh_first)
    assert code != 0, stderr
    assert "results in" not in stdout
    assert len(partials(seen)) == 1  # the signal came while the temporary folder was written
    assert partials(os.listdir(folder)) == [], "a temporary folder was left behind"
    if expected is None:
        assert os.listdir(folder) == []
    else:
        assert os.listdir(folder) == ["out"] and snapshot(out) == expected


def test_sigint_while_writing_conforming(tmp_path, previous):
    """The body-fitted path (gmsh imported and finalized while meshing) over a previous
    result."""
    folder = tmp_path / "results"
    folder.mkdir()
    out = folder / "out"
    shutil.copytree(previous, out, symlinks=True)
    expected = snapshot(out)
    code, stdout, stderr, seen = interrupt(tmp_path, "writing", "conforming", out)
    assert code != 0, stderr
    assert len(partials(seen)) == 1
    assert os.listdir(folder) == ["out"] and snapshot(out) == expected
