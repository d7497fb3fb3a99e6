"""Process start-up of the cut Hertz demo (issue 12, item 3): what a run imports and what it
leaves in the environment. Each check is a fresh interpreter (imports are per process)."""

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _python(code, **env):
    e = dict(os.environ, PYTHONPATH=str(ROOT), **env)
    for k in ("OMPI_MCA_pml", "OMPI_MCA_btl"):  # as a user's shell has them: unset
        if k not in env:
            e.pop(k, None)
    p = subprocess.run([sys.executable, "-c", code], env=e, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout.strip().splitlines()[-1])


IMPORTS = """
import json, os, sys
import dolfinx_forms.app, dolfinx, dolfinx.fem.petsc, ufl, ffcx
from mpi4py import MPI
print(json.dumps(dict(
    modules=[m for m in ("gmsh", "pkg_resources", "matplotlib") if m in sys.modules],
    env={k: os.environ.get(k) for k in ("OMPI_MCA_pml", "OMPI_MCA_btl")},
    versions=[ufl.__version__, ffcx.__version__], size=MPI.COMM_WORLD.size)))
"""


def test_application_start_is_lean():
    """The application's start-up (dolfinx_forms.app.startup, what every demo and the runner
    run): no gmsh, pkg_resources or matplotlib on import; ufl and ffcx know their versions;
    the singleton's MPI settings are gone from the environment (an mpirun started from here
    must not inherit btl=self). The library's own import does nothing: test_layout.py."""
    r = _python(IMPORTS)
    assert r["modules"] == []
    assert r["env"] == {"OMPI_MCA_pml": None, "OMPI_MCA_btl": None}
    from importlib.metadata import version

    assert r["versions"] == [version("fenics-ufl"), version("fenics-ffcx")]
    assert r["size"] == 1


def test_user_mpi_settings_kept():
    """A user's own pml/btl choice is neither overridden nor removed."""
    r = _python(IMPORTS, OMPI_MCA_pml="ob1", OMPI_MCA_btl="self,vader")
    assert r["env"] == {"OMPI_MCA_pml": "ob1", "OMPI_MCA_btl": "self,vader"}


SESSION = """
import json, os
from dolfinx_forms.app import startup
startup.start()
from mpi4py import MPI
mine = startup.isolated_session_dir({})["OMPI_MCA_orte_top_session_dir"]
print(json.dumps(dict(top=mine, inside=os.path.isdir(os.path.join(mine, "jf.0", "1", "0")),
                      env=os.environ.get("OMPI_MCA_orte_top_session_dir"))))
"""


def test_isolated_singletons_have_their_own_session_folder():
    """Every isolated singleton is job 1 of family 0: a shared session folder made two runs at
    once race (one's MPI_Init failed to mkdir .../jf.0/1, exit 1). Each process has its own,
    named by its pid, which Open MPI removes at MPI_Finalize; the setting does not stay in the
    environment; a user's own choice is kept."""
    r = _python(SESSION)
    assert r["inside"] and r["env"] is None
    assert str(os.getpid()) not in r["top"] and not os.path.exists(r["top"])
    from dolfinx_forms.app import startup

    assert startup.isolated_session_dir({"OMPI_MCA_orte_top_session_dir": "/x"}) == {}
    mine = startup.isolated_session_dir({})["OMPI_MCA_orte_top_session_dir"]
    assert mine.endswith(f".singleton.{os.getpid()}")


CHILD_MPI_ENV = (
    "import json, os; print(json.dumps(sorted(k for k in os.environ"
    " if k.startswith(('PMIX_', 'OMPI_', 'ORTE_')))))"
)


def test_mpi_init_environment_not_passed_to_children():
    """MPI_Init writes a singleton's daemon address and PMIX_RANK=0 to the C environment, which
    subprocess passes to a child started with env=None (the child then joined this job as a
    second rank 0). drop_mpi_environment removes what the process did not start with: a
    variable set in the C environment only (os.putenv) is dropped and reaches no child; this
    process (tests/conftest.py) and an application process (startup) pass none of MPI's."""
    from dolfinx_forms.common import drop_mpi_environment

    started = {k for k in os.environ if k.startswith(("PMIX_", "OMPI_", "ORTE_"))}
    os.putenv("OMPI_ILS_PROBE", "1")  # the C environment only, as MPI_Init's setenv
    assert drop_mpi_environment() == ["OMPI_ILS_PROBE"]
    child = subprocess.run([sys.executable, "-c", CHILD_MPI_ENV], capture_output=True, text=True)
    assert set(json.loads(child.stdout)) <= started
    code = (
        "import dolfinx_forms.app, subprocess, sys; from mpi4py import MPI; "
        f"print(subprocess.run([sys.executable, '-c', {CHILD_MPI_ENV!r}], capture_output=True,"
        " text=True).stdout)"
    )
    grandchild = _python(code, OMPI_MCA_ess_singleton_isolated="0")  # a daemon, as pytest's
    # the variables it was given (the Makefile's OMPI_ALLOW_RUN_AS_ROOT...) and its own only
    given = started - {"OMPI_MCA_pml", "OMPI_MCA_btl"}
    assert set(grandchild) == given | {"OMPI_MCA_ess_singleton_isolated"}


