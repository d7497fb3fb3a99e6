"""Cut-cell integration (dolfinx_forms/fem/cut.py): any UFL form on the inside part of cut cells.

Checks against independent formulations: FFCx's own rule on uncut cells (to round-off), the
elastic energy of random Q1 fields against the sub-triangle rule of `cut_square_rule` (both
exact for Q2 integrands), rigid-body modes (zero energy with and without ghost penalty), the
ghost penalty's zero action on linear fields, body forces against the inside area and first
moment, the cut traction load against its closed form, and the cut rule's disc area at second
order (the vectorised binding used by diagnostics).
"""

from types import SimpleNamespace

import numpy as np
import pytest
import ufl
from dolfinx import fem
from dolfinx import mesh as dmesh
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_forms import _cpp
from dolfinx_forms.fem.cut import CUT, GHOST, INTERIOR, CutIntegration
from dolfinx_forms.fem.laws import LinearElastic

E, NU = 3.0, 0.3


def _scene(nx=6, ny=4, levelset=None):
    """A [0,2]x[0,1] quad mesh as a one-body cut scene; levelset(x) -> phi at the vertices."""
    m = dmesh.create_rectangle(
        MPI.COMM_WORLD, [[0, 0], [2, 1]], [nx, ny], dmesh.CellType.quadrilateral
    )
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
    ghost = np.array(
        [f for f in range(nf) if len(f2c.links(f)) == 2 and np.any(kind[f2c.links(f)] == CUT)],
        np.int32,
    )
    cut = SimpleNamespace(
        kind_tags=dmesh.meshtags(m, 2, cells, kind),
        ghost_facets=dmesh.meshtags(m, 1, ghost, np.full(len(ghost), GHOST, np.int32)),
    )
    scene = SimpleNamespace(
        mesh=m,
        cell_tags=dmesh.meshtags(m, 2, cells, np.ones(nc, np.int32)),
        cell_type="quadrilateral",
        cut=cut,
    )
    return scene, phi, kind


def _matrix(form):
    A = fem.petsc.assemble_matrix(form)
    A.assemble()
    return A


LAW = LinearElastic(E, NU)


def _forms(scene, phi, gamma=0.0):
    """(integration, bilinear form) of LAW on the scene's material, ghost penalty gamma."""
    cut = CutIntegration(scene, phi=phi)
    V = fem.VectorFunctionSpace(scene.mesh, ("Lagrange", 1))
    u, du, v = fem.Function(V), ufl.TrialFunction(V), ufl.TestFunction(V)
    a = ufl.derivative(LAW.residual(u, v, cut.measure()), u, du)
    if gamma > 0:
        pm = fem.Function(fem.FunctionSpace(scene.mesh, ("DG", 0)))
        pm.x.array[:] = LAW.p_modulus
        a += cut.ghost_penalty(du, v, gamma, pm)
    return cut, V, fem.form(a)


def test_cut_weights_equal_ffcx_on_uncut_cells():
    scene, phi, kind = _scene()
    scene.cut.kind_tags.values[:] = CUT  # every cell through the weights, phi < 0 everywhere
    cut, V, a = _forms(scene, phi)
    assert np.allclose(cut.factor.x.array, 1.0, rtol=0, atol=1e-13)
    A = _matrix(a)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    B = _matrix(fem.form(ufl.inner(LAW.stress(u), ufl.grad(v)) * ufl.dx))
    A.axpy(-1.0, B)
    assert A.norm() <= 1e-12 * B.norm()


