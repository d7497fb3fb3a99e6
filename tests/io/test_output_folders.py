"""Result folders (dolfinx_forms/io/folders.py): atomic, marked, never deleting what this code did
not write; --out refused at parse time with one line and exit status 2."""

import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from mpi4py import MPI

from dolfinx_forms.app.cli import DemoParser
from dolfinx_forms.io.folders import (
    MARKER,
    OutputFolderError,
    atomic_output_dir,
    check_output_path,
    read_marker,
)

ROOT = Path(__file__).resolve().parents[2]
NOT_OURS = "exists and is not a result folder of this code (use another path or --force)"


def write(out, files, force=False, program="test"):
    with atomic_output_dir(out, MPI.COMM_SELF, force=force, program=program) as tmp:
        for name, text in files.items():
            (tmp / name).parent.mkdir(parents=True, exist_ok=True)
            (tmp / name).write_text(text)


def listing(folder):
    return sorted(p.relative_to(folder).as_posix() for p in Path(folder).rglob("*"))


def test_new_folder_marker_and_permissions(tmp_path):
    out = tmp_path / "a" / "b"
    old = os.umask(0o027)
    try:
        write(out, {"m.json": "1", "runs/x.csv": "2"}, program="prog.py")
    finally:
        os.umask(old)
    assert listing(out) == [MARKER, "m.json", "runs", "runs/x.csv"]
    marker = read_marker(out)
    assert marker["program"] == "prog.py" and marker["files"] == {"m.json", "runs", "runs/x.csv"}
    assert (out.stat().st_mode & 0o777) == 0o750  # not mkdtemp's 0o700
    assert (out / "m.json").stat().st_mode & 0o777 == 0o640
    assert [p.name for p in tmp_path.iterdir()] == ["a"]  # no temporary folder left


