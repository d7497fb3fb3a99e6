"""ILS contact: level-set frictional contact on structured grids, coupled to DOLFINx.

The compiled core (`dolfinx_forms._cpp`, built from `cpp_contact/`) holds the
level-set geometry (grids, shapes, reinitialisation, closest-point projection,
the intermediate contact surface) and the contact constitutive update (gaps,
return mapping). Equation numbers refer to Liu & Sun, ILS-MPM (seed paper 000).
"""

import os

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
        "dolfinx_forms._cpp is not built: run `make build` (or `pip install --no-build-isolation .`)"
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
    from mpi4py import MPI

    if MPI.COMM_WORLD.size > 1:
        from . import parallel

        parallel.install()


_setup()


def __getattr__(name):
    """`dolfinx_forms.run` (app.py: run a scene description), imported on first use."""
    if name == "run":
        from .app import run

        return run
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
