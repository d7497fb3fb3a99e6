"""The self-checks of a converged contact state (checks.py): each one fires on the case it is
for and stays quiet on a sound one; a demo run outside the penalty's window reports them in
metrics.json and on the console (exit 0, the answer flagged, not silently wrong)."""

import json
import os
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from dolfinx_forms.solvers.checks import PENETRATION, pair_warnings

ROOT = Path(__file__).resolve().parents[2]
H, BAND = 0.1, 0.2


def pair(state, g_n=None, g_n0=None):
    n = len(state)
    x = np.linspace(0, 1, n)
    g = SimpleNamespace(
        points=np.c_[x, np.zeros(n)][::-1].copy(),  # any order: sorted along the tangent
        tangents=np.tile([1.0, 0.0], (n, 1)),
        g_n0=np.zeros(n) if g_n0 is None else g_n0[::-1].copy(),
        num_nodes=0,  # no multiplier nodes (the penalty's pairs)
    )
    s = dict(
        state=np.asarray(state, np.int8)[::-1].copy(),
        g_n=(np.full(n, -1e-4 * H) if g_n is None else g_n)[::-1].copy(),
    )
    return g, s


def test_sound_state_is_quiet():
    assert pair_warnings(*pair([0, 0, 2, 2, 2, 2, 0]), H, BAND, "a-b") == []
    # separate contact spots of one pair: one gap, or gaps longer than h (points 1/n apart)
    assert pair_warnings(*pair([0, 2, 2, 0, 0, 2, 2, 0]), H, BAND, "a-b") == []
    assert pair_warnings(*pair([2, 2, 0, 0, 0, 2, 2, 0, 0, 0, 2]), 0.25, BAND, "a-b") == []


def test_checkerboard():
    """Alternating points, or pairs of points (a contact-surface piece's two Gauss points)."""
    (w,) = pair_warnings(*pair([0, 2, 0, 2, 0, 2, 0, 2, 0]), 0.3, BAND, "a-b")
    assert w.startswith("a-b: 3 gaps shorter than h in the contact zone")
    assert len(pair_warnings(*pair([2, 2, 0, 0, 2, 2, 0, 0, 2, 2] * 4), 0.2, BAND, "a-b")) == 1


def test_penetration_and_band():
    g_n = np.full(5, -1.5 * PENETRATION * H)
    g_n0 = np.array([0.0, 0.0, 0.0, 0.0, 0.95 * BAND])
    w = pair_warnings(*pair([2, 2, 2, 2, 2], g_n, g_n0), H, BAND, "a-b")
    assert len(w) == 2 and "penetration" in w[0] and "within 10 % of the band" in w[1]


