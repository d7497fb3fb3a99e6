"""Stress suite (issue 11, item 6): under `mpirun -n 2`, rank 0 alone fails while the demo
writes its result folder (rank 1 is then waiting in the barrier that ends the writing): every
rank ends within seconds with a non-zero status and one line naming the error, and nothing is
left: no result folder, no temporary folder. tests/app/test_parallel_errors.py has the same for
rank 1 failing in a plain script; here it is rank 0, inside a demo's atomic folder
(folders.atomic_output_dir). Serial test: it starts mpirun itself (helper of
tests/app/test_parallel_errors.py)."""

import importlib.util
import os
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location(
    "_parallel_errors_helpers", ROOT / "tests" / "app" / "test_parallel_errors.py"
)
_helpers = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_helpers)
mpirun = _helpers.mpirun

WRAPPER = textwrap.dedent(
    """
    import runpy, sys

    import dolfinx_forms.io.results as results  # rank 0 writes metrics.json, the last file

    def fail(*args, **kwargs):
        raise OSError(28, "No space left on device (injected)")

    results.write_metrics = fail
    sys.argv = sys.argv[1:]
    runpy.run_path(sys.argv[0], run_name="__main__")
    """
)


def test_rank_0_fails_while_writing(tmp_path):
    (tmp_path / "fail_writing.py").write_text(WRAPPER)
    folder = tmp_path / "results"
    folder.mkdir()
    demo = ROOT / "demos" / "patch_test.py"
    args = ["fail_writing.py", str(demo), "--h", "0.25", "--out", str(folder / "out")]
    r, wall = mpirun(args, timeout=300, cwd=tmp_path)
    assert r.returncode != 0
    assert wall < 120, f"took {wall:.1f} s"
    ours = [ln for ln in r.stderr.splitlines() if "error on rank" in ln]
    assert ours == [
        "patch_test.py: error on rank 0: OSError: [Errno 28] No space left on device (injected)"
    ], r.stderr
    assert "Traceback" not in r.stderr
    assert os.listdir(folder) == []  # neither the result nor its temporary folder
