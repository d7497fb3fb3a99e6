"""Multi-step scenes from a description (`method = "mpm"`, app/mpm_spec.py, app/mpm_runner.py).

The four MPM demos' scene files (demos/scenes/) give the demos' own contact and body records
at coarse settings: the same level sets, points, obstacles and conditions built from the
description instead of the demo's code (byte for byte where the geometry is the same; the grain
assembly's rigid plates get other bounding boxes, which move the pair grids by round-off). A
force target is reached within its tolerance; bad descriptions are one line, exit 2, nothing
written. The tutorial's multi-step scene on 1 and 2 ranks: tests/app/test_tutorial.py."""

import csv
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from dolfinx_forms.app.description import load
from dolfinx_forms.common import SpecError

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "demos" / "scenes"
ENV = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1")


def run(args, cwd, timeout=600):
    return subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True,
                          env=ENV, cwd=cwd, timeout=timeout)  # fmt: skip


def table(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def assert_same_records(a, b, rtol):
    """contacts.csv / bodies.csv of two runs: the same rows; numbers equal to rtol of their
    column's largest magnitude, a body's resultant (zero: equilibrium) to rtol of the largest
    contact force."""
    force = max(abs(float(r["normal_force"])) for r in table(a / "contacts.csv"))
    for name in ("contacts.csv", "bodies.csv"):
        ra, rb = table(a / name), table(b / name)
        assert len(ra) == len(rb) > 0, name
        for key in ra[0]:
            try:
                x = np.array([float(r[key]) for r in ra])
            except ValueError:
                assert [r[key] for r in ra] == [r[key] for r in rb], (name, key)
                continue
            y = np.array([float(r[key]) for r in rb])
            scale = max(np.abs(x).max(), force if key in ("fx", "fy", "moment") else 1e-300)
            assert np.all(np.abs(x - y) <= rtol * scale), (name, key, np.abs(x - y).max() / scale)


# the demo's command line, the scene's overrides giving the same run, the tolerance
CASES = {
    "brazilian_disc": (["--steps", "3", "--h", "0.5"],
                       ["stages[0].steps=3", "grid.h=0.5", "checks=[]"], 0.0),
    "nine_discs": ([], [], 0.0),
    "four_grains": ([], [], 0.0),
    "grain_assembly": (["--steps", "2", "--shear-steps", "1"],
                       ["stages[0].steps=2", "stages[1].steps=1"], 1e-9),
}  # fmt: skip


@pytest.mark.parametrize("name", list(CASES))
def test_scene_file_gives_the_demo(tmp_path, name):
    demo_args, overrides, rtol = CASES[name]
    r = run([ROOT / "demos" / f"{name}.py", *demo_args, "--out", tmp_path / "demo"], tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    sets = [a for o in overrides for a in ("--set", o)]
    scene = SCENES / f"{name}.toml"
    r = run(["-m", "dolfinx_forms", "run", scene, *sets, "--out", tmp_path / "scene"], tmp_path)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert_same_records(tmp_path / "demo", tmp_path / "scene", rtol)
    files = {p.name for p in (tmp_path / "scene").iterdir()}
    assert {"steps.csv", "contacts.csv", "bodies.csv", "metrics.json", "levelsets.xdmf",
            "force_chains.png"} <= files  # fmt: skip


def test_force_target_is_reached(tmp_path):
    """The upper platen of the Brazilian disc driven to a force of 400 in two steps: each
    step's force within the target's tolerance of its share (200, then 400)."""
    sets = ["stages[0].steps=2", "grid.h=0.5", "stages[0].target={obstacle='platen_top', "
            "component='y', force=400.0, tol=1e-4}", "checks=[]"]  # fmt: skip
    args = [a for s in sets for a in ("--set", s)]
    out = tmp_path / "out"
    r = run(["-m", "dolfinx_forms", "run", SCENES / "brazilian_disc.toml", *args, "--out", out],
            tmp_path)  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    fy = [float(row["platen_top_fy"]) for row in table(out / "steps.csv")]
    assert fy == pytest.approx([200.0, 400.0], abs=1e-4 * 400.0)
    # per step: its Newton residuals and its sparse factorisations (the accepted solve's)
    solver = json.loads((out / "metrics.json").read_text())["solver"]
    assert len(solver["residual_history"]) == len(solver["factorisations"]) == 2
    assert all(f >= 1 for f in solver["factorisations"])


BASE = {
    "method": "mpm",
    "grid": {"extent": [[-2.0, -2.0], [2.0, 2.0]], "h": 0.1},
    "bodies": [{"name": "disc", "shape": {"type": "circle", "centre": [0.0, 0.0], "radius": 1.0},
                "law": {"type": "linear", "E": 100.0, "nu": 0.3}}],
    "obstacles": [{"name": "floor", "shape": {"type": "half_plane", "point": [0.0, -0.99],
                   "normal": [0.0, 1.0]}}],
    "stages": [{"steps": 2, "move": {"floor": {"translation": [0.0, 0.01]}}}],
}  # fmt: skip

BAD = [  # (override, the key the message names, a word of the message)
    ("bodies[0].shape={type='half_plane', point=[0.0, 0.0], normal=[0.0, 1.0]}",
     "bodies[0].shape.type", "bounded"),
    ("solver.enforcement='lagrange'", "solver.enforcement", "penalty"),
    ("solver={enforcement='augmented', eps0=1e5}", "solver.eps0", "1e4"),
    ("obstacles[0].shape.point=[0.0, -0.5]", "obstacles[0]", "deeper than h/2"),
    ("bodies[0].shape.centre=[1.5, 0.0]", "bodies[0]", "not inside the grid"),
    ("grid.h=0.6", "grid.h", "quarter"),
    ("grid.h=1e-4", "grid.h", "grid cells"),
    ("stages[0].move.floor.translation=[0.0, 0.2]", "stages[0].move.floor.translation", "h/2"),
    ("stages[0].move.wall={translation=[0.0, 0.01]}", "stages[0].move.wall", "unknown obstacle"),
    ("stages[0].target={obstacle='floor', component='x', force=1.0}", "stages[0].move",
     "nonzero translation"),
    ("stages[0].steps=0", "stages[0].steps", ">= 1"),
    ("stages=[]", "stages", "missing"),
    ("dirichlet=[{box={x_min=5.0}, component='x'}]", "dirichlet[0].box", "no node"),
    ("obstacles[0].name='disc'", "obstacles[0].name", "duplicate"),
    ("obstacles[0].bodies=['nobody']", "obstacles[0].bodies", "body names"),
    ("analytic={type='hertz', body='disc', obstacle='floor', R=1.0}", "analytic.R", "unknown"),
    ("solver.petsc={ksp_type='bogus'}", "solver.petsc", "bogus"),
    ("outputs.series_every=0", "outputs.series_every", ">= 1"),
    ("method='multi'", "method", "mpm"),
    ("bodies[0].name=''", "bodies[0].name", "empty"),
    ("obstacles[0].name=' '", "obstacles[0].name", "empty"),
    ("checks=[{quantity='results.nothing', below=1.0}]", "checks[0].quantity", "writes"),
    ("checks=[{quantity='results.obstacle_forces.wall[1]', below=1.0}]", "checks[0].quantity",
     "floor"),
    ("checks=[{quantity='results.half_width_rel_error_max', below=1.0}]", "checks[0].quantity",
     "writes"),
    ("dynamics={dt=0.0}", "dynamics.dt", "> 0"),
    ("dynamics={dt=0.1, integrator='euler'}", "dynamics.integrator", "dissipative"),
    ("dynamics={dt=0.1, gravity=[0.0, -1.0, 0.0]}", "dynamics.gravity", "[gx, gy]"),
    ("dynamics={dt=0.1, damping=1.0}", "dynamics.damping", "unknown"),
    ("bodies[0].rho=-1.0", "bodies[0].rho", "> 0"),
    ("solver.levelset_update='weno'", "solver.levelset_update", "reference-map"),
    ("solver.extrapolate=1", "solver.extrapolate", "true"),
]  # fmt: skip


@pytest.mark.parametrize("override,key,word", BAD)
def test_bad_description_names_the_key(override, key, word):
    with pytest.raises(SpecError) as e:
        load(BASE, [override])
    assert e.value.key == key, str(e.value)
    assert word in str(e.value)


def test_base_description_is_valid():
    spec = load(BASE)
    assert spec["solver"]["band"] is None and spec["stages"][0]["move"]["floor"]["rotation"] == 0
    # extrapolate absent: ImplicitMPM chooses (on, but for laws with a history)
    assert (
        spec["solver"]["levelset_update"] == "advection" and spec["solver"]["extrapolate"] is None
    )
    assert load(BASE, ["solver.extrapolate=false"])["solver"]["extrapolate"] is False
    assert load(BASE, ["solver.extrapolate=true"])["solver"]["extrapolate"] is True
    assert load(BASE, ["solver.levelset_update='reference-map'"])["solver"]["levelset_update"] == (
        "reference-map"
    )


def test_bad_description_on_the_command_line(tmp_path):
    """One line naming the key, exit 2, nothing written."""
    out = tmp_path / "out"
    bad = "stages[0].move.platen_top.translation=[0.0, -5.0]"
    r = run(["-m", "dolfinx_forms", "run", SCENES / "brazilian_disc.toml", "--set", bad,
             "--out", out], tmp_path)  # fmt: skip
    assert r.returncode == 2
    assert "stages[0].move.platen_top.translation" in r.stderr
    assert len(r.stderr.strip().splitlines()) <= 2  # usage line + the message
    assert "Traceback" not in r.stderr and not out.exists()


def test_plot_labels_from_the_scene_units():
    """The traction plot's axes name the scene's [units], and nothing when it gives none."""
    from dolfinx_forms.app.runner import labels

    spec = load(SCENES / "hertz.toml")
    assert labels(spec) == {"xlabel": "x (mm)", "ylabel": "traction (N/mm^2)"}
    spec = load(SCENES / "patch.toml")
    assert labels(spec) == {"xlabel": "x", "ylabel": "traction"}


def test_finite_strain_laws_and_the_augmented_lagrangian_from_a_file(tmp_path):
    """A description's finite-strain laws (neo-hookean, j2) and solver.enforcement =
    "augmented" reach the simulation: the nine-discs scene with its first disc's law replaced
    runs with each; j2 is refused on the single-step path."""
    for law, enforcement in (
        ("{type='j2', E=1.0e5, nu=0.3, yield_stress=200.0}", "penalty"),
        ("{type='neo-hookean', E=1.0e5, nu=0.3}", "augmented"),
    ):
        sets = [
            "checks=[]",
            f"bodies[0].law={law}",
            f"solver.enforcement='{enforcement}'",
            "solver.eps0=0.01",
        ]
        out = tmp_path / enforcement
        r = run(["-m", "dolfinx_forms", "run", SCENES / "nine_discs.toml",
                 *[a for s in sets for a in ("--set", s)], "--out", out], tmp_path)  # fmt: skip
        assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
        assert len(table(out / "steps.csv")) == 1
        m = json.loads((out / "metrics.json").read_text())
        assert m["solver"]["enforcement"] == enforcement, m["solver"].get("enforcement")
    with pytest.raises(SpecError) as e:
        load(SCENES / "hertz.toml", ["bodies[0].law={type='j2', E=1.0, nu=0.3, yield_stress=1.0}"])
    assert e.value.key == "bodies[0].law.type" and "mpm" in str(e.value)


def test_drucker_prager_from_a_description():
    """A drucker-prager law in a multi-step description becomes fem.plasticity.DruckerPrager
    (the dilatancy angle defaults to the friction angle: associative); a bad angle is refused
    naming the law, and the single-step path refuses the law."""
    from dolfinx_forms.app.spec_values import make_law
    from dolfinx_forms.fem.plasticity import DruckerPrager

    dp = "{type='drucker-prager', E=100.0, nu=0.3, cohesion=1.0, friction_angle=30.0"
    law = make_law(load(BASE, [f"bodies[0].law={dp}}}"])["bodies"][0]["law"])
    assert isinstance(law, DruckerPrager) and law.eta == law.eta_bar > 0
    law = make_law(load(BASE, [f"bodies[0].law={dp}, dilatancy_angle=10.0}}"])["bodies"][0]["law"])
    assert 0 < law.eta_bar < law.eta
    for bad in (f"{dp}, dilatancy_angle=40.0}}", dp.replace("30.0", "0.0") + "}"):
        with pytest.raises(SpecError) as e:
            load(BASE, [f"bodies[0].law={bad}"])
        assert e.value.key == "bodies[0].law" and "friction_angle" in str(e.value)
    with pytest.raises(SpecError) as e:
        load(SCENES / "hertz.toml", [f"bodies[0].law={dp}}}"])
    assert e.value.key == "bodies[0].law.type" and "mpm" in str(e.value)


def test_dynamics_from_a_file_gives_the_bouncing_disc(tmp_path):
    """demos/scenes/bouncing_disc.toml ([dynamics]: inertia, gravity, Kelvin-Voigt damping) is
    demos/bouncing_disc.py moved up by h / 2: over the first 0.6 s (the impact at 0.45 s) the
    floor's force and the kinetic energy per step equal the demo's to 1e-8 of their largest
    values (the translation changes the round-off only); steps.csv has time and kinetic
    energy."""
    demo = ["--t-end", "0.6", "--series-every", "100", "--out", tmp_path / "demo"]
    r = run([ROOT / "demos" / "bouncing_disc.py", *demo], tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    sets = ["--set", "stages[0].steps=60", "--set", "checks=[]", "--set", "outputs.plots=false"]
    scene = SCENES / "bouncing_disc.toml"
    r = run(["-m", "dolfinx_forms", "run", scene, *sets, "--out", tmp_path / "scene"], tmp_path)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    a, b = table(tmp_path / "demo" / "steps.csv"), table(tmp_path / "scene" / "steps.csv")
    assert len(a) == len(b) == 60
    assert np.allclose([float(q["time"]) for q in b], [float(q["t"]) for q in a], atol=1e-12)
    for x, y in (("contact_force", "floor_fy"), ("kinetic_energy", "kinetic_energy")):
        u = np.array([float(q[x]) for q in a])
        v = np.array([float(q[y]) for q in b]) * (-1 if x == "contact_force" else 1)
        assert np.abs(u).max() > 0 and np.all(np.abs(u - v) <= 1e-8 * np.abs(u).max()), x
    m = json.load(open(tmp_path / "scene" / "metrics.json"))["results"]
    assert m["time_final"] == pytest.approx(0.6) and m["equilibrium_rel_max"] is None


def test_extrapolate_from_a_file(tmp_path):
    """`solver.extrapolate` reaches ImplicitMPM: the Brazilian disc's steps start from the last
    increment by default (metrics.json `predicted` per step), from du = 0 with false, and the
    records agree to Newton's tolerance."""
    sets = ["stages[0].steps=3", "grid.h=0.5", "checks=[]"]
    outs = {}
    for extrapolate in ("true", "false"):
        args = [a for s in [*sets, f"solver.extrapolate={extrapolate}"] for a in ("--set", s)]
        outs[extrapolate] = out = tmp_path / extrapolate
        r = run(["-m", "dolfinx_forms", "run", SCENES / "brazilian_disc.toml", *args,
                 "--out", out], tmp_path)  # fmt: skip
        assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    on, off = (json.loads((outs[k] / "metrics.json").read_text())["solver"] for k in outs)
    assert off["predicted"] == [0, 0, 0] and on["predicted"][0] == 0 and sum(on["predicted"]) >= 1
    assert sum(on["newton_iterations"]) < sum(off["newton_iterations"])
    assert_same_records(outs["false"], outs["true"], 1e-8)