def test_pkg_resources_still_works_after():
    r = _python(
        "import json, dolfinx_forms.app, pkg_resources\n"
        "print(json.dumps([pkg_resources.get_distribution('fenics-ufl').version,"
        " hasattr(pkg_resources, 'iter_entry_points')]))"
    )
    from importlib.metadata import version

    assert r == [version("fenics-ufl"), True]


def test_cut_demo_imports(tmp_path):
    """The cut demo's module imports neither gmsh nor matplotlib (the plot imports it when it
    draws); the GetFEM benchmark's mesher imports neither dolfinx nor mpi4py."""
    r = _python(
        "import json, runpy, sys\n"
        f"runpy.run_path({str(ROOT / 'demos' / 'hertz.py')!r}, run_name='not_main')\n"
        "print(json.dumps([m for m in ('gmsh', 'matplotlib', 'pkg_resources') "
        "if m in sys.modules]))"
    )
    assert r == []
    r = _python(
        "import json, sys\n"
        "from dolfinx_forms.mesh.scene import gmsh_model\n"
        "print(json.dumps([m for m in ('dolfinx', 'mpi4py') if m in sys.modules]))"
    )
    assert r == []


def _lines():
    import numpy as np

    x = np.linspace(-1, 1, 200)
    return {"p_n computed": (x, 1 - x**2, "."), "Hertz": (x, np.sqrt(1 - x**2), "-")}


def test_plot_worker_draws_the_same_png(tmp_path):
    """The worker's PNG is byte for byte the in-process one; it is used once, then plot_lines
    draws in-process again."""
    from dolfinx_forms.io import output, plot_worker

    plot_worker.draw(tmp_path / "here.png", _lines(), "t", "x", "y", (0.5,))
    output._worker = worker = plot_worker.Worker()  # start_plot_worker: none on a busy machine
    output.plot_lines(tmp_path / "worker.png", _lines(), "t", "x", "y", (0.5,))
    assert output._worker is None and worker.proc.returncode == 0
    assert (tmp_path / "worker.png").read_bytes() == (tmp_path / "here.png").read_bytes()
    output.plot_lines(tmp_path / "again.png", _lines(), "t", "x", "y", (0.5,))
    assert (tmp_path / "again.png").read_bytes() == (tmp_path / "here.png").read_bytes()


def test_plot_worker_errors_and_unused(tmp_path):
    """An error in the worker is raised in the caller; an unused worker is ended."""
    import pytest

    from dolfinx_forms.io import output, plot_worker

    output._worker = plot_worker.Worker()
    with pytest.raises(RuntimeError, match="plot worker"):
        output.plot_lines(tmp_path / "missing" / "x.png", _lines())
    output._worker = worker = plot_worker.Worker()
    output.stop_plot_worker()
    assert worker.proc.poll() is not None and output._worker is None


def test_plot_worker_only_when_a_core_is_idle(monkeypatch):
    from dolfinx_forms.io import plot_worker

    monkeypatch.setattr(plot_worker.os, "getloadavg", lambda: (64.0, 64.0, 64.0))
    assert plot_worker.start() is None
    monkeypatch.setattr(plot_worker.os, "getloadavg", lambda: (0.0, 0.0, 0.0))
    worker = plot_worker.start()
    assert worker is not None
    worker.close()


def test_plot_worker_started_early_for_a_demo(monkeypatch, tmp_path):
    """A script in demos/ (rank 0) starts the worker as the package is imported; the first
    plot takes it over; another script, another rank or ILS_EARLY_PLOT=0 does not start it."""
    import types

    from dolfinx_forms.io import output, plot_worker

    started = []
    monkeypatch.setattr(plot_worker, "start", lambda: started.append(1) or "worker")
    main = types.SimpleNamespace(__file__=str(ROOT / "demos" / "hertz.py"))
    monkeypatch.setitem(sys.modules, "__main__", main)
    for env in ({"OMPI_COMM_WORLD_RANK": "1"}, {"ILS_EARLY_PLOT": "0"}):
        with monkeypatch.context() as m:
            for k, v in env.items():
                m.setenv(k, v)
            plot_worker.start_early()
        assert plot_worker.take_early() is None and not started
    main.__file__ = str(tmp_path / "hertz.py")  # not this repository's demos
    plot_worker.start_early()
    assert plot_worker.take_early() is None and not started
    main.__file__ = str(ROOT / "demos" / "hertz.py")
    plot_worker.start_early()
    assert started == [1]
    output.start_plot_worker()  # demo.Run: takes the early worker, starts no other
    assert output._worker == "worker" and started == [1] and plot_worker.take_early() is None
    output._worker = None


def test_demo_process_plots_with_the_early_worker(tmp_path):
    """The demo's PNG is written whether the early worker draws it or the process does."""
    for early in ("1", "0"):
        out = tmp_path / early
        r = subprocess.run(
            [sys.executable, str(ROOT / "demos" / "patch_test.py"), "--out", str(out)],
            env=dict(os.environ, PYTHONPATH=str(ROOT), ILS_EARLY_PLOT=early),
            capture_output=True,
            text=True,
        )
        assert r.returncode == 0, r.stderr
        assert (out / "tractions.png").stat().st_size > 1000


