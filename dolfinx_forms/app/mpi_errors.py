"""An uncaught error on one MPI rank ends every rank (no hang in the next collective).

Under `mpirun -n N` an exception that leaves one rank's program would otherwise leave the
other ranks waiting forever in their next collective operation. :func:`install` (called by
`dolfinx_forms.app.startup.start()` when MPI.COMM_WORLD.size > 1) replaces the default
`sys.excepthook` with one that writes ONE line

    <prog>: error on rank <r>: <ExcType>: <message>

to stderr and calls MPI.COMM_WORLD.Abort(1), which ends every rank with a nonzero status.
With ILS_VERBOSE=1 the traceback is printed before that line. SystemExit (argument errors,
exit status 2 on every rank) does not go through the hook. A hook installed by someone else
(IPython, a debugger) is left alone.
"""

import sys
import traceback

from dolfinx_forms.app.logs import env_verbose
from dolfinx_forms.common import program_name

MAX_MESSAGE = 2000  # characters of the exception message kept on the line


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
