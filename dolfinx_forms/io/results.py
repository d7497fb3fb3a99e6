"""The results contract: metrics.json keys and atomic output folders.

One source of truth for the layout of metrics.json; every demo builds its record
with `new_metrics` and writes with `write_results`. Result folders (the --out rules, the
marker file, atomic replacement): folders.py.
"""

import json
import time
from contextlib import contextmanager
from pathlib import Path


PHASES = ("total", "mesh", "assembly", "contact", "solve", "mls", "points", "evolution")


def new_metrics(benchmark, discretization, parameters):
    """A metrics record with every key of the contract (null where not defined)."""
    return {
        "benchmark": benchmark,
        "discretization": discretization,
        "parameters": dict(parameters),
        "mesh": {"h_contact": None, "num_cells": None, "num_dofs": None},
        "solver": {
            "load_steps": 0,
            "newton_iterations": [],
            "converged": None,
            "residual_history": [],
            "penalty": {"eps_n": None, "eps_t": None},
        },
        "timing_s": {k: 0.0 for k in PHASES},
        "results": {
            "reaction": None,
            "contact_half_width": None,
            "peak_pressure": None,
            "stick_half_width": None,
            "pressure_rel_l2_error": None,
            "traction_rel_l2_error": None,
        },
        "analytic": {"contact_half_width": None, "peak_pressure": None, "stick_half_width": None},
    }


class PhaseTimer:
    """Accumulates wall time per phase into metrics['timing_s']."""

    def __init__(self, metrics):
        self.timing = metrics["timing_s"]
        self.t0 = time.perf_counter()

    @contextmanager
    def phase(self, name):
        if name not in PHASES:
            raise KeyError(f"unknown phase {name!r}; phases are {PHASES}")
        t = time.perf_counter()
        try:
            yield
        finally:
            self.timing[name] += time.perf_counter() - t

    def stop(self):
        self.timing["total"] = time.perf_counter() - self.t0


def _check_finite(obj, path="metrics"):
    """Numerical failure must never reach a results file as NaN/inf."""
    if isinstance(obj, float) and (obj != obj or obj in (float("inf"), float("-inf"))):
        raise FloatingPointError(f"{path} is not finite")
    if isinstance(obj, dict):
        for k, v in obj.items():
            _check_finite(v, f"{path}.{k}")
    if isinstance(obj, (list, tuple)):
        for i, v in enumerate(obj):
            _check_finite(v, f"{path}[{i}]")


def write_metrics(folder, metrics):
    _check_finite(metrics)
    with open(Path(folder) / "metrics.json", "w") as f:
        json.dump(metrics, f, indent=2)