def test_exit_process_status():
    """cli.exit_process: the status reaches the shell (0, 1)."""
    for status in (0, 1):
        p = subprocess.run(
            [
                sys.executable,
                "-c",
                f"from dolfinx_forms.app import cli; cli.exit_process({status})",
            ],
            env=dict(os.environ, PYTHONPATH=str(ROOT)),
        )
        assert p.returncode == status


def test_gmsh_preloaded_with_its_own_scope():
    """dolfinx_forms.mesh.scene.import_gmsh after DOLFINx's import: libgmsh is mapped once (gmsh.py
    found the preloaded library open) and meshes as before: a unit disc at size 0.2 gives the same
    node count as gmsh imported first in another process."""
    code = """
import json, sys
first = sys.argv[1] == "first"
if first:
    import gmsh
import dolfinx_forms, dolfinx, dolfinx.fem.petsc
from dolfinx_forms.mesh.scene import import_gmsh
gmsh = import_gmsh()
maps = {l.split()[-1] for l in open("/proc/self/maps") if "libgmsh" in l}
gmsh.initialize(); gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.occ.addDisk(0, 0, 0, 1, 1); gmsh.model.occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.2); gmsh.model.mesh.generate(2)
n = len(gmsh.model.mesh.getNodes()[0]); gmsh.finalize()
print(json.dumps(dict(libs=len(maps), nodes=n)))
"""
    e = dict(os.environ, PYTHONPATH=str(ROOT))
    out = {}
    for mode in ("preload", "first"):
        p = subprocess.run(
            [sys.executable, "-c", code, mode], env=e, capture_output=True, text=True, cwd=ROOT
        )
        assert p.returncode == 0, p.stderr
        out[mode] = json.loads(p.stdout.strip().splitlines()[-1])
    assert out["preload"]["libs"] == 1
    assert out["preload"]["nodes"] == out["first"]["nodes"] > 50


HUGE = """
HUGE_PAGES = True
import json, os
import dolfinx_forms.app
print(json.dumps(dict(tunables=os.environ.get("GLIBC_TUNABLES"))))
"""


def test_huge_pages_restart_rules():
    """Who is restarted with huge pages (startup.huge_pages_restart): a script that declares
    HUGE_PAGES, with THP in "madvise" mode and glibc >= 2.35, once; the user's own tunables kept;
    ILS_HUGE_PAGES=0 turns it off."""
    from types import SimpleNamespace

    from dolfinx_forms.app import startup

    main, mode, libc = SimpleNamespace(HUGE_PAGES=True), "always [madvise] never", "glibc 2.36"
    exe, argv, env = startup.huge_pages_restart(main, {"A": "1"}, mode, libc)
    assert exe == sys.executable and argv == sys.orig_argv
    assert env == {"A": "1", "GLIBC_TUNABLES": "glibc.malloc.hugetlb=1"}
    user = {"GLIBC_TUNABLES": "glibc.malloc.arena_max=2"}
    env = startup.huge_pages_restart(main, user, mode, libc)[2]
    assert env["GLIBC_TUNABLES"] == "glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1"
    for args in [
        (SimpleNamespace(), {}, mode, libc),  # not declared
        (main, {"ILS_HUGE_PAGES": "0"}, mode, libc),
        (main, {"GLIBC_TUNABLES": "glibc.malloc.hugetlb=0"}, mode, libc),  # the user's choice
        (main, env, mode, libc),  # restarted already
        (main, {}, "[always] madvise never", libc),  # huge already
        (main, {}, "always madvise [never]", libc),
        (main, {}, mode, "glibc 2.31"),
        (main, {}, mode, ""),  # another C library
    ]:
        assert startup.huge_pages_restart(*args) is None, args


def test_huge_pages_demo_process(tmp_path):
    """A process that declares HUGE_PAGES runs on with the tunable where this machine allows it
    (and once: the restarted process does not restart again), without it under
    ILS_HUGE_PAGES=0."""
    from types import SimpleNamespace

    from dolfinx_forms.app import startup

    clean = {k: v for k, v in os.environ.items() if k not in ("GLIBC_TUNABLES", "ILS_HUGE_PAGES")}
    allowed = startup.huge_pages_restart(SimpleNamespace(HUGE_PAGES=True), clean) is not None
    env = dict(clean, PYTHONPATH=str(ROOT))
    for k in ("OMPI_MCA_pml", "OMPI_MCA_btl"):
        env.pop(k, None)
    for off, expected in [("1", "glibc.malloc.hugetlb=1" if allowed else None), ("0", None)]:
        p = subprocess.run(
            [sys.executable, "-c", HUGE], env=dict(env, ILS_HUGE_PAGES=off), capture_output=True,
            text=True, timeout=120,
        )
        assert p.returncode == 0, p.stderr
        assert json.loads(p.stdout.strip().splitlines()[-1])["tunables"] == expected
