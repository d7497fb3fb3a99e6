"""Run many command lines of `python3 -m dolfinx_forms` in ONE interpreter (as cli_batch.py
does for the demos): the imports cost ~2 s per process, a refused description milliseconds.

    /usr/bin/python3 tests/stress/runner_batch.py CASES.json RESULTS.json

CASES.json: a list of {"argv": [...], "cwd": "/some/folder"}; RESULTS.json: per case {"code",
"status", "stdout", "stderr", "seconds"} with the statuses of cli_batch.py; "computed": the
description passed every check and the multi-step run (`mpm_runner.run`) would have started
(it is replaced by a function that raises).
Nothing here is a pytest test; tests/stress/test_hostile_multistep.py starts it.
"""

import importlib.util
import sys
from pathlib import Path

# cli_batch.py beside this file, loaded by path (no sys.path edits: tests/app/test_package.py)
_file = Path(__file__).with_name("cli_batch.py")
_spec = importlib.util.spec_from_file_location("cli_batch", _file)
cli_batch = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cli_batch)


def main(cases_file, results_file):
    import dolfinx_forms.__main__ as entry
    from dolfinx_forms.app import mpm_runner

    mpm_runner.run = cli_batch._guard  # a description that passed: stop before computing

    def run_case(case, scratch):
        return cli_batch.run_one(entry, "-m dolfinx_forms", case, scratch)

    cli_batch.run_batch(cases_file, results_file, "runner_batch.", run_case)


if __name__ == "__main__":
    main(*sys.argv[1:3])
