"""ILS contact: level-set frictional contact on structured grids, coupled to DOLFINx.

The compiled core (`dolfinx_forms._cpp`, built from `cpp_contact/`) holds the
level-set geometry (grids, shapes, reinitialisation, closest-point projection,
the intermediate contact surface) and the contact constitutive update (gaps,
return mapping). Equation numbers refer to Liu & Sun, ILS-MPM (seed paper 000).
"""

import os
import sys

from . import plot_worker as _plot_worker

_plot_worker.start_early()  # a demo's plot: matplotlib's import overlaps ours (plot_worker.py)

# A process started without mpirun is an Open MPI singleton: by default its MPI_Init starts a
# helper daemon (for MPI_Comm_spawn, which this code never calls), ~0.4 s of every run's start.
# Under mpirun the setting has no effect; a user's own value is kept.
os.environ.setdefault("OMPI_MCA_ess_singleton_isolated", "1")
# OpenBLAS (the Makefile installs it: MUMPS and the dense contact blocks run 2-3x faster than on
# the reference BLAS) starts a thread per core; MPI ranks already share the cores.
if int(os.environ.get("OMPI_COMM_WORLD_SIZE", "1")) > 1:
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

try:
    from . import _cpp
except ImportError as e:  # pragma: no cover - a clear message instead of a bare ImportError
    raise ImportError(
        "dolfinx_forms._cpp is not built: run `make build` "
        "(or `pip install --no-build-isolation .`)"
    ) from e

from ._cpp import (  # noqa: F401  (re-exported API)
    Box,
    CellLocator,
    Circle,
    Complement,
    ContactQuadrature,
    ContactState,
    Ellipse,
    FrictionHistory,
    Intersection,
    LevelSet,
    Polygon,
    ProjectionStatus,
    Shape,
    StructuredGrid,
    Union,
    add_coupling_zeros,
    assemble_contact,
    closest_point_projection,
    closing_levelset,
    compute_gaps,
    contact_region,
    contact_surface,
    insert_coupling,
    intermediate_levelset,
    levelset_from_polyline,
    levelset_from_shape,
    min_levelset,
    reinitialize,
    return_mapping,
)

__version__ = "0.1.0"


def _setup():
    """Quiet JIT loggers (logs.py) and, under mpirun, an error on one rank ends every rank
    (parallel.py)."""
    from . import logs

    logs.configure()
    # A singleton's only peer is itself, yet Open MPI's default point-to-point layer (UCX) and
    # transports (TCP, shared memory) probe the machine for ~0.2 s in MPI_Init. The setting
    # is read by MPI_Init only and removed after it: an mpirun started from this process must
    # not inherit btl=self. A launched process (mpirun, srun, hydra) keeps the defaults.
    launched = ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "SLURM_PROCID")
    singleton = {"OMPI_MCA_pml": "ob1", "OMPI_MCA_btl": "self"}
    if "mpi4py.MPI" in sys.modules or any(k in os.environ for k in launched + (*singleton,)):
        singleton = {}
    os.environ.update(singleton)
    try:
        from mpi4py import MPI
    finally:
        for k in singleton:
            del os.environ[k]

    if MPI.COMM_WORLD.size > 1:
        from . import parallel

        parallel.install()


def _import_ufl_ffcx():
    """Debian's ufl and ffcx (2022.2, 0.5) read their own version at import with pkg_resources,
    which scans every installed distribution (0.1 s, a third of importing dolfinx). These two
    imports see a stand-in whose get_distribution answers from the name of the distribution's
    .dist-info folder on sys.path (importlib.metadata, itself 0.04 s to import, where there is
    none), the same version string; pkg_resources itself stays importable (the stand-in is
    removed after)."""
    if any(m in sys.modules for m in ("pkg_resources", "ufl", "ffcx")):
        return
    import types

    def version(name):
        prefix = name.replace("-", "_").lower() + "-"
        for folder in sys.path:
            try:
                entries = os.listdir(folder or ".")
            except OSError:
                continue
            for e in entries:
                if e.endswith(".dist-info") and e.lower().startswith(prefix):
                    return e[len(prefix) : -len(".dist-info")]
        import importlib.metadata

        return importlib.metadata.version(name)

    def get_distribution(name):
        return types.SimpleNamespace(version=version(name))

    sys.modules["pkg_resources"] = types.ModuleType("pkg_resources", "ufl/ffcx stand-in")
    sys.modules["pkg_resources"].get_distribution = get_distribution
    try:
        import ffcx  # noqa: F401
        import ufl  # noqa: F401
    finally:
        del sys.modules["pkg_resources"]


_import_ufl_ffcx()
_setup()


def __getattr__(name):
    """`dolfinx_forms.run` (app.py: run a scene description), imported on first use."""
    if name == "run":
        from .app import run

        return run
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
