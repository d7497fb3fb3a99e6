"""The package installs offline into a venv and works from anywhere (no PYTHONPATH, no
repository on sys.path): both packages (dolfinx_forms, meshes), the compiled module built by
setup.py with CMake, and a small contact problem solved from a folder outside the repository.

The sources are copied first (git's tracked and untracked-but-not-ignored files, so no build
folder, no in-tree dolfinx_forms/_cpp*.so and no egg-info reach the build, and the build
writes nothing into the repository). Building the C++ module takes about 2.5 minutes on 2
busy cores; it runs in `make test` (test-python); skip it in a quick local run with
`/usr/bin/python3 -m pytest -m "not mpi and not install"`.
"""

import os
import shutil
import subprocess
import textwrap
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.install
SYSTEM_PYTHON = "/usr/bin/python3"  # Debian's interpreter (it sees python3-dolfinx)

SCRIPT = textwrap.dedent(
    """
    import sys
    from pathlib import Path

    import numpy as np
    from mpi4py import MPI

    import dolfinx_forms
    import meshes
    from dolfinx_forms import _cpp
    from dolfinx_forms.solvers.options import ContactOptions
    from dolfinx_forms.solvers.problem import ContactProblem
    from meshes.cut import patch_cut_scene
    from meshes.patch import patch_dirichlet

    venv = Path(sys.prefix).resolve()
    for mod in (dolfinx_forms, _cpp, meshes):  # the installed copies, not the repository
        assert Path(mod.__file__).resolve().is_relative_to(venv), mod.__file__
    E, nu, d, n = 1.0, 0.3, 0.01, 5
    scene = patch_cut_scene(MPI.COMM_WORLD, n=n, interface=0.5)  # a row of cut cells
    p = ContactProblem(scene, {b.tag: (E, nu) for b in scene.bodies},
                       contact=ContactOptions(mu=0.0, eps0=1.0, band=0.5 / n),
                       dirichlet=patch_dirichlet(d), log=lambda *a, **k: None)
    p.solve(1)
    pn = np.abs(np.concatenate([q["p_n"] for q in p.contact_points()]))
    Ep = E / (1 - nu**2)
    penalised = Ep * d / (1.0 + Ep * p.eps_n)  # the patch test's exact penalised pressure
    assert len(pn) > 0 and np.allclose(pn, penalised, rtol=1e-10, atol=0), (pn, penalised)
    assert abs(abs(p.reaction("upper_top")[1]) - penalised) < 1e-10 * penalised
    print("installed patch test ok", len(pn), penalised)
"""
)


def source_files(root: Path):
    """Relative paths of the sources: git's view (tracked + untracked, ignored excluded)."""
    if (root / ".git").exists() and shutil.which("git"):
        r = subprocess.run(
            ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
            cwd=root,
            capture_output=True,
            text=True,
            check=True,
        )
        return [f for f in r.stdout.split("\0") if f and (root / f).is_file()]
    skip = {"build", ".git", "results", "__pycache__", ".pytest_cache"}
    return [
        str(p.relative_to(root))
        for p in root.rglob("*")
        if p.is_file()
        and not skip & set(p.relative_to(root).parts)
        and p.suffix != ".so"
        and ".egg-info" not in str(p)
    ]


def clean_env(**extra):
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "PIP_"))}
    env.update(PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1", **extra)
    return env


@pytest.mark.skipif(not Path(SYSTEM_PYTHON).exists(), reason="needs Debian's /usr/bin/python3")
def test_venv_install_works_outside_the_repository(tmp_path):
    src = tmp_path / "src"
    for rel in source_files(ROOT):
        (src / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / rel, src / rel)
    assert not list(src.rglob("_cpp*.so")) and (src / "meshes" / "cut.py").is_file()
    venv = tmp_path / "venv"
    subprocess.run(
        [SYSTEM_PYTHON, "-m", "venv", "--system-site-packages", str(venv)],
        check=True,
        env=clean_env(),
        timeout=300,
    )
    py = venv / "bin" / "python"
    t0 = time.perf_counter()
    r = subprocess.run(
        [str(py), "-m", "pip", "install", "--no-build-isolation", "--no-deps", str(src)],
        capture_output=True,
        text=True,
        env=clean_env(),
        cwd=tmp_path,
        timeout=1800,
    )
    build_s = time.perf_counter() - t0
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    print(f"pip install (CMake build of _cpp included): {build_s:.0f} s")
    elsewhere = tmp_path / "elsewhere"  # outside the repository and the copied sources
    elsewhere.mkdir()
    (elsewhere / "patch.py").write_text(SCRIPT)
    r = subprocess.run(
        [str(py), "patch.py"],
        capture_output=True,
        text=True,
        cwd=elsewhere,
        env=clean_env(XDG_CACHE_HOME=str(tmp_path / "cache")),
        timeout=600,
    )
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert "installed patch test ok" in r.stdout
    site = next((venv / "lib").glob("python3*/site-packages"))  # both packages, _cpp inside
    assert (site / "meshes" / "cut.py").is_file() and list(site.glob("dolfinx_forms/_cpp*.so"))
