"""The tuned numbers of the method, in one place: what each one sets, the value, and the
study that chose it (`STUDIES`: a reproducible benchmark script, run by `make calibrate`
or by hand, that sweeps the value on the case it was tuned on and on a second case).

Every module reads its value from `TUNING` at the moment it needs it, so a study (or a user)
can try another value with `dataclasses.replace`:

    import dolfinx_forms.defaults as d
    d.TUNING = dataclasses.replace(d.TUNING, pointwise_eps0=1.0)

Thresholds of the self-checks (solvers/checks.py: PENETRATION, RIGID_RTOL, MIN_NODES) and
size limits are not tuned numbers: they stay beside the code they bound, with their reason.
"""

from dataclasses import dataclass, fields


@dataclass(frozen=True)
class Tuning:
    # the augmented Lagrangian's point-wise regularisation (eq 51's scale, contact.penalty):
    # eps_n = pointwise_eps0 h / E_c with the lumped projection of the multipliers
    pointwise_eps0: float = 2.0
    # eps_n = consistent_eps0 h / E_c with the consistent or hybrid projection (the default)
    consistent_eps0: float = 1.0
    # the P1 multiplier nodes' spacing, in h, with the consistent or hybrid projection
    consistent_length: float = 1.5
    # eps_t = pointwise_eps0_t h / E_c: the tangential regularisation a step's loop starts at
    pointwise_eps0_t: float = 1.5
    # eps_t = consistent_eps0_t h / E_c: where the continuation ends (consistent, hybrid)
    consistent_eps0_t: float = 1.0
    # the hybrid projection: a node whose hat has this fraction of its weight on closed points
    # gets the consistent row, the others the lumped one
    hybrid_closed_fraction: float = 0.75
    # the P1 multiplier nodes aligned with the contact zones (`NewtonOptions.al_align`): the
    # first node outside a contact edge lies this fraction of a multiplier element past it
    # (Hertz a/20, p(x), body-fitted / cut: R = 10, 0 / 0.15 / 0.27 / 0.4 / 0.5: 1.21 / 1.12 /
    # 1.07 / 1.09 / 1.19 % and 1.19 / 1.06 / 1.08 / 1.18 / 1.27 %; R = 40: 1.09 / 0.99 / 0.92 /
    # 0.93 / 1.03 % and 1.12 / 0.98 / 0.98 / 1.06 / 1.13 %; the best at a/20, a/40, a/80 too)
    edge_offset: float = 0.27
    # the demos' --eps0 with --enforcement augmented (it sets the Uzawa step only)
    augmented_eps0: float = 1e-2
    # linear solves: "auto" condenses the bulk where m^3 <= condensed_cost n^1.5
    condensed_cost: float = 400.0
    # below this many dofs the dense kernels run on one BLAS thread
    blas_one_thread_dofs: int = 50_000


TUNING = Tuning()

# field -> the study that chose it: the script and its arguments (benchmarks/calibration.py
# sweeps the value on Hertz R = 10 at a/20, the tuning case, and on Hertz R = 40 at a/20, a
# case it was not tuned on; the others are measured by the scripts named)
STUDIES = {
    "pointwise_eps0": "benchmarks/calibration.py --constant pointwise_eps0",
    "consistent_eps0": "benchmarks/calibration.py --constant consistent_eps0",
    "consistent_length": "benchmarks/calibration.py --constant consistent_length",
    "pointwise_eps0_t": "benchmarks/calibration.py --constant pointwise_eps0_t",
    "consistent_eps0_t": "benchmarks/calibration.py --constant consistent_eps0_t",
    "hybrid_closed_fraction": "benchmarks/calibration.py --constant hybrid_closed_fraction",
    "edge_offset": "benchmarks/calibration.py --constant edge_offset",
    "augmented_eps0": "benchmarks/calibration.py --constant augmented_eps0",
    "condensed_cost": "benchmarks/scaling.py (condensed against factorised, side by side)",
    "blas_one_thread_dofs": "benchmarks/scaling.py (one and two BLAS threads, side by side)",
}
assert set(STUDIES) == {f.name for f in fields(Tuning)}
