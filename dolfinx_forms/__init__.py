"""ILS contact: level-set frictional contact on structured grids, coupled to DOLFINx.

The compiled core (`dolfinx_forms._cpp`, built from `cpp_contact/`) holds the
level-set geometry (grids, shapes, reinitialisation, closest-point projection,
the intermediate contact surface) and the contact constitutive update (gaps,
return mapping). Equation numbers refer to Liu & Sun, ILS-MPM (seed paper 000).

The sub-packages, by job: `geometry` (contact pairs, point location, rigid obstacles),
`contact` (the contact set: active set, friction history, multipliers), `fem` (laws, bulk
forms, cut-cell integration, boundary conditions), `mesh` (scenes: bodies on one mesh, cut
grids, scenes from a description), `solvers` (the contact problem, Newton, linear solves,
load protocols, self-checks), `mpm` (the implicit material point method), `analysis`
(analytic references, comparisons, sampling), `io` (result folders, tables, fields, plots) and
`app` (command line, scene runner, the demos' run skeleton). Importing the package changes no
environment variable and starts no process: the application's start-up tweaks are
`dolfinx_forms.app.startup.start()`, called by the entry points.
"""

try:
    from dolfinx_forms import _cpp
except ImportError as e:  # pragma: no cover - a clear message instead of a bare ImportError
    raise ImportError(
        "dolfinx_forms._cpp is not built: run `make build` "
        "(or `pip install --no-build-isolation .`)"
    ) from e

from dolfinx_forms._cpp import (  # noqa: F401  (re-exported API)
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


def __getattr__(name):
    """`dolfinx_forms.run` (dolfinx_forms.app.run: run a scene description), imported on first
    use."""
    if name == "run":
        from dolfinx_forms.app import run

        return run
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
