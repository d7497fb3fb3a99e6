"""An uncaught error on one MPI rank ends every rank (no hang in the next collective).

Under `mpirun -n N` an exception that leaves one rank's program would otherwise leave the
other ranks waiting forever in their next collective operation. :func:`install` (called by
`import dolfinx_forms` when MPI.COMM_WORLD.size > 1) replaces the default `sys.excepthook`
with one that writes ONE line

    <prog>: error on rank <r>: <ExcType>: <message>

to stderr and calls MPI.COMM_WORLD.Abort(1), which ends every rank with a nonzero status.
With ILS_VERBOSE=1 the traceback is printed before that line. SystemExit (argument errors,
exit status 2 on every rank) does not go through the hook. A hook installed by someone else
(IPython, a debugger) is left alone.
"""

import os
import sys
import traceback

import numpy as np

from .logs import env_verbose

MAX_MESSAGE = 2000  # characters of the exception message kept on the line


def program_name() -> str:
    """The running program's name: basename of argv[0], the package for `python3 -m pkg`,
    'python3' for -c / interactive."""
    arg0 = sys.argv[0] if sys.argv and sys.argv[0] else ""
    name = os.path.basename(arg0)
    if name == "__main__.py":
        return os.path.basename(os.path.dirname(os.path.abspath(arg0))) or "python3"
    return name if name and name not in ("-c", "-m") else "python3"


def error_line(exc_type, value, rank) -> str:
    """'<prog>: error on rank r: <ExcType>: <message>' on one line (whitespace collapsed)."""
    message = " ".join(str(value).split())
    if len(message) > MAX_MESSAGE:
        message = message[:MAX_MESSAGE] + " ..."
    head = f"{program_name()}: error on rank {rank}: {exc_type.__name__}"
    return f"{head}: {message}" if message else head


def excepthook(exc_type, value, tb):
    from mpi4py import MPI

    try:
        if env_verbose():
            traceback.print_exception(exc_type, value, tb)
        sys.stderr.write(error_line(exc_type, value, MPI.COMM_WORLD.rank) + "\n")
        sys.stderr.flush()
        sys.stdout.flush()
    finally:
        MPI.COMM_WORLD.Abort(1)


def install() -> bool:
    """Install :func:`excepthook` if the current hook is Python's default; True if installed."""
    if sys.excepthook is sys.__excepthook__:
        sys.excepthook = excepthook
    return sys.excepthook is excepthook


def allreduce_array(comm, a, op):
    """Element-wise MPI reduction of a numpy array (buffer based: the pickled `allreduce`
    compares whole arrays for MIN/MAX)."""
    a = np.ascontiguousarray(a)
    out = np.empty_like(a)
    comm.Allreduce(a, out, op=op)
    return out
