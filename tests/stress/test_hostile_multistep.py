"""Stress suite (issue 29 item 9): hostile multi-step descriptions (`method = "mpm"`) through
the command line `python3 -m dolfinx_forms run`: bad grids, laws, obstacles, stages, force
targets, Dirichlet boxes, `extends` loops, overrides, files that are not TOML text. Each ends
with exit status 2, ONE stderr line naming the key, and nothing written (the case's folder as
before, no `--out`, no ./results). All run in one interpreter (runner_batch.py); a description
that passes every check is stopped before the run (status "computed": not refused).
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BATCH = Path(__file__).with_name("runner_batch.py")
SCENES = ROOT / "demos" / "scenes"
BD, ND, GA = "brazilian_disc", "nine_discs", "grain_assembly"

# (scene: a file of demos/scenes or a file written into the case's folder, the --set
# overrides, the key the one line must name)
CASES = [
    # ------------------------------------------------ grid
    (BD, ["grid.h=0"], "grid.h"),
    (BD, ["grid.h=-0.2"], "grid.h"),
    (BD, ["grid.h=nan"], "grid.h"),
    (BD, ["grid.h=inf"], "grid.h"),
    (BD, ['grid.h="0.2"'], "grid.h"),
    (BD, ["grid.h=1e-300"], "grid.h"),
    (BD, ["grid.h=1e300"], "grid.h"),
    (BD, ["grid.extent=[[0.0, 0.0], [0.0, 1.0]]"], "grid.extent"),
    (BD, ["grid.extent=[[1.0, 1.0], [-1.0, -1.0]]"], "grid.extent"),
    (BD, ["grid.extent=[[0.0, 0.0]]"], "grid.extent"),
    (BD, ["grid.extent=[[-1e300, -1e300], [1e300, 1e300]]"], "grid"),
    (BD, ["grid.bogus=1"], "grid.bogus"),
    # ------------------------------------------------ bodies and laws
    (BD, ["bodies[0].law.E=0"], "bodies[0].law.E"),
    (BD, ["bodies[0].law.E=-1.0"], "bodies[0].law.E"),
    (BD, ["bodies[0].law.E=inf"], "bodies[0].law.E"),
    (BD, ["bodies[0].law.nu=0.5"], "bodies[0].law.nu"),
    (BD, ["bodies[0].law.nu=-1.0"], "bodies[0].law.nu"),
    (BD, ["bodies[0].law={type='plastic', E=1.0, nu=0.3}"], "bodies[0].law.type"),
    (BD, ["bodies[0].shape.radius=0"], "bodies[0].shape.radius"),
    (BD, ["bodies[0].shape.radius=1e300"], "bodies[0]"),
    (BD, ["bodies[0].shape={type='triangle'}"], "bodies[0].shape.type"),
    (BD, ["bodies=[]"], "bodies"),
    (ND, ["bodies[1].name='disc0'"], "bodies[1].name"),
    (ND, ["bodies[1].shape.centre=[-3.399, -3.399]"], "bodies[1]"),  # identical to disc0
    (ND, ["bodies[1].shape.centre=[-2.5, -3.399]"], "bodies[1]"),  # overlapping
    (ND, ["bodies[4].shape.centre=[6.0, 6.0]"], "bodies[4]"),  # partly outside the grid
    (ND, ["bodies[4]={name='bow', shape={type='polygon', points=[[-1,-1],[1,1],[1,-1],[-1,1]]},"
          " law={type='linear', E=1e5, nu=0.3}}"], "bodies[4].shape.points"),
    # ------------------------------------------------ obstacles
    (BD, ["obstacles[0].shape.normal=[0.0, 0.0]"], "obstacles[0].shape.normal"),
    (BD, ["obstacles[0].name='platen_bottom'"], "duplicate name 'platen_bottom'"),
    (BD, ["obstacles[0].bodies=[]"], "obstacles[0].bodies"),
    (BD, ["obstacles[0].centre=[nan, 0.0]"], "obstacles[0].centre"),
    (BD, ["obstacles[0].shape.point=[0.0, 5.0]"], "obstacles[0]"),  # deep inside the disc
    # ------------------------------------------------ stages, motions, targets
    (BD, ["stages[0].steps=-1"], "stages[0].steps"),
    (BD, ["stages[0].steps=1.5"], "stages[0].steps"),
    (BD, ["stages[0].steps=1000000"], "stages[0].steps"),
    (BD, ["stages[0].move.platen_top.translation=[nan, 0.0]"],
     "stages[0].move.platen_top.translation"),
    (BD, ["stages[0].move.platen_top.translation=[0.0, -5.0]"],
     "stages[0].move.platen_top.translation"),
    (BD, ["stages[0].move.platen_top.rotation=inf"], "stages[0].move.platen_top.rotation"),
    (BD, ["stages[0].move.platen_top={spin=1.0}"], "stages[0].move.platen_top"),
    (BD, ["stages[0].dirichlet={nowhere=1.0}"], "stages[0].dirichlet"),
    (BD, ["stages[0].target={obstacle='platen_top', component='z', force=1.0}"],
     "stages[0].target"),
    (BD, ["stages[0].target={obstacle='nobody', component='y', force=1.0}"],
     "stages[0].target"),
    (BD, ["stages[0].target={obstacle='platen_top', component='y', force=nan}"],
     "stages[0].target"),
    (BD, ["stages[0].target={obstacle='platen_top', component='y', force=-100.0, tol=0}"],
     "stages[0].target"),
    (BD, ["stages[0].target={obstacle='platen_top', component='y', force=-100.0, max_iter=0}"],
     "stages[0].target"),
    # ------------------------------------------------ Dirichlet boxes
    (BD, ["dirichlet[0].component='z'"], "dirichlet[0].component"),
    (BD, ["dirichlet[0].box={x_min=1.0, x_max=-1.0}"], "dirichlet[0].box"),
    (BD, ["dirichlet[0].box={x_min=nan}"], "dirichlet[0].box"),
    (BD, ["dirichlet[0].value='9**9**9'"], "dirichlet[0].value"),
    (BD, ["dirichlet[0].value='1/0'"], "dirichlet[0].value"),
    (BD, ["dirichlet[0].value='sqrt(-1.0)'"], "dirichlet[0].value"),
    (BD, ["dirichlet[0].value='exp(1000.0)'"], "dirichlet[0].value"),
    (BD, ["dirichlet[0].value='__import__(\"os\")'"], "dirichlet[0].value"),
    # ------------------------------------------------ solver, outputs, analytic, checks
    (BD, ["solver.eps0=1e300"], "solver.eps0"),
    (BD, ["solver.eps0=1e-6"], "solver.eps0"),
    (BD, ["solver.mu=-0.5"], "solver.mu"),
    (BD, ["solver.band=0"], "solver.band"),
    (BD, ["solver.grid_refine=17"], "solver.grid_refine"),
    (BD, ["solver.num_gauss=0"], "solver.num_gauss"),
    (BD, ["solver.linear_solver='magic'"], "solver.linear_solver"),
    (BD, ["solver.linear_solver='condensed'", "solver.petsc={ksp_type='cg'}"], "solver.petsc"),
    (BD, ["solver.petsc={pc_type='nonsense'}"], "solver.petsc"),
    (BD, ["solver.newton={max_iterations=0}"], "solver.newton.max_iterations"),
    (BD, ["outputs.series='yes'"], "outputs.series"),
    (BD, ["analytic.body='nobody'"], "analytic.body"),
    # ------------------------------------------------ the name, overrides, the file
    (BD, ["name='/abs/path'"], "name"),
    (BD, ["name='../../x'"], "name"),
    (BD, ["name=''"], "name"),
    (BD, ["grid.h"], "--set"),  # no '='
    (BD, ["grid.h=[0.2"], "grid.h"),  # not TOML
    (BD, ["bodies[7].law.E=1.0"], "bodies[7]"),  # no such index
    ("loop_a.toml", [], "extends"),  # a extends b extends a
    ("self.toml", [], "extends"),
    ("binary.toml", [], "binary.toml"),
    ("not_toml.toml", [], "not_toml.toml"),
    ("missing.toml", [], "missing.toml"),
    ("empty.toml", [], "discretization: missing"),  # no method: a single-step one
]

FILES = {  # written into every case's folder
    "loop_a.toml": 'extends = "loop_b.toml"\nmethod = "mpm"\n',
    "loop_b.toml": 'extends = "loop_a.toml"\n',
    "self.toml": 'extends = "self.toml"\nmethod = "mpm"\n',
    "binary.toml": b'method = "mpm"\n\xff\xfe\x00\x01 binary\n',
    "not_toml.toml": 'method = "mpm"\n[grid\nh = 0.2\n',
    "empty.toml": "",
}


def _key(case):
    return f"{case[0]} {' '.join(case[1])}"


def populate(d):
    d.mkdir(parents=True)
    for name, text in FILES.items():
        (d / name).write_bytes(text if isinstance(text, bytes) else text.encode())


def snapshot(d):
    return {
        p.relative_to(d).as_posix(): (p.read_bytes() if p.is_file() else None)
        for p in sorted(d.rglob("*"))
    }


def command(case, d):
    scene, sets, _ = case
    path = d / scene if scene.endswith(".toml") else SCENES / f"{scene}.toml"
    argv = ["run", str(path), "--out", str(d / "out")]
    for s in sets:
        argv += ["--set", s]
    return argv


@pytest.fixture(scope="module")
def batch(tmp_path_factory):
    base = tmp_path_factory.mktemp("hostile_multistep")
    io = tmp_path_factory.mktemp("hostile_multistep_io")
    cases, folders = [], {}
    for i, case in enumerate(CASES):
        d = base / f"c{i:03d}"
        populate(d)
        folders[_key(case)] = (d, snapshot(d))
        cases.append(dict(argv=command(case, d), cwd=str(d)))
    assert len(folders) == len(CASES), "a case is listed twice"
    (io / "cases.json").write_text(json.dumps(cases))
    before = set(os.listdir(ROOT))
    r = subprocess.run(
        [sys.executable, str(BATCH), str(io / "cases.json"), str(io / "results.json")],
        capture_output=True, text=True, timeout=300, cwd=io,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr[-3000:]
    results = json.loads((io / "results.json").read_text())
    assert set(os.listdir(ROOT)) == before  # nothing written into the repository
    return {k: (d, res, snap) for (k, (d, snap)), res in zip(folders.items(), results)}


@pytest.mark.parametrize("case", CASES, ids=[_key(c) for c in CASES])
def test_hostile_description(batch, case):
    d, r, before = batch[_key(case)]
    assert r["status"] == "exit", f"{r['status']} (code {r['code']}): {r['stderr'][-3000:]}"
    lines = [ln for ln in r["stderr"].splitlines() if ln.strip()]
    assert r["code"] == 2 and len(lines) == 1, r["stderr"][-3000:]
    assert lines[0].startswith("python3 -m dolfinx_forms: error: "), lines[0]
    assert case[2] in lines[0], lines[0]
    assert r["stdout"].strip() == ""
    assert not (d / "out").exists() and not (d / "results").exists()
    assert snapshot(d) == before
    assert r["seconds"] < 10


def test_enough_cases():
    assert len(CASES) >= 60