def test_penetration_cause_names_the_enforcement():
    """The augmented Lagrangian constrains its multiplier nodes' weighted mean gaps, not each
    point's: a point penetrating between closed nodes is the P1 trace's resolution (a corner,
    an edge singularity), not a soft penalty; nodes' gaps open too mean its constraint is not
    met. Two nodes, each the mean of half the points (a stand-in for `PairGeometry.project`)."""
    n = 8
    g, s = pair([2] * n)
    g.law_at_points_with_nodes = True
    g.project = lambda v: (np.array([np.mean(v[: n // 2]), np.mean(v[n // 2 :])]), None)
    s["tau_n"] = np.full(n, -1.0)  # every point pressed: both nodes carry pressure
    s["g_n"] = np.zeros(n)
    s["g_n"][1] = -1.5 * PENETRATION * H  # one point between nodes whose mean gap is small
    (w,) = pair_warnings(g, s, H, BAND, "a-b", augmented=True)
    assert "between the multiplier nodes" in w and "cannot follow" in w and "soft" not in w
    (w,) = pair_warnings(g, s, H, BAND, "a-b")  # the penalty's reading of the same state
    assert "the penalty is too soft" in w
    s["g_n"][:] = -1.5 * PENETRATION * H  # the nodes' mean gaps open as well
    (w,) = pair_warnings(g, s, H, BAND, "a-b", augmented=True)
    assert "constraint is not met" in w


def hertz(out, *args):
    r = subprocess.run(
        # gmsh's mesh, the figures' (the demo's default is now the layers mesher)
        [sys.executable, str(ROOT / "demos" / "hertz.py"), "--h", "0.1", "--mesher", "gmsh", *args]
        + ["--out", str(out)],
        capture_output=True,
        text=True,
        cwd=ROOT,
        # unbuffered: what the child printed survives an exit from compiled code
        env=dict(os.environ, PYTHONUNBUFFERED="1"),
    )
    # everything the child said: twice in CI it exited 1 with both streams empty (design.md 10)
    assert r.returncode == 0, f"exit {r.returncode}\nstdout: {r.stdout[-3000:]}\nstderr: {r.stderr}"
    return json.loads((out / "metrics.json").read_text()), r


def test_demo_reports_stiff_penalty(tmp_path):
    """eps0 = 1e-2 at h = a/10: p(x) 69 % off, an open/closed checkerboard, flagged; the
    augmented enforcement at the same eps0 is not."""
    m, _ = hertz(tmp_path / "stiff", "--eps0", "1e-2")
    assert m["results"]["pressure_rel_l2_error"] > 0.3
    assert any("checkerboard" in w for w in m["solver"]["warnings"])
    m, _ = hertz(tmp_path / "al", "--eps0", "1e-2", "--enforcement", "augmented")
    assert m["solver"]["warnings"] == []


def test_demo_reports_soft_penalty(tmp_path):
    out = tmp_path / "soft"
    m, r = hertz(out, "--eps0", "100")
    warnings = m["solver"]["warnings"]
    assert any("penetration" in w for w in warnings)
    # the contact (a = 2.05, twice Hertz's) reached the band's edge: the band doubled and the
    # step was done again, so the band is no longer a warning (`ContactProblem.grow_band`)
    band = m["solver"]["band"]
    assert band["end"] == 2 * band["start"]
    assert not any("band" in w for w in warnings)
    assert sum(line.startswith("WARNING: ") for line in r.stdout.splitlines()) == len(warnings)


def test_demo_reports_under_resolved_multipliers(tmp_path):
    """Augmented at h = a/2: 4 multiplier nodes carry the Hertz pressure (body-fitted, the
    default hybrid projection's nodes 1.5 h apart; 6 with the lumped one's h), the P1
    multipliers widen the zone (lumped: a +9.2 % against the penalty's +2.7 %): flagged. At
    a/10 (20 nodes) quiet (test_demo_reports_stiff_penalty)."""
    m, r = hertz(tmp_path / "coarse", "--h", "0.5", "--enforcement", "augmented")
    (w,) = [w for w in m["solver"]["warnings"] if "multiplier nodes carry" in w]
    assert "only 4 multiplier nodes" in w
    assert f"WARNING: {w}" in r.stdout


def test_contact_over_every_multiplier_node_is_not_under_resolved(tmp_path):
    """The cut patch test (augmented): all 6 multiplier nodes of the interface carry the
    exact uniform pressure; no contact edge lies on Gamma_c for the hats to smear, so the
    resolution check stays quiet (it warned: "only 6 multiplier nodes ... soften the contact")."""
    out = tmp_path / "patch"
    demo = str(ROOT / "demos" / "patch_test.py")
    args = ["--discretization", "cut", "--interface", "0.5126", "--enforcement", "augmented"]
    r = subprocess.run(
        [sys.executable, demo, *args, "--out", str(out)], capture_output=True, text=True, cwd=ROOT
    )
    assert r.returncode == 0, r.stderr
    m = json.loads((out / "metrics.json").read_text())
    assert m["results"]["pressure_rel_error_vs_exact"] <= 1e-8
    assert m["solver"]["warnings"] == []


def free_block_scene():
    """demos/scenes/two_blocks.toml without the upper block's Dirichlet conditions (as text),
    the upper block lifted 1 mm (5 h, five bands) off the lower one: no contact point can
    close whatever solution of the singular system the linear solver returns (on one machine
    MUMPS returned a block that touched at one sliding point), so the expected warning does
    not depend on the solver, the BLAS kernel or round-off."""
    text = (ROOT / "demos" / "scenes" / "two_blocks.toml").read_text()
    a, b = text.index('[[dirichlet]]\nname = "top_x"'), text.index("[[tractions]]")
    text = text[:a] + text[b:]
    text = text.replace('[outputs]\nreaction = "upper_top"\n', "[outputs]\n")
    lifted = "min = [10.0, 11.0], max = [30.0, 20.0]"
    text = text.replace("min = [10.0, 10.0], max = [30.0, 20.0]", lifted)
    assert lifted in text
    return text[: text.index("[[checks]]")]


@pytest.mark.mpi
def test_a_body_held_by_nothing_is_reported_on_two_ranks(tmp_path):
    """The free upper block of test_a_body_held_by_nothing_is_reported on 2 ranks: the same
    warning on every rank (the rigid motions' product J R is assembled across the ranks)."""
    import tomllib

    from mpi4py import MPI

    from dolfinx_forms import run

    assert MPI.COMM_WORLD.size == 2, "run under mpirun -n 2"
    r = run(tomllib.loads(free_block_scene()), write=False, log=lambda *a: None)
    (w,) = r.metrics["solver"]["warnings"]
    assert w.startswith("upper: held by nothing in x, y, rotation")


def test_a_body_held_by_nothing_is_reported(tmp_path):
    """demos/scenes/two_blocks.toml without the upper block's Dirichlet conditions, the upper
    block lifted off the lower one (free_block_scene): the upper block is free. Newton still
    "converges" (MUMPS returns one of the singular system's solutions); the check says that
    its position means nothing, in metrics.json and on the console."""
    scene = tmp_path / "free.toml"
    scene.write_text(free_block_scene())
    out = tmp_path / "free"
    r = subprocess.run(
        [sys.executable, "-m", "dolfinx_forms", "run", str(scene), "--out", str(out)],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert r.returncode == 0, r.stderr
    (w,) = json.loads((out / "metrics.json").read_text())["solver"]["warnings"]
    assert w.startswith("upper: held by nothing in x, y, rotation")
    assert f"WARNING: {w}" in r.stdout


def _rigid_factors(points, k_t, centre):
    """Factors A, B (|A c| = |J R c|, |B c| = |R c|) of a body held by contact springs at
    `points` on a face of normal y: normal stiffness 1 and tangential k_t (0: the point
    slides) on each, J the springs' stiffness on the point displacements. R also samples two
    points off the face (rigid motions are measured on the whole body)."""
    from dolfinx_forms.solvers.checks import stacked_rfactors

    def u(x):  # the displacement at x of c = (a, b, w), rotation about centre
        d = np.asarray(x, float) - centre
        return np.array([[1.0, 0.0, -d[1]], [0.0, 1.0, d[0]]])

    JR = [row for x in points for row in (u(x)[1], k_t * u(x)[0])] or [np.zeros(3)]
    R = np.vstack([u(x) for x in list(points) + [(5.0, 5.0), (-5.0, 5.0)]])
    A = stacked_rfactors(np.array(JR), np.zeros(len(JR), int), 1)[0]
    return A, stacked_rfactors(R, np.zeros(len(R), int), 1)[0]


@pytest.mark.parametrize(
    "points, k_t, expected",
    [
        # nothing closed: every rigid motion is free
        ([], 0.0, r"x, y, rotation"),
        # one sliding point at (3, -1) on a face with normal y: free in x and in a rotation
        # about a point of the line x = 3 (the centres that differ by an x translation),
        # whatever solution the solver returned
        ([(3.0, -1.0)], 0.0, r"x, the rotation about \(3, [-0-9.e]+\)"),
        # one sticking point: the rotation about it only
        ([(3.0, -1.0)], 1.0, r"the rotation about \(3, -1\)"),
        # two sliding points on the face: x only
        ([(3.0, -1.0), (-2.0, -1.0)], 0.0, r"x"),
        # two sticking points: held
        ([(3.0, -1.0), (-2.0, -1.0)], 1.0, r""),
    ],
)
def test_free_rigid_modes_is_a_rank_test(points, k_t, expected):
    """The held-by-nothing check decides from the rank of the rigid-mode block, not from each
    mode alone: a body on one sliding point is reported (the per-mode test saw it held in y
    and in the rotation about its centre). The free modes are named the same whichever basis
    of the null space the SVD returns (the points' order, the body's centre)."""
    import re

    from dolfinx_forms.solvers.checks import free_rigid_modes

    for centre in (np.zeros(2), np.array([0.7, 2.0])):
        for pts in (points, points[::-1]):
            A, B = _rigid_factors(pts, k_t, centre)
            assert re.fullmatch(expected, ", ".join(free_rigid_modes(A, B, 1.0, centre)))
