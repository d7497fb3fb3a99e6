"""Boundary conditions and loads of a contact problem (the scene names the boundaries)."""

from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import fem


@dataclass
class Dirichlet:
    """u[component] = value(lam) on a tagged boundary (component None: all components).

    boundary: a facet-tag name of the scene, or a callable marker x (3, n) -> bool selecting
    dofs geometrically (e.g. a single point)."""

    boundary: object
    component: object
    value: object = 0.0  # float or callable(lam) -> float

    def at(self, lam):
        return self.value(lam) if callable(self.value) else float(self.value)


@dataclass
class Traction:
    """Surface traction t(x) (a UFL vector) on a tagged boundary, scaled by scale(lam)."""

    boundary: str
    traction: object
    scale: object = None  # callable(lam) -> float; default lam

    def at(self, lam):
        return lam if self.scale is None else self.scale(lam)


@dataclass
class BodyForce:
    """Body force f per unit volume on body `body` (a tag; None: every body), scaled by
    scale(lam) (default lam). f: a UFL vector, or a callable x -> UFL vector with x the
    spatial coordinate. On cut bodies it is integrated over the inside part only."""

    f: object
    body: object = None
    scale: object = None

    def at(self, lam):
        return lam if self.scale is None else self.scale(lam)

    def form(self, v, measure):
        f = self.f
        if not isinstance(f, ufl.core.expr.Expr) and callable(f):  # UFL exprs are callable too
            f = f(ufl.SpatialCoordinate(v.ufl_function_space().mesh))
        return ufl.inner(f, v) * measure(self.body)


@dataclass
class Load:
    """Any UFL right-hand side: form(v, measure) -> a linear form in the test function v
    (measure(tag) integrates over body `tag`'s material, cut cells included), scaled by
    scale(lam) (default lam)."""

    form_fn: object
    scale: object = None

    def at(self, lam):
        return lam if self.scale is None else self.scale(lam)

    def form(self, v, measure):
        return self.form_fn(v, measure)


def dirichlet_dofs(V, scene, condition):
    """Local (owned + ghost) unrolled dof indices that `condition` prescribes."""
    gdim = V.mesh.geometry.dim
    comps = list(range(gdim)) if condition.component is None else [condition.component]
    if callable(condition.boundary):
        dofs = [
            fem.locate_dofs_geometrical((V.sub(c), V.sub(c).collapse()[0]), condition.boundary)[0]
            for c in comps
        ]
    else:
        if condition.boundary not in scene.boundaries:
            raise ValueError(
                f"Dirichlet: unknown boundary {condition.boundary!r}; the scene has "
                f"{sorted(scene.boundaries)}"
            )
        facets = scene.facet_tags.find(scene.boundaries[condition.boundary])
        dofs = [
            fem.locate_dofs_topological(V.sub(c), V.mesh.topology.dim - 1, facets) for c in comps
        ]
    return np.concatenate(dofs).astype(np.int32)


def nearest_vertex_marker(mesh, point, on=None):
    """A Dirichlet marker x (3, n) -> bool that selects the one mesh vertex nearest to `point`
    among those where on(x) holds (a predicate on coordinates (3, n); default: every vertex),
    e.g. the bottom vertex nearest to the middle of a roller support. Collective: every rank
    selects the same vertex (ties: the smaller coordinates). Raises ValueError if no vertex
    qualifies."""
    gdim = mesh.geometry.dim
    X = mesh.geometry.x
    X = X[on(X.T)] if on is not None else X
    p = np.zeros(3)
    p[: len(point)] = point
    d = np.linalg.norm(X[:, :gdim] - p[:gdim], axis=1)
    k = np.argmin(d) if d.size else None
    mine = (float(d[k]), tuple(X[k, :gdim])) if d.size else (np.inf, ())
    dist, c = min(mesh.comm.allgather(mine))
    if not np.isfinite(dist):
        raise ValueError("nearest_vertex_marker: no vertex satisfies `on`")
    c = np.array(c)
    return lambda x: np.all(np.isclose(x[:gdim].T, c), axis=1)
