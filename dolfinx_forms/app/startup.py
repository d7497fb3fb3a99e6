"""Process start-up of the application (demos, `python3 -m dolfinx_forms`, the scene runner):
settings that make a run start faster or end cleanly, made once, before MPI, UFL and FFCx are
imported. The library itself (`import dolfinx_forms`) does none of this.

`start()`:
* a script that sets `HUGE_PAGES = True` before it imports this package is restarted once with
  glibc's transparent huge pages for large allocations (`huge_pages_restart`);
* an early plotting worker for a demo (io/plot_worker.py: matplotlib's import overlaps ours);
* Open MPI singleton settings (no helper daemon, no transport probing: ~0.6 s of a
  singleton's start; a session folder of its own, `isolated_session_dir`), removed from the
  environment again after MPI_Init;
* one OpenBLAS thread per MPI rank under mpirun (the ranks already share the cores);
* UFL's and FFCx's version look-up without scanning every installed distribution;
* quiet JIT loggers (app/logs.py) and, under mpirun, an error on one rank ends every rank
  (app/mpi_errors.py); in a single process Ctrl-C (SIGINT) ends the program with one line
  and status 130, not a traceback (`interrupted`).
"""

import os
import sys

def _setup_mpi():
    """Quiet JIT loggers (logs.py) and, under mpirun, an error on one rank ends every rank
    (mpi_errors.py)."""
    from dolfinx_forms.app import logs

    logs.configure()
    # A singleton's only peer is itself, yet Open MPI's default point-to-point layer (UCX) and
    # transports (TCP, shared memory) probe the machine for ~0.2 s in MPI_Init. The setting
    # is read by MPI_Init only and removed after it: an mpirun started from this process must
    # not inherit btl=self. A launched process (mpirun, srun, hydra) keeps the defaults.
    launched = ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "SLURM_PROCID")
    alone = "mpi4py.MPI" not in sys.modules and not any(k in os.environ for k in launched)
    singleton = {"OMPI_MCA_pml": "ob1", "OMPI_MCA_btl": "self"}
    if not alone or any(k in os.environ for k in singleton):
        singleton = {}
    if alone and os.environ.get("OMPI_MCA_ess_singleton_isolated") == "1":
        singleton.update(isolated_session_dir(os.environ))
    os.environ.update(singleton)
    try:
        from mpi4py import MPI
    finally:
        for k in singleton:
            del os.environ[k]
    # what MPI_Init wrote to the C environment must not reach the programs this one starts
    from dolfinx_forms.common import drop_mpi_environment

    drop_mpi_environment()

    if MPI.COMM_WORLD.size > 1:
        from dolfinx_forms.app import mpi_errors

        mpi_errors.install()


def isolated_session_dir(environ) -> dict:
    """{OMPI_MCA_orte_top_session_dir: a folder of this process's own} for an isolated Open MPI
    singleton, {} where the user chose one.

    Why: every isolated singleton (no helper daemon: `start`) has the same name, job 1 of job
    family 0, so all of them share the session folder <tmp>/ompi.<host>.<uid>/jf.0/1, and each
    removes it at MPI_Finalize when empty. Two runs at once (a parameter sweep, `xargs -P`)
    then race: one's MPI_Init fails with "A call to mkdir was unable to create the desired
    directory ... jf.0/1" and exit 1 (2 of ~745 runs of four concurrent Hertz demos). A folder
    per process, which Open MPI creates and removes itself, has no one to race with; a killed
    run leaves its empty folders behind, as Open MPI's own do."""
    if "OMPI_MCA_orte_top_session_dir" in environ:
        return {}
    import tempfile

    name = f"ompi.{os.uname().nodename}.{os.getuid()}.singleton.{os.getpid()}"
    return {"OMPI_MCA_orte_top_session_dir": os.path.join(tempfile.gettempdir(), name)}


def _import_ufl_ffcx():
    """Debian's ufl and ffcx (2022.2, 0.5) read their own version at import with pkg_resources,
    which scans every installed distribution (0.1 s, a third of importing dolfinx). These two
    imports see a stand-in whose get_distribution answers from the name of the distribution's
    .dist-info folder on sys.path (importlib.metadata, itself 0.04 s to import, where there is
    none), the same version string; pkg_resources itself stays importable (the stand-in is
    removed after)."""
    if any(m in sys.modules for m in ("pkg_resources", "ufl", "ffcx")):
        return
    import types

    def version(name):
        prefix = name.replace("-", "_").lower() + "-"
        for folder in sys.path:
            try:
                entries = os.listdir(folder or ".")
            except OSError:
                continue
            for e in entries:
                if e.endswith(".dist-info") and e.lower().startswith(prefix):
                    return e[len(prefix) : -len(".dist-info")]
        import importlib.metadata

        return importlib.metadata.version(name)

    def get_distribution(name):
        return types.SimpleNamespace(version=version(name))

    sys.modules["pkg_resources"] = types.ModuleType("pkg_resources", "ufl/ffcx stand-in")
    sys.modules["pkg_resources"].get_distribution = get_distribution
    try:
        import ffcx  # noqa: F401
        import ufl  # noqa: F401
    finally:
        del sys.modules["pkg_resources"]