def test_cut_energy_equals_sub_triangle_rule():
    # energy of random Q1 fields on a mesh cut by a line and a circle: the moment-fitted
    # weights (FFCx, 3x3 points) and the degree-4 sub-triangle rule are both exact for Q2
    levelset = lambda x: np.minimum(
        x[1] - 0.31 * x[0] - 0.43, np.hypot(x[0] - 1.3, x[1] - 0.2) - 0.3  # noqa: E731
    )
    scene, phi, kind = _scene(8, 5, levelset)
    cut, V, a = _forms(scene, phi)
    A = _matrix(a)
    m = scene.mesh
    nc = len(kind)
    pdofs = phi.function_space.dofmap.list.array.reshape(nc, 4)
    vdofs = V.dofmap.list.array.reshape(nc, 4)
    xg = m.geometry.x[m.geometry.dofmap.array.reshape(nc, 4)][:, :, :2]
    rng = np.random.default_rng(3)
    for _ in range(3):
        w = fem.Function(V)
        w.x.array[:] = rng.standard_normal(len(w.x.array))
        y = A.createVecLeft()
        A.mult(w.vector, y)
        energy = w.vector.dot(y)
        ref = 0.0
        for c in range(nc):  # reference: sub-triangle rule, Q1 gradients on the rectangle
            if kind[c] == INTERIOR:
                q = _cpp.cut_quadrature(-np.ones((1, 4)), 4)
            else:
                q = _cpp.cut_quadrature(phi.x.array[pdofs[c]][None, :], 4)
            if not len(q["weights"]):
                continue
            X, Y = q["points"][:, 0], q["points"][:, 1]
            J = np.column_stack([xg[c, 1] - xg[c, 0], xg[c, 2] - xg[c, 0]])  # affine cell
            # tensor-order Q1 basis derivatives on the reference square, then to x, y
            dref = np.stack(
                [np.stack([-(1 - Y), 1 - Y, -Y, Y], 1), np.stack([-(1 - X), -X, 1 - X, X], 1)], 2
            )  # (np, 4, 2)
            dphys = dref @ np.linalg.inv(J)  # rows: grad_X N J^-1 = grad_x N
            uc = w.x.array.reshape(-1, 2)[vdofs[c]]  # (4, 2)
            G = np.einsum("pnd,nc->pcd", dphys, uc)  # (np, 2 components, 2 derivatives)
            eps = 0.5 * (G + G.transpose(0, 2, 1))
            tr = eps[:, 0, 0] + eps[:, 1, 1]
            dens = 2 * LAW.mu * np.sum(eps * eps, axis=(1, 2)) + LAW.lmbda * tr**2
            ref += abs(np.linalg.det(J)) * np.dot(q["weights"], dens)
        assert energy == pytest.approx(ref, rel=1e-12)


def test_a_measure_over_many_bodies_is_one_kernel_given_to_each_body():
    # three bodies (the cells tagged 1, 2, 3 in turn): measure([1, 2, 3]) is one integral per
    # part, on an id that stands for the group; CutIntegration.form compiles its kernel once and
    # gives it to the three bodies' ids. The same vector as the bodies' measures one by one (a
    # kernel per id), also when a body is in two integrals of the form (compiled per id then)
    from dolfinx_forms.fem import jit_memo

    scene, phi, _ = _scene(nx=8)
    nc = len(scene.cell_tags.values)
    scene.cell_tags = dmesh.meshtags(
        scene.mesh, 2, np.arange(nc, dtype=np.int32), (1 + np.arange(nc) % 3).astype(np.int32)
    )
    cut = CutIntegration(scene, phi=phi)
    V = fem.VectorFunctionSpace(scene.mesh, ("Lagrange", 1))
    u, v = fem.Function(V), ufl.TestFunction(V)
    u.interpolate(lambda x: np.stack([0.1 * x[0] ** 2, 0.05 * x[0] * x[1]]))
    integrand = ufl.inner(LAW.stress(u), ufl.grad(v))
    form = integrand * cut.measure([1, 2, 3])
    assert len(form.integrals()) == 2
    assert min(i.subdomain_id() for i in form.integrals()) >= jit_memo.ALIAS_BASE
    per_body = sum(integrand * cut.measure(t) for t in (1, 2, 3))
    assert len(per_body.integrals()) == 6

    def vector(f):
        b = fem.petsc.assemble_vector(f)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        return b.array.copy()

    ref = vector(fem.form(per_body))
    assert np.abs(ref).max() > 0
    assert np.allclose(vector(cut.form(form)), ref, rtol=0, atol=1e-14 * np.abs(ref).max())
    # body 2 in the group and on its own: one kernel per id cannot be both, so per id
    twice = vector(cut.form(form + integrand * cut.measure(2)))
    ref2 = vector(fem.form(per_body + integrand * cut.measure(2)))
    assert np.allclose(twice, ref2, rtol=0, atol=1e-14 * np.abs(ref2).max())
    assert not np.allclose(twice, ref)
    # fem.form of the group's ids would integrate over no cell: refused (a CutIntegration
    # installs the memo that checks)
    with pytest.raises(RuntimeError, match="CutIntegration.form"):
        fem.form(integrand * cut.measure([1, 2]))


