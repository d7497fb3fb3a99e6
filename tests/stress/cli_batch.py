"""Run many command lines of the demos in ONE interpreter (the imports of dolfinx, gmsh and
PETSc cost ~2 s per process; a bad command line must fail in milliseconds after them).

    /usr/bin/python3 tests/stress/cli_batch.py CASES.json RESULTS.json

CASES.json: a list of {"demo": "patch_test", "argv": [...], "cwd": "/some/folder"}. For each
case the demo's `main(argv)` runs with the current folder `cwd`, sys.argv[0] the demo's path,
and the file descriptors 1 and 2 redirected to files (so output of C libraries is caught
too). RESULTS.json: per case {"code": exit status, "status": ..., "stdout", "stderr",
"seconds"}; status is

* "exit": main raised SystemExit (code: its status, as the interpreter would report it),
* "returned": main returned (code: its value, as `sys.exit(main())` would give),
* "computed": main got past its argument checks (it called the demo's Run or
  sweep, replaced here by a function that raises): a bad command line that was not refused,
* "exception": any other exception (its traceback is on the captured stderr, code 1),
* "timeout": the case took longer than 60 s (SIGALRM),
* "import": the demo cannot be imported (its traceback is the stderr).

Nothing here is a pytest test; tests/stress/test_bad_inputs.py starts it.
"""

import importlib.util
import json
import os
import signal
import sys
import tempfile
import time
import traceback
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
GUARDED = ("Run", "sweep")  # where a demo starts computing
TIMEOUT = 60


class Computed(Exception):
    """A demo got past its argument checks."""


class Timeout(Exception):
    pass


def _guard(*args, **kwargs):
    raise Computed()


def load(demo):
    """demos/<demo>.py as a module, its entry points to the computation guarded."""
    spec = importlib.util.spec_from_file_location(f"stress_{demo}", ROOT / "demos" / f"{demo}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    for name in GUARDED:
        if hasattr(mod, name):
            setattr(mod, name, _guard)
    return mod


def _exit_status(code):
    """The process exit status of SystemExit(code), and what the interpreter would print."""
    if code is None:
        return 0, ""
    if isinstance(code, int):
        return code, ""
    return 1, f"{code}\n"


def run_one(mod, path, case, scratch):
    sys.argv = [str(path)] + list(case["argv"])
    os.chdir(case["cwd"])
    sys.stdout.flush()
    sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    files = [tempfile.TemporaryFile(dir=scratch) for _ in range(2)]
    os.dup2(files[0].fileno(), 1)
    os.dup2(files[1].fileno(), 2)
    t0 = time.perf_counter()
    signal.alarm(TIMEOUT)
    try:
        try:
            code, status = mod.main(list(case["argv"])), "returned"
            code = _exit_status(code)[0]
        except SystemExit as e:
            code, text = _exit_status(e.code)
            sys.stderr.write(text)
            status = "exit"
        except Computed:
            code, status = None, "computed"
        except Timeout:
            code, status = None, "timeout"
        except BaseException:
            traceback.print_exc()
            code, status = 1, "exception"
    finally:
        signal.alarm(0)
        sys.stdout.flush()
        sys.stderr.flush()
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        os.close(saved[0])
        os.close(saved[1])
        os.chdir(scratch)
    out = []
    for f in files:
        f.seek(0)
        out.append(f.read().decode(errors="replace"))
        f.close()
    return dict(
        code=code, status=status, stdout=out[0], stderr=out[1], seconds=time.perf_counter() - t0
    )


def run_batch(cases_file, results_file, prefix, run_case):
    """run_case(case, scratch) for every case of CASES.json, under the SIGALRM timeout, in a
    scratch folder removed afterwards; the results to RESULTS.json (runner_batch.py too)."""
    cases = json.loads(Path(cases_file).read_text())
    results_file = Path(results_file).resolve()

    def alarm(signum, frame):
        raise Timeout()

    signal.signal(signal.SIGALRM, alarm)
    home = os.getcwd()
    scratch = tempfile.mkdtemp(prefix=prefix)
    results = []
    try:
        for case in cases:
            results.append(run_case(case, scratch))
    finally:
        os.chdir(home)
        for p in Path(scratch).iterdir():
            p.unlink()
        os.rmdir(scratch)
    Path(results_file).write_text(json.dumps(results, indent=1))


def main(cases_file, results_file):
    modules = {}

    def run_case(case, scratch):
        demo = case["demo"]
        if demo not in modules:
            try:
                modules[demo] = load(demo)
            except BaseException:
                modules[demo] = traceback.format_exc()
        if isinstance(modules[demo], str):  # the demo cannot be imported
            return dict(code=1, status="import", stdout="", stderr=modules[demo])
        return run_one(modules[demo], ROOT / "demos" / f"{demo}.py", case, scratch)

    run_batch(cases_file, results_file, "cli_batch.", run_case)


if __name__ == "__main__":
    main(*sys.argv[1:3])