# The glibc tunable that backs malloc's large blocks with transparent huge pages (glibc >= 2.35;
# the kernel's THP mode "madvise"), and the variable that turns the restart off ("0").
HUGE_PAGES_TUNABLE = "glibc.malloc.hugetlb=1"
HUGE_PAGES_ENV = "ILS_HUGE_PAGES"


def huge_pages_restart(main=None, environ=None, thp_mode=None, libc=None):
    """The command that restarts this process with `HUGE_PAGES_TUNABLE` in GLIBC_TUNABLES,
    (executable, argv, environment), or None where it does not apply.

    Why: a material-point step builds a new mesh, so each step's first sparse factorisation
    (MUMPS) and its matrices get fresh memory, and on the virtual machines this code runs on
    each 4 KB page fault costs microseconds: 234k faults in 6 steps of 100 grains, the step's
    first factorisation 0.25-0.6 s against 0.15 s for the next ones on the same matrix. With
    2 MB pages the faults fall 7x; side by side, 400 grains x 3 steps ran in 41.8 s instead of
    58.1 s (solve 18.8 / 26.3 s, assembly 4.4 / 7.5 s), 100 grains x 6 steps 15.5 / 16.4 s,
    the Brazilian disc 12.4 / 12.7 s. The restart costs ~0.25 s (the interpreter, numpy and the
    compiled module once more), so only scripts that declare `HUGE_PAGES = True` in __main__
    before importing this package (the multi-step demos) are restarted. Not restarted: the
    tunable already set (by the user or by the restart), ILS_HUGE_PAGES=0, no THP "madvise"
    mode (under "always" the pages are huge already), glibc older than 2.35, no sys.orig_argv
    (and pytest: `_restart_with_huge_pages`)."""
    main = sys.modules.get("__main__") if main is None else main
    environ = os.environ if environ is None else environ
    if not getattr(main, "HUGE_PAGES", False) or environ.get(HUGE_PAGES_ENV, "1") == "0":
        return None
    tunables = environ.get("GLIBC_TUNABLES", "")
    if "glibc.malloc.hugetlb" in tunables:
        return None
    argv = getattr(sys, "orig_argv", None)
    if not argv or not sys.executable:
        return None
    if thp_mode is None:
        try:
            with open("/sys/kernel/mm/transparent_hugepage/enabled") as f:
                thp_mode = f.read()
        except OSError:
            return None
    libc = os.confstr("CS_GNU_LIBC_VERSION") if libc is None else libc  # "glibc 2.36"
    try:
        name, version = (libc or "").split()
        new_enough = name == "glibc" and tuple(map(int, version.split(".")[:2])) >= (2, 35)
    except ValueError:
        new_enough = False
    if "[madvise]" not in thp_mode or not new_enough:
        return None
    env = dict(environ, GLIBC_TUNABLES=":".join(t for t in (tunables, HUGE_PAGES_TUNABLE) if t))
    return sys.executable, list(argv), env


def _restart_with_huge_pages():
    command = None if "pytest" in sys.modules else huge_pages_restart()
    if command is None:
        return
    sys.stdout.flush()
    sys.stderr.flush()
    try:
        os.execve(*command)
    except OSError:  # the run goes on without huge pages
        pass


_started = False


def start():
    """The application's start-up (module doc); once per process, later calls do nothing."""
    global _started
    if _started:
        return
    _started = True
    _restart_with_huge_pages()
    from dolfinx_forms.io import plot_worker

    plot_worker.start_early()
    # A process started without mpirun is an Open MPI singleton: by default its MPI_Init starts
    # a helper daemon (for MPI_Comm_spawn, which this code never calls), ~0.4 s of every run's
    # start. Under mpirun the setting has no effect; a user's own value is kept.
    os.environ.setdefault("OMPI_MCA_ess_singleton_isolated", "1")
    # OpenBLAS starts a thread per core; MPI ranks already share the cores.
    if int(os.environ.get("OMPI_COMM_WORLD_SIZE", "1")) > 1:
        os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    _import_ufl_ffcx()
    _setup_mpi()
    if sys.excepthook is sys.__excepthook__:  # not under mpirun (mpi_errors' hook), nor IPython
        sys.excepthook = interrupted


def interrupted(kind, value, tb):
    """sys.excepthook: KeyboardInterrupt as one line "<prog>: interrupted" and status 130 (the
    shell's for SIGINT); anything else as Python reports it. The result folder is already
    cleaned up by then (folders.atomic_output_dir)."""
    if not issubclass(kind, KeyboardInterrupt):
        return sys.__excepthook__(kind, value, tb)
    from dolfinx_forms.common import program_name

    sys.stdout.flush()
    sys.stderr.write(f"{program_name()}: interrupted\n")
    sys.stderr.flush()
    os._exit(130)
