"""Small cut fractions (benchmarks/small_cuts.py): the ghost penalty bounds the condition number
of the cut-cell stiffness, and the cut patch test stays exact at a cut fraction of 1e-6.

n = 5 grid, interface at y = (2 + eta) h (eta in the lower body's top row) and mirrored
(2 + 1 - eta) h (eta in the upper body's bottom row). Measured (n = 5): cond(K) = 3.4e2 at
eta = 0.5 and 4.1e2 at eta = 1e-6 with gamma = 0.1 (ratio 1.2); 3.2e2 and 4.8e7 with gamma = 0
(ratio 1.5e5, cond ~ 1/eta); pressure deviation ~ 1e-12.
"""

import pytest

from benchmarks.small_cuts import run_case

N, ETA = 5, 1e-6
BOUNDED = 2.0  # gamma = 0.1: cond(K)(eta) <= BOUNDED * cond(K)(0.5)
GROWS = 1e4  # gamma = 0: cond(K)(eta) >= GROWS * cond(K)(0.5)  (1/eta = 1e6 predicted)
UNIFORM = 1e-8  # max |p - p_pen| / p_pen with gamma = 0.1


@pytest.fixture(scope="module")
def reference():
    return {g: run_case(N, 0.5, g)["cond_K"] for g in (0.0, 0.1)}


@pytest.mark.parametrize("tiny", ["lower", "upper"])
def test_ghost_penalty_bounds_condition_number(reference, tiny):
    rec = run_case(N, ETA, 0.1, tiny)
    assert rec["eta_actual"] == pytest.approx(ETA, rel=1e-6)
    assert not rec["K_singular"] and rec["lambda_min"] > 0
    assert rec["cond_K"] <= BOUNDED * reference[0.1], (rec["cond_K"], reference[0.1])
    # the patch test: linear fields are exact, the ghost penalty vanishes on them
    assert not rec["failed"], rec["error"]
    assert rec["pressure_max_rel_deviation"] <= UNIFORM
    assert rec["reaction_rel_error"] <= UNIFORM
    assert rec["u_error_physical"] <= UNIFORM


@pytest.mark.parametrize("tiny", ["lower", "upper"])
def test_without_ghost_penalty_condition_number_grows(reference, tiny):
    rec = run_case(N, ETA, 0.0, tiny)
    assert rec["cond_K"] >= GROWS * reference[0.0], (rec["cond_K"], reference[0.0])
    assert rec["lambda_min"] > 0  # ill-conditioned, not singular
