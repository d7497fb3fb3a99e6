"""Cut-cell forms (dolfinx_forms/cut.py): the C++ cut kernels inside one dolfinx Form.

Checks against independent formulations: the FFCx kernel of the same UFL form on uncut cells
(to round-off), rigid-body modes (zero energy with and without ghost penalty), the ghost
penalty's zero action on linear fields, the cut traction load against its closed form, and the
cut rule's disc area at second order (the vectorised binding used by diagnostics).
"""

from types import SimpleNamespace

import numpy as np
import pytest
import ufl
from dolfinx import fem
from dolfinx import mesh as dmesh
from mpi4py import MPI

from dolfinx_forms import _cpp
from dolfinx_forms.cut import CUT, GHOST, INTERIOR, CutForms
from dolfinx_forms.solver import plane_strain

E, NU = 3.0, 0.3


def _scene(nx=6, ny=4, levelset=None):
    """A [0,2]x[0,1] quad mesh as a one-body cut scene; levelset(x) -> phi at the vertices."""
    m = dmesh.create_rectangle(MPI.COMM_WORLD, [[0, 0], [2, 1]], [nx, ny],
                               dmesh.CellType.quadrilateral)
    nc = m.topology.index_map(2).size_local + m.topology.index_map(2).num_ghosts
    cells = np.arange(nc, dtype=np.int32)
    Q = fem.FunctionSpace(m, ("Lagrange", 1))
    phi = fem.Function(Q)
    phi.interpolate(levelset or (lambda x: -1.0 - 0 * x[0]))
    cdofs = Q.dofmap.list.array.reshape(nc, 4)
    kind = np.where(np.max(phi.x.array[cdofs], axis=1) <= 0, INTERIOR, CUT).astype(np.int32)
    m.topology.create_connectivity(1, 2)
    f2c = m.topology.connectivity(1, 2)
    nf = m.topology.index_map(1).size_local + m.topology.index_map(1).num_ghosts
    ghost = np.array([f for f in range(nf) if len(f2c.links(f)) == 2
                      and np.any(kind[f2c.links(f)] == CUT)], np.int32)
    cut = SimpleNamespace(kind_tags=dmesh.meshtags(m, 2, cells, kind),
                          ghost_facets=dmesh.meshtags(m, 1, ghost, np.full(len(ghost), GHOST,
                                                                            np.int32)))
    scene = SimpleNamespace(mesh=m, cell_tags=dmesh.meshtags(m, 2, cells, np.ones(nc, np.int32)),
                            cell_type="quadrilateral", cut=cut)
    return scene, phi, kind


def _matrix(form):
    A = fem.petsc.assemble_matrix(form)
    A.assemble()
    return A


def test_cut_kernel_equals_ffcx_on_uncut_cells():
    scene, phi, kind = _scene()
    scene.cut.kind_tags.values[:] = CUT  # every cell through the C++ kernel, phi < 0 everywhere
    V = fem.VectorFunctionSpace(scene.mesh, ("Lagrange", 1))
    A = _matrix(CutForms(V, scene, {1: (E, NU)}, ghost_penalty=0.0, phi=phi).a)
    mu, lmb = plane_strain(E, NU)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    eps = lambda w: ufl.sym(ufl.grad(w))  # noqa: E731
    B = _matrix(fem.form(ufl.inner(2 * mu * eps(u) + lmb * ufl.tr(eps(u)) * ufl.Identity(2),
                                   eps(v)) * ufl.dx))
    A.axpy(-1.0, B)
    assert A.norm() <= 1e-12 * B.norm()


