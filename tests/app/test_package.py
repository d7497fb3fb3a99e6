"""Package hygiene: nothing edits sys.path, every program's --help shows the defaults, and JIT
compilation is quiet unless asked for (the import structure: test_layout.py)."""

import importlib.util
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DEMOS = sorted((ROOT / "demos").glob("*.py"))


def test_no_sys_path_edits():
    offenders = []
    for folder in ("demos", "tests", "benchmarks", "meshes", "dolfinx_forms"):
        for f in sorted((ROOT / folder).rglob("*.py")):
            for i, line in enumerate(f.read_text().splitlines(), 1):
                code = line.split("#", 1)[0]
                if re.search(r"sys\.path\.(insert|append|extend)|sys\.path\s*[+]?=", code):
                    offenders.append(f"{f.relative_to(ROOT)}:{i}")
    assert offenders == []


def _load(path):
    spec = importlib.util.spec_from_file_location(f"_demo_{path.stem}", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("demo", [d.name for d in DEMOS])
def test_help_shows_defaults(demo, capsys):
    mod = _load(ROOT / "demos" / demo)
    with pytest.raises(SystemExit) as e:
        mod.parse(["--help"])
    assert e.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    for opt in ("--out", "--force", "--verbose"):
        assert opt in text
    assert re.search(r"--out OUT .*?\(?default: results/", text)
    # every option with a value default states it
    parser_defaults = re.findall(r"(--[\w-]+) [A-Z_\[\]\.0-9=,{}]+ [^-]*?default: ", text)
    assert len(parser_defaults) >= 2, text


def _compile_tiny_form(cache, verbose_env=False, verbose_flag=False):
    """A fresh JIT cache: FFCx generates and cffi compiles one form in a child process (a
    program with the shared parser, given --verbose or not)."""
    script = textwrap.dedent(
        f"""
        import sys
        import ufl
        from dolfinx import fem, mesh
        from mpi4py import MPI
        from dolfinx_forms.app.cli import DemoParser

        DemoParser(prog="tiny.py").parse_args(sys.argv[1:])
        m = mesh.create_unit_square(MPI.COMM_SELF, 1, 1)
        V = fem.FunctionSpace(m, ("Lagrange", 1))
        u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
        fem.form(1.2345 * ufl.inner(u, v) * ufl.dx, jit_params={{"cache_dir": {str(cache)!r}}})
        print("compiled", flush=True)
        """
    )
    env = {k: v for k, v in os.environ.items() if k != "ILS_VERBOSE"}
    env.update(XDG_CACHE_HOME=str(cache), **({"ILS_VERBOSE": "1"} if verbose_env else {}))
    args = ["--verbose"] if verbose_flag else []
    r = subprocess.run(
        [sys.executable, "-c", script, *args], capture_output=True, text=True, env=env, timeout=300
    )
    assert r.returncode == 0, r.stderr
    assert any(cache.rglob("*.so")), "nothing was compiled: the cache was not fresh"
    return r.stdout + r.stderr


def test_jit_quiet_on_fresh_cache(tmp_path):
    out = _compile_tiny_form(tmp_path / "quiet")
    assert "compiled" in out
    assert [ln for ln in out.splitlines() if "INFO" in ln] == []


@pytest.mark.parametrize("how", ["env", "flag"])
def test_jit_verbose_on_request(tmp_path, how):
    out = _compile_tiny_form(tmp_path / how, verbose_env=how == "env", verbose_flag=how == "flag")
    assert "INFO:root" in out
