"""Test set-up. The packages (dolfinx_forms, meshes) are imported like any installed package:
from PYTHONPATH (`make test` exports the repository root) or from a pip installation; nothing
here changes sys.path.

Tests start demos and mpirun in subprocesses, which inherit os.environ. When this process
found the packages in a source tree that PYTHONPATH does not name (`/usr/bin/python3 -m pytest`
from the repository root puts the current folder on sys.path), that tree is added to
PYTHONPATH here, so the children import the same code as the tests.
"""

import importlib.util
import os
from pathlib import Path


def _source_tree():
    spec = importlib.util.find_spec("dolfinx_forms")
    if spec is None or spec.origin is None:
        return None
    root = Path(spec.origin).resolve().parents[1]
    return root if (root / "pyproject.toml").is_file() and (root / "meshes").is_dir() else None


def pytest_configure(config):
    _drop_mpi_environment()
    root = _source_tree()
    if root is None:
        return
    parts = [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    if str(root) not in {str(Path(p).resolve()) for p in parts}:
        os.environ["PYTHONPATH"] = os.pathsep.join([str(root), *parts])


def _drop_mpi_environment():
    """MPI initialised now, and what its MPI_Init wrote to the C environment dropped
    (dolfinx_forms.common.drop_mpi_environment). Outside mpirun this process is an Open MPI
    singleton with a helper daemon, whose address and rank 0 subprocess would pass to every
    child started with env=None: each demo joined this process's job as a second rank 0. (A
    demo started by a test has twice ended with exit 1 and nothing on either stream in CI;
    this sharing is the suspect, not reproduced here in 1200 runs.)"""
    from mpi4py import MPI

    from dolfinx_forms.common import drop_mpi_environment

    if MPI.Is_initialized():
        drop_mpi_environment()
