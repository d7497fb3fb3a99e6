"""Small helpers shared by the library's sub-packages: MPI reductions of arrays, the running
program's name (for one-line messages), the threads a rank may use, the error of a bad scene
description and the signals that unwind (a block's clean-up runs when it is interrupted)."""

import os
import signal
import sys
import threading
from contextlib import contextmanager

import numpy as np


def program_name() -> str:
    """The running program's name: basename of argv[0], the package for `python3 -m pkg`,
    'python3' for -c / interactive."""
    arg0 = sys.argv[0] if sys.argv and sys.argv[0] else ""
    name = os.path.basename(arg0)
    if name == "__main__.py":
        return os.path.basename(os.path.dirname(os.path.abspath(arg0))) or "python3"
    return name if name and name not in ("-c", "-m") else "python3"


MPI_ENVIRONMENT_PREFIXES = ("PMIX_", "OMPI_", "ORTE_")  # what Open MPI's MPI_Init sets


def drop_mpi_environment() -> list[str]:
    """Unset the variables MPI_Init put in this process's C environment (PMIX_*, OMPI_*,
    ORTE_* that os.environ, the environment the process started with plus Python's own
    changes, does not hold); returns their names.

    Why: Python's subprocess with env=None passes the C environment, and an Open MPI singleton
    writes its helper daemon's address and its own identity there (PMIX_SERVER_URI*,
    PMIX_NAMESPACE, PMIX_RANK=0). A child MPI program then takes itself for a launched rank:
    it joins this process's job as a second rank 0 (pytest's process and every demo it ran
    shared one namespace). Variables the process started with (under mpirun) are kept."""
    import ctypes

    try:
        environ = ctypes.POINTER(ctypes.c_char_p).in_dll(ctypes.CDLL(None), "environ")
    except (OSError, ValueError, AttributeError):
        return []
    names, i = [], 0
    while environ[i] is not None:
        names.append(environ[i].split(b"=", 1)[0].decode(errors="replace"))
        i += 1
    dropped = [n for n in names if n.startswith(MPI_ENVIRONMENT_PREFIXES) and n not in os.environ]
    for n in dropped:
        os.unsetenv(n)
    return dropped


def worker_threads(comm):
    """Threads each rank gives its C++ loops over points (the MLS projection): ILS_THREADS if
    set (>= 1), else this process's cores shared among the ranks (at least 1). Results do not
    depend on it."""
    env = os.environ.get("ILS_THREADS")
    if env:
        try:
            n = int(env)
        except ValueError:
            n = 0
        if n < 1:
            raise ValueError(f"ILS_THREADS must be an integer >= 1, got {env!r}")
        return n
    return max(1, len(os.sched_getaffinity(0)) // comm.size)


def allreduce_array(comm, a, op):
    """Element-wise MPI reduction of a numpy array (buffer based: the pickled `allreduce`
    compares whole arrays for MIN/MAX)."""
    a = np.ascontiguousarray(a)
    out = np.empty_like(a)
    comm.Allreduce(a, out, op=op)
    return out


class SpecError(ValueError):
    """A bad description: `key` is the dotted path of the offending key."""

    def __init__(self, key, message):
        self.key = key
        super().__init__(f"{key}: {message}")


class SolverChoiceError(ValueError):
    """An explicitly chosen linear solver that does not apply to the problem (solvers/linear.py
    `pick`): a bad input, found once the problem is built and on every rank alike. The demos
    and the runner exit 2 naming their option."""


@contextmanager
def signals_unwind():
    """Within the block (main thread only), SIGINT raises KeyboardInterrupt and SIGTERM
    SystemExit(143) where the handler is the default action, so the block's clean-up runs (a
    result folder's temporary folder is removed, a JIT compile's claim released): importing
    gmsh (also through dolfinx.io.gmshio) sets SIGINT's handler to the default action, and only
    gmsh.finalize restores it. Other handlers are left alone (an enclosing block's too)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def term(signum, frame):
        raise SystemExit(128 + signum)

    handlers = {signal.SIGINT: signal.default_int_handler, signal.SIGTERM: term}
    ours = [s for s in handlers if signal.getsignal(s) is signal.SIG_DFL]
    for s in ours:
        signal.signal(s, handlers[s])
    try:
        yield
    finally:
        for s in ours:
            signal.signal(s, signal.SIG_DFL)
