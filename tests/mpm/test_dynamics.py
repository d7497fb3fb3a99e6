"""Step-size control of the Newmark rule on the material-point path (mpm/dynamics.py
PointNewmark.advance): a failed step is undone exactly (points with v and a, level sets,
friction and multiplier records, time) and done again at half the step; the step grows back."""

import numpy as np
from mpi4py import MPI

from dolfinx_forms.fem.laws import NeoHookean
from dolfinx_forms.mpm.dynamics import PointNewmark
from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
from dolfinx_forms.solvers.newton import NewtonOptions
from meshes.mpm import cylinder_on_floor


def cylinder(dt, damp_cycles=False):
    """A coarse neo-Hookean cylinder released on a floor under gravity turned by 30 degrees,
    the dissipative rule: its first step fails at dt = 0.1 (the contact's active set cycles)
    unless Newton damps the cycle (NewtonOptions.damp_cycles, the default elsewhere)."""
    grid, (name, tag, shape), floor, build = cylinder_on_floor(MPI.COMM_SELF, 1.0, 0.2, 2.0)
    dyn = PointNewmark({tag: 1.0}, dt, "dissipative", gravity=(0.5, -np.sqrt(0.75)))
    sim = ImplicitMPM(MPI.COMM_SELF, grid, [MPMBody(name, tag, NeoHookean(1e4, 0.3), shape)],
                      build, obstacles=[floor], dynamics=dyn, mu=0.5,
                      newton=NewtonOptions(damp_cycles=damp_cycles),
                      log=lambda *a, **k: None)  # fmt: skip
    return sim, dyn


def test_a_failed_step_is_undone_and_done_again_at_half_the_step():
    sim, dyn = cylinder(0.1)
    lines = []
    recs = list(dyn.advance(sim, 0.3, log=lines.append))
    assert len(lines) == 1 and "halved to 0.05" in lines[0]  # the first step failed once
    assert np.allclose([r["dt"] for r in recs], [0.05, 0.05, 0.05, 0.05, 0.1], rtol=1e-12)
    assert abs(recs[-1]["time"] - 0.3) < 1e-12
    # the retried first step is the first step of a run at dt = 0.05 from the start, exactly:
    # nothing of the failed attempt survived
    ref, _ = cylinder(0.05)
    first = ref.step()
    again, _ = cylinder(0.1)
    a_dyn = again.dynamics
    step = next(a_dyn.advance(again, 0.05, log=lambda *a: None))
    assert step["dt"] == 0.05 and first["time"] == step["time"]
    same = lambda a, b: np.allclose(a, b, rtol=1e-12, atol=1e-14)  # noqa: E731 (same ops)
    for name in ("x", "v", "a", "F"):
        assert same(getattr(ref.points[1], name), getattr(again.points[1], name)), name
    assert same(ref.levelsets[1].values, again.levelsets[1].values)
    assert same(first["obstacles"]["floor"]["fy"], step["obstacles"]["floor"]["fy"])


def test_a_damped_cycle_converges_where_the_plain_step_failed():
    """NewtonOptions.damp_cycles: the same first step at dt = 0.1 whose active set cycled (the
    test above) converges, halving the Newton step that jumped back to a seen active set, to
    the residual tolerance; no step is retried."""
    sim, dyn = cylinder(0.1, damp_cycles=True)
    lines = []
    recs = list(dyn.advance(sim, 0.2, log=lines.append))
    assert not lines and [r["dt"] for r in recs] == [0.1, 0.1]
    assert all(r["residuals"][-1] <= 1e-10 * r["residuals"][0] for r in recs)


def test_drag_follows_the_newmark_recursion_of_a_falling_body():
    """Rayleigh's mass damping alpha (PointNewmark(mass_damping=...)) on a disc in free fall:
    its points move rigidly with v' = -g - alpha v, whose trapezoidal rule is the recursion
    v_{n+1} (1 + alpha dt / 2) = v_n (1 - alpha dt / 2) - g dt (a_0 = -g); the points' v equal
    it to round-off (1e-9), the dissipative rule (gamma 0.6) too with its own recursion, and the
    terminal velocity g / alpha is approached."""
    import dolfinx_forms as df
    from meshes.mpm import grid_scene, uniform_lines

    xl, yl = uniform_lines(-1.5, 1.5, 0.1), uniform_lines(-4.5, 1.5, 0.1)
    g, alpha, dt = 1.0, 2.0, 0.1
    for integrator in ("trapezoidal", "dissipative"):
        dyn = PointNewmark({1: 1.0}, dt, integrator, gravity=(0.0, -g), mass_damping=alpha)
        body = MPMBody("d", 1, NeoHookean(1e3, 0.3), df.Circle((0.0, 0.0), 1.0))
        sim = ImplicitMPM(MPI.COMM_SELF, (xl, yl), [body],
                          grid_scene(MPI.COMM_SELF, xl, yl, [("d", 1)]), dynamics=dyn,
                          log=lambda *a, **k: None)  # fmt: skip
        v, a, gm = 0.0, -g, dyn.gamma
        for _ in range(20):
            sim.step()
            # v_{n+1} = v + dt ((1 - gm) a + gm a1), a1 = -g - alpha v_{n+1}
            v_new = (v + dt * (1 - gm) * a - gm * dt * g) / (1 + gm * dt * alpha)
            v, a = v_new, -g - alpha * v_new
            assert np.allclose(sim.points[1].v[:, 1], v, rtol=1e-9, atol=1e-12)
            assert np.allclose(sim.points[1].v[:, 0], 0.0, atol=1e-12)
        assert abs(v + g / alpha) < 0.03 * g / alpha  # t = 2: 1 - exp(-4) of the terminal