def test_body_force_is_the_inside_integral():
    # f = (1, x): total x-force = inside area, total y-force = int x over the inside
    scene, phi, kind = _scene(8, 5, lambda x: np.hypot(x[0] - 1.1, x[1] - 0.45) - 0.37)
    cut, V, _ = _forms(scene, phi)
    v = ufl.TestFunction(V)
    X = ufl.SpatialCoordinate(scene.mesh)
    b = fem.petsc.assemble_vector(
        fem.form(ufl.inner(ufl.as_vector((1.0, X[0])), v) * cut.measure())
    )
    pdofs = phi.function_space.dofmap.list.array.reshape(len(kind), 4)
    h2 = (2 / 8) * (1 / 5)
    area = h2 * _cpp.inside_fraction(phi.x.array[pdofs]).sum()
    f = b.array.reshape(-1, 2)
    assert f[:, 0].sum() == pytest.approx(area, rel=1e-13)
    q = _cpp.cut_quadrature(phi.x.array[pdofs], 4)  # int x over the inside, sub-triangles
    xg = scene.mesh.geometry.x[scene.mesh.geometry.dofmap.array.reshape(len(kind), 4)]
    cells = np.repeat(np.arange(len(kind)), np.diff(q["offsets"]))
    P = q["points"]
    x = (
        xg[cells, 0, 0]
        + P[:, 0] * (xg[cells, 1, 0] - xg[cells, 0, 0])
        + P[:, 1] * (xg[cells, 2, 0] - xg[cells, 0, 0])
    )  # affine map of the tensor cell
    moment = h2 * np.dot(q["weights"], x)
    assert f[:, 1].sum() == pytest.approx(moment, rel=1e-12)


@pytest.mark.parametrize("gamma", [0.0, 0.1])
def test_rigid_modes_zero_energy_and_ghost_penalty_linear_fields(gamma):
    # a slanted line and a circle cut the cells at arbitrary fractions
    scene, phi, kind = _scene(
        8,
        5,
        lambda x: np.minimum(x[1] - 0.31 * x[0] - 0.43, np.hypot(x[0] - 1.3, x[1] - 0.2) - 0.3),
    )
    assert np.sum(kind == CUT) > 5
    _, V, a = _forms(scene, phi, gamma)
    A = _matrix(a)
    modes = [
        lambda x: np.stack([1 + 0 * x[0], 0 * x[0]]),
        lambda x: np.stack([0 * x[0], 1 + 0 * x[0]]),
        lambda x: np.stack([-x[1], x[0]]),
    ]
    r = fem.Function(V)
    y = A.createVecLeft()
    for mode in modes:
        r.interpolate(mode)
        A.mult(r.vector, y)
        assert y.norm() <= 1e-12 * A.norm() * r.vector.norm()
    # a linear non-rigid field: the ghost penalty adds nothing (its gradient has no jumps)
    r.interpolate(lambda x: np.stack([0.3 * x[0] + 0.2 * x[1], -0.1 * x[0] + 0.5 * x[1]]))
    A0 = _matrix(_forms(scene, phi, 0.0)[2])
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
    scene.facet_tags = dmesh.meshtags(
        m, 1, np.sort(facets).astype(np.int32), np.full(len(facets), 7, np.int32)
    )
    cut, V, _ = _forms(scene, phi)
    X = ufl.SpatialCoordinate(m)
    b = fem.petsc.assemble_vector(cut.traction_form(V, ufl.as_vector((X[1], X[0] * X[1] + 2)), 7))
    f = b.array.reshape(-1, 2).sum(axis=0)
    assert f[0] == pytest.approx(0.53**2 / 2, rel=1e-13)
    assert f[1] == pytest.approx(2 * 0.53, rel=1e-13)
    # moment about the origin of the x-load: int y * y dy (the Q1 test functions carry it)
    y = V.tabulate_dof_coordinates()[:, 1]
    assert np.dot(b.array.reshape(-1, 2)[:, 0], y) == pytest.approx(0.53**3 / 3, rel=1e-13)


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
