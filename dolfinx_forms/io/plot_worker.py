"""Line plots (output.plot_lines), drawn in this process or in a worker process started early.

A demo's default plot (tractions.png) costs ~0.5 s of a ~1.5 s process: matplotlib's import
(0.3-0.4 s) and the drawing (0.1 s). When a core is idle, `start()` (demo.Run, before the
run computes) launches `python3 -P plot_worker.py`, which imports matplotlib while the run
computes, then draws the one figure it receives, replies and exits at once; the figure is the
one `draw` makes in-process (same code, same matplotlib, same PNG bytes). A demo starts it
even earlier, as the application starts (`start_early`).

Protocol: the parent writes one pickled (path, lines, title, xlabel, ylabel, vlines) to the
worker's stdin and closes it; the worker answers "ok" or the error's traceback on stdout. An
empty stdin (the run failed, nothing to plot) ends the worker. The worker ignores SIGINT (the
parent's Ctrl-C handling decides what remains) and imports nothing of this package (no MPI).
"""

import os
import pickle
import subprocess
import sys


def draw(path, lines, title="", xlabel="x (mm)", ylabel="", vlines=()):
    """Curves {label: (x, y, style)} (style "-": a line, ".": points) and dotted vertical lines
    at the abscissae `vlines`, in one PNG."""
    import matplotlib  # only here: most of a run never plots

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    for label, (x, y, style) in lines.items():
        ax.plot(x, y, style, label=label, **(dict(ms=3) if style == "." else dict(lw=1)))
    for xv in vlines:
        ax.axvline(xv, color="0.6", lw=0.8, ls=":")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


class Worker:
    """A started worker process: `plot` (once) or `close`."""

    def __init__(self):
        # -P: not this folder first on sys.path (its module names must not shadow matplotlib's)
        self.proc = subprocess.Popen(
            [sys.executable, "-P", os.path.abspath(__file__)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
        )

    def plot(self, *args):
        """Draw draw(*args) in the worker; False if the worker is gone (the caller draws)."""
        try:
            reply, _ = self.proc.communicate(pickle.dumps(args))
        except OSError:  # BrokenPipeError: it died before reading
            self.close()
            return False
        if self.proc.returncode != 0 or not reply:
            return False
        if reply != b"ok":
            raise RuntimeError(f"plotting {args[0]} failed in the plot worker:\n{reply.decode()}")
        return True

    def close(self):
        """End an unused worker (the run failed or plotted nothing)."""
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.communicate()


def start():
    """A Worker, or None (the plot is then drawn in-process): when no core is idle besides the
    run's own (1-minute load average above the cores less 0.5) or no process can be started.
    On a busy machine the worker does not run beside the run but takes its CPU (a second
    interpreter, and the BLAS threads of the factorisations wait for a core): measured 0.1-0.2 s
    slower there."""
    if os.getloadavg()[0] > (os.cpu_count() or 1) - 0.5:
        return None
    try:
        return Worker()
    except OSError:
        return None


_early = None  # the Worker of `start_early`, until `take_early`


def start_early():
    """For a demo (a script in a folder named demos run as the program, on rank 0): start the
    worker as the application starts (dolfinx_forms.app.startup), so that matplotlib's
    import (0.4 s) overlaps the package's own (dolfinx, ufl, ffcx, MPI: ~0.45 s) as well as
    the run. Cut Hertz at a/10, whole process: 1.02-1.07 s -> 0.72-0.82 s (5 interleaved
    pairs). The first plot takes it over (`take_early`); unused (bad input, no plot) it is
    ended at exit. ILS_EARLY_PLOT=0 turns it off."""
    global _early
    import atexit
    from pathlib import Path

    main = getattr(sys.modules.get("__main__"), "__file__", None)
    if _early is not None or main is None or Path(main).resolve().parent.name != "demos":
        return
    rank = os.environ.get("OMPI_COMM_WORLD_RANK", os.environ.get("PMI_RANK", "0"))
    if rank != "0" or os.environ.get("ILS_EARLY_PLOT", "1") == "0":
        return
    _early = start()
    if _early is not None:
        atexit.register(_end_early)


def take_early():
    """The early worker, if one was started and no plot has taken it (else None)."""
    global _early
    worker, _early = _early, None
    return worker


def _end_early():
    worker = take_early()
    if worker is not None:
        worker.close()


def _serve():
    import signal
    import traceback

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    import matplotlib  # now, while the parent computes

    matplotlib.use("Agg")
    import io

    import matplotlib.pyplot  # noqa: F401

    # a throwaway figure while the parent computes: the first figure of a process pays for
    # loading the fonts and the Agg renderer (0.11 s against 0.08 s for the next ones)
    draw(io.BytesIO(), {"warm-up": ([0.0, 1.0], [0.0, 1.0], "-")}, "t", vlines=(0.5,))
    data = sys.stdin.buffer.read()
    if data:
        try:
            draw(*pickle.loads(data))
            reply = b"ok"
        except BaseException:
            reply = traceback.format_exc().encode()
        sys.stdout.buffer.write(reply)
        sys.stdout.flush()
    # the figure is written and closed: skip the interpreter's clean-up of matplotlib (0.1 s)
    os._exit(0)


if __name__ == "__main__":
    _serve()