def test_result_folder_replaced_empty_folder_used(tmp_path):
    out = tmp_path / "r"
    write(out, {"old.txt": "old", "keep/deep.txt": "x"})
    write(out, {"new.txt": "new"})
    assert listing(out) == [MARKER, "new.txt"]
    empty = tmp_path / "e"
    empty.mkdir()
    write(empty, {"f": "1"})
    assert listing(empty) == [MARKER, "f"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["e", "r"]


@pytest.mark.parametrize("extra", ["notes.txt", "runs/notes.txt"])
def test_foreign_content_refused_then_merged_with_force(tmp_path, extra):
    out = tmp_path / "r"
    write(out, {"metrics.json": "1", "runs/a.csv": "a"})
    (out / extra).write_text("mine")  # a file the user added to a result folder
    with pytest.raises(OutputFolderError) as e:
        check_output_path(out)
    assert str(e.value) == f"--out: {out} {NOT_OURS}"
    with pytest.raises(OutputFolderError, match="not a result folder"):
        write(out, {"metrics.json": "2"})
    assert (out / "metrics.json").read_text() == "1" and (out / extra).read_text() == "mine"
    write(out, {"metrics.json": "2", "runs/b.csv": "b"}, force=True)
    assert (out / extra).read_text() == "mine"  # never deleted
    assert (out / "metrics.json").read_text() == "2"
    # our earlier file not written again is removed, the new one added
    assert not (out / "runs" / "a.csv").exists() and (out / "runs" / "b.csv").read_text() == "b"
    m = read_marker(out)
    assert extra not in m["files"] and {"metrics.json", "runs", "runs/b.csv"} <= m["files"]
    assert "runs/a.csv" not in m["files"]


def test_force_adds_next_to_foreign_files_never_overwrites(tmp_path):
    out = tmp_path / "project"
    out.mkdir()
    (out / "paper.tex").write_text("text")
    with pytest.raises(OutputFolderError, match="not a result folder"):
        check_output_path(out)
    write(out, {"metrics.json": "1"}, force=True)
    assert listing(out) == [MARKER, "metrics.json", "paper.tex"]
    assert (out / "paper.tex").read_text() == "text"
    write(out, {"metrics.json": "2", "tractions.csv": "t"}, force=True)  # ours: replaced
    assert (out / "metrics.json").read_text() == "2" and (out / "paper.tex").read_text() == "text"
    # a foreign file with one of our names: refused while parsing, and at the move
    other = tmp_path / "other"
    other.mkdir()
    (other / "metrics.json").write_text("theirs")
    with pytest.raises(OutputFolderError, match="metrics.json"):
        check_output_path(other, force=True)
    with pytest.raises(OutputFolderError, match="metrics.json"):
        write(other, {"metrics.json": "ours", "x.csv": "x"}, force=True)
    assert listing(other) == ["metrics.json"] and (other / "metrics.json").read_text() == "theirs"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["other", "project"]


def test_refused_paths(tmp_path, monkeypatch):
    f = tmp_path / "file"
    f.write_text("x")
    monkeypatch.chdir(tmp_path)
    cases = {
        "": "must be a folder path",
        ".": "the current folder",
        str(tmp_path): "the current folder",
        "..": "a parent of the current folder",
        "/": "the filesystem root",
        str(Path.home()): "the home folder",
        str(f): "exists and is not a folder",
        str(f / "sub"): "is not a folder",
    }
    for text, what in cases.items():
        for force in (False, True):
            with pytest.raises(OutputFolderError, match=what) as e:
                check_output_path(text, force=force)
            assert str(e.value).startswith("--out: ") and "\n" not in str(e.value)
    assert f.read_text() == "x" and sorted(p.name for p in tmp_path.iterdir()) == ["file"]


def test_failure_leaves_nothing(tmp_path):
    out = tmp_path / "r"
    write(out, {"a": "1"})
    with pytest.raises(RuntimeError):
        with atomic_output_dir(out, MPI.COMM_SELF) as tmp:
            (tmp / "a").write_text("half")
            raise RuntimeError("solver failed")
    assert (out / "a").read_text() == "1" and listing(tmp_path) == ["r", f"r/{MARKER}", "r/a"]


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_signal_while_writing(tmp_path, sig):
    """A signal while the results are written: no folder under the final name, no leftovers."""
    script = textwrap.dedent(
        f"""
        import time, sys
        from pathlib import Path
        from mpi4py import MPI
        from dolfinx_forms.io.folders import atomic_output_dir
        with atomic_output_dir({str(tmp_path / 'out')!r}, MPI.COMM_SELF) as tmp:
            (tmp / "part.csv").write_text("half")
            print("writing", flush=True)
            time.sleep(60)
    """
    )
    p = subprocess.Popen(
        [sys.executable, "-c", script],
        stdout=subprocess.PIPE,
        text=True,
        stderr=subprocess.DEVNULL,
        cwd=tmp_path,
    )
    try:
        assert p.stdout.readline().strip() == "writing"
        assert len(list(tmp_path.iterdir())) == 1  # the temporary folder, hidden
        p.send_signal(sig)
        p.wait(timeout=30)
    finally:
        p.kill()
    assert p.returncode != 0
    assert list(tmp_path.iterdir()) == []


def test_parser_checks_out_before_running(tmp_path):
    p = DemoParser(prog="demo.py")
    p.add_out("results/x")
    assert p.parse_args(["--out", str(tmp_path / "new")]).force is False
    (tmp_path / "foreign").mkdir()
    (tmp_path / "foreign" / "f").write_text("x")
    with pytest.raises(SystemExit) as e:
        p.parse_args(["--out", str(tmp_path / "foreign")])
    assert e.value.code == 2
    assert p.parse_args(["--out", str(tmp_path / "foreign"), "--force"]).force is True


def test_demo_refuses_foreign_out_before_computing(tmp_path):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "data.txt").write_text("keep")
    r = subprocess.run(
        [
            sys.executable,
            str(ROOT / "demos" / "patch_test.py"),
            "--out",
            str(out),
            "--discretization",
            "cut",
        ],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert r.returncode == 2, r.stderr
    lines = [ln for ln in r.stderr.splitlines() if "mca_base" not in ln]
    assert lines == [f"patch_test.py: error: --out: {out} {NOT_OURS}"]
    assert listing(tmp_path) == ["mine", "mine/data.txt"]
    r = subprocess.run(
        [
            sys.executable,
            str(ROOT / "demos" / "patch_test.py"),
            "--out",
            str(out),
            "--discretization",
            "cut",
            "--h",
            "0.2",
            "--force",
        ],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert r.returncode == 0, r.stderr
    assert (out / "data.txt").read_text() == "keep"
    assert json.loads((out / "metrics.json").read_text())["benchmark"] == "patch"
    assert read_marker(out)["program"] == "patch_test.py"


def test_too_long_a_folder_name_is_refused_before_computing(tmp_path):
    """A name the file system cannot hold (with the temporary folder's affixes) is one line
    at parse time, not a traceback after the run (issue 29)."""
    with pytest.raises(OutputFolderError, match="a folder name of at most"):
        check_output_path(tmp_path / ("a" * 300))
    assert check_output_path(tmp_path / ("a" * 200)) == (tmp_path / ("a" * 200)).resolve()
