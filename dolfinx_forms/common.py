"""Small helpers shared by the library's sub-packages: MPI reductions of arrays, the running
program's name (for one-line messages) and the error of a bad scene description."""

import os
import sys

import numpy as np


def program_name() -> str:
    """The running program's name: basename of argv[0], the package for `python3 -m pkg`,
    'python3' for -c / interactive."""
    arg0 = sys.argv[0] if sys.argv and sys.argv[0] else ""
    name = os.path.basename(arg0)
    if name == "__main__.py":
        return os.path.basename(os.path.dirname(os.path.abspath(arg0))) or "python3"
    return name if name and name not in ("-c", "-m") else "python3"


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
