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


# warnings of one kind printed in full on the console, the rest counted (all of them stay in
# metrics.json solver.warnings): 100 grains under the augmented Lagrangian gave 291 lines of
# "only 2 multiplier nodes carry the contact pressure" in 2 steps, one per pair
PER_KIND = 3
_NUMBER = re.compile(r"(?<![A-Za-z_])[-+]?\d+(?:\.\d*)?(?:e[-+]?\d+)?")


def warning_kind(text):
    """A warning without its step, its pair or body name and its numbers ("step 3: a-b: only 2
    nodes" -> "only # nodes"): what warnings of one kind share."""
    text = re.sub(r"^step \d+: ", "", text)
    text = re.sub(r"^[^\s:]+: ", "", text)  # a pair's or body's name (no spaces)
    return _NUMBER.sub("#", text)


def console_warnings(warnings, per_kind=PER_KIND):
    """The console's lines for `warnings`: "WARNING: " and each, the first per_kind of each
    kind (`warning_kind`) only, then one line per kind that had more, with their count."""
    seen, lines = {}, []
    for w in warnings:
        k = warning_kind(w)
        seen[k] = seen.get(k, 0) + 1
        if seen[k] <= per_kind:
            lines.append(f"WARNING: {w}")
    for k, n in seen.items():
        if n > per_kind:
            lines.append(f"WARNING: {n - per_kind} more like '{k}' (all in metrics.json "
                         "solver.warnings)")  # fmt: skip
    return lines
