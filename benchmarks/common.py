"""What several benchmarks share: atomic result files, the commit they measured, a child
process with its peak memory, and demos/hertz.py as a module.

The benchmarks import it as `benchmarks.common` (the repository root on PYTHONPATH, as
`make bench` and `make test` set it).
"""

import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# runs a script and prints its peak resident memory (kB) as the last line of stderr, in one
# write: print()'s pieces, unbuffered (PYTHONUNBUFFERED), interleaved with another rank's lines
# under mpirun and the benchmark read 0 MB
WRAP = (
    "import resource, runpy, sys; script = sys.argv[1]; sys.argv = sys.argv[1:]\n"
    "try:\n    runpy.run_path(script, run_name='__main__')\n"
    "except SystemExit as e:\n    code = e.code\nelse:\n    code = 0\n"
    "sys.stderr.write(f'peak_rss_kb {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss}\\n')\n"
    "sys.exit(code)"
)


def huge_pages_env():
    """The variables under which a multi-step demo runs (its start-up restarts it with them,
    `dolfinx_forms.app.startup.huge_pages_restart`), or {} where this machine runs it without:
    for a reference run beside it, so that both get the same memory allocator."""
    from types import SimpleNamespace

    # the module alone: importing dolfinx_forms.app would start the application here (MPI)
    spec = importlib.util.spec_from_file_location(
        "_startup", ROOT / "dolfinx_forms" / "app" / "startup.py"
    )
    startup = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(startup)
    command = startup.huge_pages_restart(SimpleNamespace(HUGE_PAGES=True), dict(os.environ))
    return {} if command is None else {"GLIBC_TUNABLES": command[2]["GLIBC_TUNABLES"]}


def write_atomic(path, writer):
    """writer(tmp_path) writes the file; it then replaces `path` in one rename (a reader sees
    the old file or the new one, never a part)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        writer(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the usual file mode
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def write_text(path, text):
    """`text` into `path` in one rename."""
    write_atomic(path, lambda tmp: Path(tmp).write_text(text))


def write_json(path, data):
    """`data` as indented JSON (no NaN) into `path` in one rename."""

    def writer(tmp):
        with open(tmp, "w") as f:
            json.dump(data, f, indent=2, allow_nan=False)
            f.write("\n")
            f.flush()
            os.fsync(f.fileno())

    write_atomic(path, writer)


def git_head():
    """The commit measured and the tracked files modified against it (None outside git)."""
    try:
        r = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True, timeout=30
        )
        d = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"],
            cwd=ROOT,
            capture_output=True,
            text=True,
            timeout=30,
        )
        return dict(
            commit=r.stdout.strip() or None,
            modified=[ln[3:] for ln in d.stdout.splitlines() if ln.strip()],
        )
    except (OSError, subprocess.SubprocessError):
        return dict(commit=None, modified=None)


def child(cmd, timeout, env=None):
    """Run the script cmd[0] with arguments cmd[1:] (env: variables added to this process's);
    returns (returncode, stdout, stderr, wall seconds, peak RSS in MB)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), **(env or {}))
    t0 = time.perf_counter()
    proc = subprocess.Popen(
        [sys.executable, "-c", WRAP, *cmd],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        cwd=ROOT,
    )
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        return -9, out, f"timeout after {timeout} s", time.perf_counter() - t0, 0.0
    wall = time.perf_counter() - t0
    lines = [x for x in err.splitlines() if x.startswith("peak_rss_kb ")]
    rss = int(lines[-1].split()[1]) / 1024 if lines else 0.0
    err = "\n".join(x for x in err.splitlines() if not x.startswith("peak_rss_kb "))
    return proc.returncode, out, err, wall, rss


def load_script(path, name=None):
    """A script of the repository (demos/ and benchmarks/ are not packages) as a module,
    registered in sys.modules under `name` (default: its file name)."""
    path = Path(path)
    name = name or path.stem
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


def hertz_demo():
    """demos/hertz.py as a module (its parse, estimate and scene)."""
    return load_script(ROOT / "demos" / "hertz.py", "hertz_demo")