@pytest.mark.parametrize("gamma", [0.0, 0.1])
def test_rigid_modes_zero_energy_and_ghost_penalty_linear_fields(gamma):
    # a slanted line and a circle cut the cells at arbitrary fractions
    scene, phi, kind = _scene(8, 5, lambda x: np.minimum(x[1] - 0.31 * x[0] - 0.43,
                                                           np.hypot(x[0] - 1.3, x[1] - 0.2) - 0.3))
    assert np.sum(kind == CUT) > 5
    V = fem.VectorFunctionSpace(scene.mesh, ("Lagrange", 1))
    forms = CutForms(V, scene, {1: (E, NU)}, ghost_penalty=gamma, phi=phi)
    A = _matrix(forms.a)
    modes = [lambda x: np.stack([1 + 0 * x[0], 0 * x[0]]), lambda x: np.stack([0 * x[0], 1 + 0 * x[0]]),
             lambda x: np.stack([-x[1], x[0]])]
    r = fem.Function(V)
    y = A.createVecLeft()
    for mode in modes:
        r.interpolate(mode)
        A.mult(r.vector, y)
        assert y.norm() <= 1e-12 * A.norm() * r.vector.norm()
    # a linear non-rigid field: the ghost penalty adds nothing (its gradient has no jumps)
    r.interpolate(lambda x: np.stack([0.3 * x[0] + 0.2 * x[1], -0.1 * x[0] + 0.5 * x[1]]))
    A0 = _matrix(CutForms(V, scene, {1: (E, NU)}, ghost_penalty=0.0, phi=phi).a)
    y0 = A0.createVecLeft()
    A.mult(r.vector, y)
    A0.mult(r.vector, y0)
    y.axpy(-1.0, y0)
    assert y.norm() <= 1e-12 * y0.norm()
    if gamma > 0:  # and it does act on a non-linear field
        r.interpolate(lambda x: np.stack([x[0] ** 2, x[1] * x[0]]))
        A.mult(r.vector, y)
        A0.mult(r.vector, y0)
        y.axpy(-1.0, y0)
        assert y.norm() > 1e-3 * y0.norm()


def test_cut_traction_is_the_clipped_facet_integral():
    # body y < 0.53 on [0,2]x[0,1] (ny = 4: the line cuts the cells of row 3 at 0.12/0.25);
    # traction t = (y, x y) on the left side x = 0: total force (int_0^0.53 y dy, 0)
    scene, phi, kind = _scene(6, 4, lambda x: x[1] - 0.53)
    m = scene.mesh
    facets = dmesh.locate_entities_boundary(m, 1, lambda x: np.isclose(x[0], 0.0))
    scene.facet_tags = dmesh.meshtags(m, 1, np.sort(facets).astype(np.int32),
                                      np.full(len(facets), 7, np.int32))
    V = fem.VectorFunctionSpace(m, ("Lagrange", 1))
    forms = CutForms(V, scene, {1: (E, NU)}, ghost_penalty=0.0, phi=phi)
    X = ufl.SpatialCoordinate(m)
    b = fem.petsc.assemble_vector(forms.traction_form(ufl.as_vector((X[1], X[0] * X[1] + 2)), 7))
    f = b.array.reshape(-1, 2).sum(axis=0)
    assert f[0] == pytest.approx(0.53 ** 2 / 2, rel=1e-13)
    assert f[1] == pytest.approx(2 * 0.53, rel=1e-13)
    # moment about the origin of the x-load: int y * y dy (the Q1 test functions carry it)
    y = V.tabulate_dof_coordinates()[:, 1]
    assert np.dot(b.array.reshape(-1, 2)[:, 0], y) == pytest.approx(0.53 ** 3 / 3, rel=1e-13)


def test_disc_area_second_order_through_the_binding():
    errs = []
    for n in (20, 40, 80):
        x = np.linspace(-1.25, 1.25, n + 1)
        X, Y = np.meshgrid(x, x, indexing="ij")
        d = np.hypot(X, Y) - 1.0
        phi = np.stack([d[:-1, :-1], d[1:, :-1], d[:-1, 1:], d[1:, 1:]], axis=-1).reshape(-1, 4)
        h = x[1] - x[0]
        q = _cpp.cut_quadrature(phi, 2)
        area = h * h * q["weights"].sum()
        assert area == pytest.approx(h * h * _cpp.inside_fraction(phi).sum(), rel=1e-14)
        errs.append(abs(area - np.pi))
    rates = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(rates > 1.8), (errs, rates)
