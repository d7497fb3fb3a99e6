"""solution.xdmf is one grid that meshio reads (and ParaView): the displacement, each body's
level set, the stress, the body tag and the cut/interior tag, checked against the run (the
patch test: its exact, uniform state) and read again through h5py (issue 29, item 5)."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module", params=["cut", "conforming"])
def patch(request, tmp_path_factory):
    out = tmp_path_factory.mktemp("fields") / request.param
    args = ["--discretization", request.param, "--out", str(out)]
    r = subprocess.run(
        [sys.executable, str(ROOT / "demos" / "patch_test.py"), *args],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stderr
    return request.param, out, json.loads((out / "metrics.json").read_text())


def test_meshio_reads_every_field(patch):
    import meshio

    kind, out, m = patch
    mesh = meshio.read(out / "solution.xdmf")  # one grid: no "Only supports one grid" exit
    assert set(mesh.point_data) == {"displacement", "levelset_lower", "levelset_upper"}
    expected = {"stress", "body"} | ({"cut"} if kind == "cut" else set())
    assert set(mesh.cell_data) == expected
    cells = mesh.cells[0].data
    assert len(cells) == m["mesh"]["num_cells"]
    # the top moved down by the demo's displacement; the bottom held
    uy = mesh.point_data["displacement"][:, 1]
    d = m["parameters"]["displacement"]
    assert uy.min() == pytest.approx(-d, rel=1e-12) and np.abs(uy).max() <= d * (1 + 1e-12)
    # the uniform stress of the patch test: sigma_yy = -(the computed contact pressure)
    syy = mesh.cell_data["stress"][0][:, 4]
    assert np.allclose(syy, -m["results"]["pressure_mean"], rtol=1e-8)
    body = mesh.cell_data["body"][0].ravel()
    assert set(body) == {1.0, 2.0}
    # the level sets: < 0 inside, at the nodes of each body's cells that no boundary cuts
    inner = body > 0 if kind != "cut" else mesh.cell_data["cut"][0].ravel() == 0
    h = m["mesh"]["h_contact"]
    for tag, name in ((1, "lower"), (2, "upper")):
        phi = mesh.point_data[f"levelset_{name}"]
        assert phi[cells[(body == tag) & inner]].max() <= 1e-12 * h
        assert phi[cells[(body == 3 - tag) & inner]].min() >= -1e-12 * h  # the other body


def test_h5_paths_are_relative_and_h5py_reads_them(patch):
    import h5py
    import meshio

    _, out, _ = patch
    text = (out / "solution.xdmf").read_text()
    assert "solution.h5:/" in text and str(out) not in text  # relative to the .xdmf
    mesh = meshio.read(out / "solution.xdmf")
    with h5py.File(out / "solution.h5", "r") as f:
        u = f["/Function/displacement/0"][()]
    assert np.array_equal(u, mesh.point_data["displacement"])
