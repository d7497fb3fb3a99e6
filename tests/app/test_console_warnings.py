"""The console's warnings (app/checks.py console_warnings): every kind shown, each kind's first
PER_KIND in full and the rest counted; metrics.json keeps them all (the demos' contract)."""

from dolfinx_forms.app.checks import PER_KIND, console_warnings, warning_kind

NODES = "only {} multiplier nodes carry the contact pressure (fewer than 7): the P1 multipliers"


def test_many_pairs_of_one_kind_are_counted():
    """A warning per pair (100 grains: 291 in 2 steps) prints PER_KIND of them and a count;
    another kind, and the numbers' variety inside a kind, do not split the count."""
    warnings = [f"step {1 + k % 2}: g{k}-g{k + 1}: " + NODES.format(2 + k % 3) for k in range(50)]
    warnings.insert(7, "step 1: a-b: penetration 0.0107 = 0.11 h exceeds 0.1 h (soft)")
    lines = console_warnings(warnings)
    assert len(lines) == PER_KIND + 1 + 1
    assert lines[:PER_KIND] == [f"WARNING: {w}" for w in warnings[:PER_KIND]]
    assert "penetration 0.0107" in lines[PER_KIND]
    assert lines[-1].startswith(f"WARNING: {50 - PER_KIND} more like 'only # multiplier nodes")
    assert "the P1 multipliers" in lines[-1]  # a name's digits are not a number
    assert "metrics.json" in lines[-1]


def test_few_warnings_are_printed_whole():
    warnings = ["step 2: disc-platen: " + NODES.format(3), "D4 symmetry broken: forces 4.7e-05"]
    assert console_warnings(warnings) == [f"WARNING: {w}" for w in warnings]
    assert warning_kind("step 12: grain3-plate_top: only 2 nodes") == "only # nodes"
