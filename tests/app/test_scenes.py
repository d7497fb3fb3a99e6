"""Scene descriptions (demos/scenes/*.toml) run by `python3 -m dolfinx_forms run`.

End to end (one subprocess per case): the Hertz scene at h = a/10 (coarse; a/20 is the
default) against Hertz at the computed load (a within 2 %, p0 within 4 %: the element-scale
penalty ripple of the point values at this h), the cut patch test to round-off against the
penalised exact pressure E' d / (H + E' eps_n), a failed check (exit 1, reason, results
written), bad descriptions (exit 2, one line naming the key, nothing written). The description
checks are in-process (scene_spec is pure Python), so is the fitted (gmsh) path of the builder.
"""

import json
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from dolfinx_forms.analysis import analytic
from dolfinx_forms.app.scene_spec import SpecError, load

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "demos" / "scenes"


def run(*args, cwd=ROOT):
    return subprocess.run(
        [sys.executable, "-m", "dolfinx_forms", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"},
    )


def metrics(out):
    return json.loads((Path(out) / "metrics.json").read_text())


def test_hertz_scene(tmp_path):
    out = tmp_path / "hertz"
    r = run(
        "run",
        SCENES / "hertz.toml",
        "--out",
        out,
        "--set",
        "discretization.h=0.1",
        "--set",
        "checks[1].rtol=0.04",
        "--set",
        "checks[2].below=0.05",
    )
    assert r.returncode == 0, r.stderr
    m = metrics(out)
    assert m["benchmark"] == "hertz" and m["discretization"] == "cut"
    assert m["mesh"]["h_contact"] == 0.1 and m["solver"]["converged"]
    res = m["results"]
    P = res["reaction"][1]
    assert P == pytest.approx(430.0, rel=1e-3)
    a, p0 = analytic.hertz_line(P, 10.0, analytic.effective_modulus(1e4, 0.3, 1e4, 0.3))
    assert res["contact_half_width"] == pytest.approx(a, rel=0.02)
    assert res["peak_pressure"] == pytest.approx(p0, rel=0.04)
    assert m["analytic"]["contact_half_width"] == pytest.approx(a, rel=1e-12)
    assert m["checks_passed"] and len(m["checks"]) == 5
    assert [s["kind"] for s in m["stages"]] == ["force"]
    assert m["stages"][0]["values"]["top_y"] < 0
    for f in ("tractions.csv", "tractions.png", "solution.xdmf", "solution.h5"):
        assert (out / f).exists(), f
    assert "normal: reaction y on block_bottom" in r.stdout


def test_patch_scene(tmp_path):
    out = tmp_path / "patch"
    r = run("run", SCENES / "patch.toml", "--out", out)
    assert r.returncode == 0, r.stderr
    m = metrics(out)
    E, nu, d, h = 1.0, 0.3, 0.01, 0.125
    Ep = E / (1 - nu**2)
    eps_n = 1.0 * h / E  # eq 51, eps0 = 1
    assert m["solver"]["penalty"]["eps_n"] == pytest.approx(eps_n)
    penalised = Ep * d / (1.0 + Ep * eps_n)
    t = np.genfromtxt(out / "tractions.csv", delimiter=",", names=True, dtype=None, encoding=None)
    assert set(t["state"]) == {"active"}  # all active, frictionless: neither stick nor slip
    assert np.max(np.abs(t["p_n"] - penalised)) <= 1e-8 * penalised
    assert np.max(np.abs(t["p_t"])) <= 1e-12
    assert m["results"]["reaction"][1] == pytest.approx(penalised, rel=1e-8)
    assert m["analytic"]["pressure"] == pytest.approx(0.010989011, rel=1e-8)
    assert m["checks_passed"]


@pytest.mark.parametrize("mass", ["lumped", "consistent", "hybrid"])
def test_patch_scene_augmented(tmp_path, mass):
    """[solver] enforcement = "augmented": the exact pressure E' d / H, not the penalised one
    (the patch reference then has eps_n = 0, so the scene's own checks hold as written)."""
    out = tmp_path / mass
    sets = ['solver.enforcement="augmented"', f'solver.multiplier_mass="{mass}"']
    r = run("run", SCENES / "patch.toml", "--out", out, *[a for x in sets for a in ("--set", x)])
    assert r.returncode == 0, r.stderr
    m = metrics(out)
    assert m["parameters"]["solver"]["enforcement"] == "augmented"
    assert m["parameters"]["solver"]["multiplier_mass"] == mass
    t = np.genfromtxt(out / "tractions.csv", delimiter=",", names=True, dtype=None, encoding=None)
    exact = 0.01 / (1 - 0.3**2)
    assert np.max(np.abs(t["p_n"] - exact)) <= 1e-8 * exact
    assert m["results"]["reaction"][1] == pytest.approx(exact, rel=1e-8)
    assert m["checks_passed"]


@pytest.mark.parametrize("h", [0.01, 0.005])
def test_soft_disc_between_stiff_blocks_augmented(tmp_path, h):
    """A neo-Hookean disc (E = 200) squeezed between linear blocks (E = 1e5), augmented.
    The point-wise regularisation is scaled by the softest pair's harmonic-mean modulus
    (`contact.penalty.contact_modulus`, 399 here): scaled by the mean of all moduli (66733) it was
    167 times stiffer, a checkerboard at h = 0.01 (7 short gaps per contact, a failed check of the
    scene, exit 1). At the scene's h = 0.005 its full Uzawa steps cycled (changes of 0.4-6 of
    the largest traction for 300 updates, 32 cut-backs, 132 s) until the loop learned to halve
    its step when the change stops falling (`NewtonOptions.al_stall`): 0 cut-backs, ~15 s."""
    out = tmp_path / "disc"
    sets = ['solver.enforcement="augmented"', f"discretization.h={h}"]
    r = run(
        "run", SCENES / "disc_squeeze.toml", "--out", out, *[a for x in sets for a in ("--set", x)]
    )
    assert r.returncode == 0, r.stderr[-2000:]
    m = metrics(out)
    assert m["solver"]["warnings"] == [] and m["checks_passed"]
    assert m["solver"]["cutbacks"] == 0
    if h == 0.005:  # the full steps cycle there: halved (2-4 times seen)
        assert m["solver"]["uzawa_halvings"] > 0
    # the default hybrid projection's eps_n = TUNING.consistent_eps0 h / E_c
    assert m["solver"]["multiplier_mass"] == "hybrid"
    assert m["solver"]["penalty"]["eps_n"] == pytest.approx(1.0 * h / (2 * 200 * 1e5 / (1e5 + 200)))


def test_contact_modulus():
    from types import SimpleNamespace as NS

    from dolfinx_forms.contact.penalty import contact_modulus
    from dolfinx_forms.fem.laws import LinearElastic

    bodies = [NS(tag=1), NS(tag=2), NS(tag=3)]
    laws = {1: LinearElastic(1e4, 0.3), 2: LinearElastic(1e4, 0.3), 3: LinearElastic(1e2, 0.3)}
    assert contact_modulus(NS(bodies=bodies, pairs=[(0, 1)]), laws) == 1e4  # exactly E
    two = contact_modulus(NS(bodies=bodies, pairs=[(0, 1), (1, 2)]), laws)
    assert two == pytest.approx(2 * 1e4 * 1e2 / (1e4 + 1e2))  # the softer pair
    rigid = NS(bodies=[3])  # an obstacle touching body 3 only
    assert contact_modulus(NS(bodies=bodies, pairs=[(0, 1)]), laws, [rigid]) == 2e2


def test_two_blocks_scene(tmp_path):
    """Tractions given as expressions in x, y, friction switched on before the ramp, a uniform
    grid of given cells: the stick zone of demos/two_blocks.py (checks in the scene)."""
    out = tmp_path / "blocks"
    r = run("run", SCENES / "two_blocks.toml", "--out", out)
    assert r.returncode == 0, r.stderr
    m = metrics(out)
    assert m["checks_passed"] and [s["kind"] for s in m["stages"]] == ["friction", "ramp"]
    assert m["stages"][1]["values"] == {
        "clamp": 0.0,
        "top_x": 0.0,
        "top_y": -1.6e-3,
        "left": 1.0,
        "right": 1.0,
    }
    assert m["results"]["num_points"]["slip"] > 0 and m["results"]["num_points"]["stick"] > 0


def test_failed_check(tmp_path):
    """A check that fails: exit 1 with the reason, the results (and the verdict) written."""
    out = tmp_path / "patch"
    r = run("run", SCENES / "patch.toml", "--out", out, "--set", "checks[1].below=-1.0")
    assert r.returncode == 1
    assert "check 'results.shear_max' failed" in r.stderr and "is not <= -1" in r.stderr
    m = metrics(out)
    assert m["checks_passed"] is False
    assert [c["passed"] for c in m["checks"]] == [True, False, True, True]


@pytest.mark.parametrize(
    "args,key",
    [
        (["--set", "bodies[0].law.nu=0.5"], "bodies[0].law.nu"),  # while reading
        (["--set", "stages=[{kind='ramp', to={nope=1.0}}]"], "stages[0].to.nope"),
        (["--set", "bodies[0].window=[[0.0,0.0],[1.0,0.6]]"], "bodies[0].window"),  # the grid
        (["--set", "dirichlet[2].point=[0.1,0.0]"], "dirichlet[2].point"),  # the mesh
        # more cells than a builder makes (dolfinx_forms.mesh.scene.MAX_CELLS): was a numpy
        # MemoryError
        (["--set", "discretization.h=1e-7"], "discretization.h"),
        (["--set", "discretization.cells=[100000,100000]"], "discretization.cells"),
    ],
)
def test_bad_description(tmp_path, args, key):
    out = tmp_path / "never"
    r = run("run", SCENES / "patch.toml", "--out", out, *args)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and f"error: {key}:" in lines[0], r.stderr
    assert not out.exists() and not list(tmp_path.iterdir())


def test_bad_toml(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[discretization\nkind = 'cut'\n")
    r = run("run", bad, "--out", tmp_path / "never")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
    assert "bad.toml: not valid TOML" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


# --------------------------------------------------------------------------- in-process
def patch_dict():
    return tomllib.loads((SCENES / "patch.toml").read_text())


@pytest.mark.parametrize(
    "override,message",
    [
        ("discretization.h=-1", "discretization.h: must be > 0, got -1"),
        # (switching the kind drops the file's own keys of the other kind: a valid scene,
        # tests/app/test_scene_spec_hostile.py::test_set_switches_the_discretization_kind)
        ("discretization.slope=0.5", "discretization.slope: not used by kind = 'cut'"),
        ("bodies[1].shap=1", "bodies[1].shap: unknown key"),
        ("bodies[0].shape.type='star'", "bodies[0].shape.type: must be one of"),
        ("bodies[1].name='lower'", "bodies[1].name: duplicate body name"),
        ("pairs=[{bodies=['lower','lower']}]", "pairs[0].bodies: must be two different"),
        ("boundaries[0].side='middle'", "boundaries[0].side: must be one or more of"),
        ("dirichlet[0].value='x + q'", "dirichlet[0].value: unknown name 'q'"),
        ("dirichlet[0].value='__import__(1)'", "dirichlet[0].value: only sqrt"),
        ("tractions=[{boundary='upper_top', value=[1]}]", "tractions[0].value: must be a vector"),
        ("stages=[{kind='force', dirichlet='nope'}]", "stages[0].dirichlet: unknown Dirichlet"),
        ("stages=[{kind='force', dirichlet='top', target=1.0}]", "stages[0].first_guess: missing"),
        (
            "stages=[{kind='force', dirichlet='top', component='x', target=1.0, first_guess=0.0}]",
            "stages[0].component: must be the component",
        ),
        ("stages=[{kind='friction', mu=-1}]", "stages[0].mu: must be >= 0"),
        ("solver.steps=0", "solver.steps: must be >= 1"),
        ("solver.enforcement='nitsche'", "solver.enforcement: must be one of"),
        ("solver.multiplier_mass='consistent'", "solver.multiplier_mass: needs enforcement"),
        ("outputs.reaction='nope'", "outputs.reaction: unknown boundary 'nope'"),
        ("analytic.type='hertz'", "analytic.R: missing"),
        ("checks[0].quantity='foo.bar'", "checks[0].quantity: must be a metrics path"),
        ("checks[0].close_to=1.0", "checks[0].close_to: needs rtol or atol"),
        (
            "bodies[0].law={type='orthotropic', E1=1, E2=1, E3=1, nu12=0.9, nu13=0.9, nu23=0.9, "
            "G12=0.4}",
            "bodies[0].law: OrthotropicElastic",
        ),
    ],
)
def test_description_errors(override, message):
    with pytest.raises(SpecError) as e:
        load(patch_dict(), [override])
    assert str(e.value).startswith(message), str(e.value)
    assert "\n" not in str(e.value)


def test_description_defaults():
    spec = load(SCENES / "patch.toml")
    assert spec["name"] == "patch" and spec["pairs"] == [["lower", "upper"]]
    assert spec["stages"] == [{"kind": "ramp", "label": "load", "to": None, "steps": 1}]
    assert spec["outputs"]["reaction"] == "lower_bottom"  # the first Dirichlet boundary
    assert spec["dirichlet"][1] == {
        "boundary": "upper_top",
        "point": None,
        "component": "y",
        "value": -0.01,
        "name": "top",
    }
    assert spec["solver"]["enforcement"] == "penalty"
    assert spec["solver"]["multiplier_mass"] is None  # the penalty projects nothing
    d = patch_dict()
    d["solver"]["enforcement"] = "augmented"
    assert load(d)["solver"]["multiplier_mass"] == "hybrid"
    d = patch_dict()
    del d["solver"]["eps0"]
    assert load(d)["solver"]["eps0"] == 1.0
    # augmented: eps0 sets only the loop's speed; the demos' fast default
    assert load(d, ["solver.enforcement='augmented'"])["solver"]["eps0"] == 1e-2
    mindlin = load(SCENES / "mindlin.toml")  # extends hertz.toml
    assert mindlin["name"] == "mindlin" and mindlin["discretization"]["h"] == 0.05
    assert [s["kind"] for s in mindlin["stages"]] == ["force", "friction", "force"]
    assert mindlin["analytic"]["R"] == 10.0 and mindlin["analytic"]["tangential_force"]


def test_fitted_patch(tmp_path):
    """The gmsh path of dolfinx_forms.mesh.from_spec: the patch on structured body-fitted
    quadrilaterals (the boxes meet at y = 0.5 on matching edges) reproduces the penalised
    pressure."""
    from dolfinx_forms import run

    spec = patch_dict()
    spec["discretization"] = {
        "kind": "fitted",
        "h": 0.25,
        "cell": "quadrilateral",
        "structured": True,
    }
    spec["solver"]["band"] = 0.125  # h / 2, as patch.toml (a band of h / 4 is too thin here)
    spec["bodies"][0]["shape"]["max"][1] = spec["bodies"][1]["shape"]["min"][1] = 0.5
    result = run(spec, write=False, log=lambda *a: None)
    assert result.passed, result.failures
    m = result.metrics
    assert m["discretization"] == "conforming"
    assert m["results"]["contact_length"] == pytest.approx(1.0, abs=1e-12)


def test_per_dof_values():
    """A Dirichlet value given as an expression in x, y is a value per dof; in a ramp's `to`
    too. u_y = -0.01 written as an expression of x keeps the patch test exact."""
    from dolfinx_forms import run

    spec = patch_dict()
    spec["dirichlet"][1]["value"] = "-0.02 + 0.0 * x"
    spec["stages"] = [{"kind": "ramp", "to": {"top": "-0.01 * (1 + 0 * x)"}}]
    result = run(spec, write=False, log=lambda *a: None)
    assert result.passed, result.failures
    assert result.metrics["stages"][0]["values"]["top"] == {"min": -0.01, "max": -0.01}


@pytest.mark.mpi
def test_patch_scene_two_ranks():
    """The runner on 2 ranks (scene partitioned, contact points on rank 0, metrics gathered):
    the cut patch test is still exact."""
    from mpi4py import MPI

    from dolfinx_forms import run

    assert MPI.COMM_WORLD.size == 2, "run under mpirun -n 2"
    result = run(SCENES / "patch.toml", write=False, log=lambda *a: None)
    assert result.passed, result.failures
    assert result.metrics["results"]["num_points"]["slip"] == 64


def test_point_condition_off_the_mesh_names_the_nearest_vertex():
    from dolfinx_forms import run

    with pytest.raises(
        SpecError,
        match=r"dirichlet\[2\]\.point: \[0\.01, 0\.0\] is not a mesh "
        r"vertex \(the nearest is \[0\.0, 0\.0\]\)",
    ):
        run(SCENES / "patch.toml", write=False, overrides=["dirichlet[2].point=[0.01, 0.0]"])


def test_band_growth_from_a_description():
    """solver.band_growth: a band of 0.001 mm on the Hertz scene (h = 0.1) doubles up to 0.064
    with 6 doublings allowed (the contact's initial gaps reach ~0.05); with the default 4 (to
    0.016) the zone stays cut off and the run ends with that error, nothing written."""
    from dolfinx_forms.app import run as run_scene
    from dolfinx_forms.solvers.newton import ContactSolverError

    sets = ["discretization.h=0.1", "solver.band=0.001", "checks=[]"]
    r = run_scene(SCENES / "hertz.toml", write=False, overrides=[*sets, "solver.band_growth=6"])
    assert r.metrics["solver"]["band"] == {"start": 0.001, "end": 0.064}
    with pytest.raises(ContactSolverError, match="cut off at the band's edge"):
        run_scene(SCENES / "hertz.toml", write=False, overrides=sets)
