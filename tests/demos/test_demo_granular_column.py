"""demos/granular_column.py (inertia, contact and friction of a random sample in four moving
walls, MELODY's protocol of meshes/column.py) on coarse settings: one disc deposited comes to
rest carrying its weight and the walls follow the protocol; 20 grains in free fall follow the
Newmark recursion of the drag exactly until they touch; 2 ranks equal 1; the bad-input
contract. A deposit of many grains is chaotic (its trajectory depends on round-off), so the
tests check what holds for any trajectory."""

import csv
import json

import numpy as np
import pytest
from demo_tests import assert_refused, load_demo
from mpi4py import MPI

from meshes import column

demo = load_demo("granular_column")


def rows_of(out):
    rows = list(csv.DictReader(open(out / "steps.csv")))
    assert list(rows[0]) == demo.COLUMNS
    return rows


def protocol_of(args):
    sample = column.random_sample(args.grains, args.radius, args.polydispersity,
                                  args.elongation, args.roughness, seed=args.seed)  # fmt: skip
    return column.Protocol(sample.box, args.t_deposit, args.t_compress, args.t_shear,
                           args.compression, args.shear_strain)  # fmt: skip


def test_one_disc_comes_to_rest_and_the_walls_follow_the_protocol(tmp_path):
    """One disc, R / h ~ 4, dt = 0.1 (drag 2, damping 10): after a deposition of 10 time units
    the walls carry the weight within 3e-3 (measured 1.0000 with either level-set update when
    written; 0.9989, and 1.0021 since the points in slivers take the field inward) at
    kinetic energy below 1e-6 (1.1e-7 and 1.6e-7). (At t = 6 the contact still rang by +-5 %,
    so a tolerance of 1 % there held or not by the phase of the ringing.) Every row's
    walls are Protocol.walls at its time with the measured settled height (1e-12); the area
    constant through the shear (1e-12); the top wall pressing at the end of compression."""
    argv = ["--grains", "1", "--h", "0.25", "--drag", "2", "--damping", "10", "--t-deposit",
            "10", "--t-compress", "1", "--t-shear", "1"]  # fmt: skip
    out = tmp_path / "one"
    assert demo.main([*argv, "--out", str(out)]) == 0
    m = json.load(open(out / "metrics.json"))
    r = m["results"]
    assert abs(r["walls_over_weight_deposited"] - 1) < 3e-3
    assert r["kinetic_energy_deposited"] < 1e-6 and not m["solver"]["warnings"]
    protocol, rows = protocol_of(demo.parse(argv)), rows_of(out)
    assert [q["phase"] for q in rows] == sorted((q["phase"] for q in rows), key=column.PHASES.index)
    for q in rows:
        want = protocol.walls(float(q["t"]), r["settled_height"])
        assert all(abs(float(q[k]) - want[k]) < 1e-12 for k in ("left", "right", "top"))
    shear = [q for q in rows if q["phase"] == "shear"]
    area = [(float(q["right"]) - float(q["left"])) * float(q["top"]) for q in shear]
    assert np.ptp(area) < 1e-12 * area[0] and float(shear[-1]["shear_strain"]) == pytest.approx(0.1)
    assert r["end_of_compression"]["force_top"] > 0


def test_twenty_grains_fall_by_the_drag_recursion_until_they_touch(tmp_path):
    """20 grains, 5 steps of dt = 0.1 (the lowest grains reach the floor only at t ~ 0.45):
    no contact, and the kinetic energy is that of the whole mass at the velocity of the
    trapezoidal-dissipative recursion of v' = -g - alpha v (1e-8)."""
    argv = ["--grains", "20", "--h", "0.25", "--t-deposit", "0.4", "--t-compress", "0.05",
            "--t-shear", "0.05", "--series-every", "100"]  # fmt: skip
    out = tmp_path / "twenty"
    assert demo.main([*argv, "--out", str(out)]) == 0
    rows = rows_of(out)
    weight = json.load(open(out / "metrics.json"))["results"]["weight"]  # mass, g = rho = 1
    gamma, dt, alpha, v, a = 0.6, 0.1, 1.0, 0.0, -1.0
    for q in rows[:4]:
        v_new = (v + dt * (1 - gamma) * a - gamma * dt) / (1 + gamma * dt * alpha)
        v, a = v_new, -1.0 - alpha * v_new
        assert float(q["contacts"]) == 0 and float(q["force_bottom"]) == 0
        assert float(q["kinetic_energy"]) == pytest.approx(0.5 * weight * v**2, rel=1e-8)


def falling_grains(comm, steps=6):
    """Four grains of the column dropped on the floor: bottom wall force and kinetic energy."""
    from dolfinx_forms.mpm.dynamics import PointNewmark
    from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
    from dolfinx_forms.solvers.newton import NewtonOptions
    from meshes.assembly import column_scene

    sample = column.random_sample(4, seed=3)
    grid, grains, plates, build = column_scene(comm, sample, 0.25)
    dyn = PointNewmark({t: 1.0 for _, t, _ in grains}, 0.1, "dissipative", gravity=(0.0, -1.0),
                       viscosity=100.0, mass_damping=1.0)  # fmt: skip
    sim = ImplicitMPM(comm, grid, [MPMBody(n, t, (1e4, 0.3), s) for n, t, s in grains], build,
                      obstacles=list(plates.values()), mu=0.3, dynamics=dyn,
                      newton=NewtonOptions(rtol=1e-13), log=lambda *a, **k: None)  # fmt: skip
    recs = [sim.step() for _ in range(steps)]
    return [(r["obstacles"]["plate_bottom"]["fy"], sum(r["kinetic_energy"].values()))
            for r in recs]  # fmt: skip


@pytest.mark.mpi
def test_two_ranks_match_one():
    """Four grains landing on the floor: the floor's force and the kinetic energy per step on
    2 ranks equal rank 0's run alone, to 1e-8."""
    assert MPI.COMM_WORLD.size == 2, "run under mpirun -n 2"
    two, one = falling_grains(MPI.COMM_WORLD), falling_grains(MPI.COMM_SELF)
    assert any(f != 0 for f, _ in one)
    assert np.allclose(two, one, rtol=1e-8, atol=1e-10)


@pytest.mark.parametrize(
    "args, word",
    [
        (["--grains", "0"], "--grains"),
        (["--h", "1"], "--h"),
        (["--dt", "100"], "--dt"),
        (["--law", "j2"], "--law"),
        (["--polydispersity", "0.9"], "--polydispersity"),
        (["--compression", "-0.1"], "--compression"),
    ],
)
def test_bad_input_exits_2_naming_the_parameter(args, word, tmp_path, capsys):
    assert_refused(demo, args, word, tmp_path, capsys)
