"""Threads of the BLAS that numpy, PETSc and MUMPS share (Debian's OpenBLAS, pthread build).

OpenBLAS starts as many threads as cores. On small problems its dense kernels (MUMPS's fronts,
the condensed solver's m x m Schur complement) are too short to gain from a second thread, and
when anything else holds a core (the plot worker importing matplotlib, another run on a
shared machine) its spinning threads wait for it: the cut Hertz demo at a/20 took 0.30-0.51 s
in process with two threads and 0.275-0.287 s with one (five interleaved pairs; the Schur
update of 456 contact dofs 6-26 ms against 2 ms); at 1e5 dofs two threads are 7 % faster on
a quiet machine (cut Hertz a/80: 2.86-3.02 s against 3.06-3.24 s). `threads_for` sets the count
at run time through OpenBLAS's own `openblas_set_num_threads` (the library is already loaded by
numpy and PETSc, so the environment variable would come too late). A user's
OPENBLAS_NUM_THREADS wins.
"""

import ctypes
import os


def _openblas():
    """The loaded OpenBLAS (ctypes.CDLL), or None (another BLAS, or none loaded yet)."""
    try:
        with open("/proc/self/maps") as f:
            paths = {line.split()[-1] for line in f if "openblas" in line and "/" in line}
    except OSError:
        return None
    for path in sorted(paths):
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        if hasattr(lib, "openblas_set_num_threads") and hasattr(lib, "openblas_get_num_threads"):
            return lib
    return None


_initial = None  # OpenBLAS's own count, before the first change


def threads_for(small):
    """One BLAS thread for a small problem (or several MPI ranks), OpenBLAS's own count for a
    large one: set at each ContactProblem, so that a process that solves a small and then a
    large problem (a benchmark) gets both right. Returns the count set, or None when nothing
    was changed (OPENBLAS_NUM_THREADS set by the user, or no OpenBLAS)."""
    global _initial
    if "OPENBLAS_NUM_THREADS" in os.environ:
        return None
    lib = _openblas()
    if lib is None:
        return None
    if _initial is None:
        _initial = int(lib.openblas_get_num_threads())
    n = 1 if small else _initial
    lib.openblas_set_num_threads(n)
    return n


def num_threads():
    """The current OpenBLAS thread count, or None without OpenBLAS."""
    lib = _openblas()
    return None if lib is None else int(lib.openblas_get_num_threads())
