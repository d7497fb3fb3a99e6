"""A run's outcome (RunResult) and the [[checks]] of a description evaluated on its
metrics.json record: what the single-step runner (runner.py) and the multi-step one
(mpm_runner.py) share."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path


@dataclass
class RunResult:
    metrics: dict  # the metrics.json record (every rank)
    passed: bool  # every check passed
    failures: list = field(default_factory=list)  # one line per failed check
    folder: Path | None = None  # where the results are (None: not written)
    problem: object = None


def lookup(metrics, path):
    """metrics['results']['reaction'][1] for 'results.reaction[1]' (KeyError if absent)."""
    node = metrics
    for part in re.findall(r"[^.\[\]]+", path):
        try:
            node = node[int(part)] if isinstance(node, list) else node[part]
        except (KeyError, IndexError, ValueError, TypeError):
            raise KeyError(path) from None
    return node


def evaluate_checks(metrics, checks):
    """Records {label, quantity, value, criterion, passed, reason} of the checks."""
    out = []
    for c in checks:
        rec = {
            "label": c["label"],
            "quantity": c["quantity"],
            "value": None,
            "passed": False,
            "reason": "",
        }
        try:
            value = lookup(metrics, c["quantity"])
            refs = {
                k: lookup(metrics, c[k]) if isinstance(c[k], str) else c[k]
                for k in ("close_to", "below", "above")
            }
        except KeyError as e:
            rec.update(criterion="", reason=f"{e.args[0]} is not in metrics.json")
            out.append(rec)
            continue
        parts, ok = [], True
        if refs["close_to"] is not None:
            tol = max(c["atol"] or 0.0, (c["rtol"] or 0.0) * abs(refs["close_to"] or 0.0))
            parts.append(f"close to {refs['close_to']:.6g} within {tol:.3g}")
            ok &= (
                value is not None
                and refs["close_to"] is not None
                and abs(value - refs["close_to"]) <= tol
            )
        if refs["below"] is not None:
            parts.append(f"<= {refs['below']:.6g}")
            ok &= value is not None and value <= refs["below"]
        if refs["above"] is not None:
            parts.append(f">= {refs['above']:.6g}")
            ok &= value is not None and value >= refs["above"]
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            ok, why = False, f"{c['quantity']} is {value!r}, not a number"
        else:
            why = "" if ok else f"{c['quantity']} = {value:.6g} is not " + " and ".join(parts)
        rec.update(value=value, criterion=" and ".join(parts), passed=bool(ok), reason=why)
        out.append(rec)
    return out
