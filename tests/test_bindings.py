"""The safe binding layer (issue 28, item 5): every array a binding reads or writes is checked.

A float32 array, an index array of another dtype or out of int32, an index out of the range of
the array it indexes, a non-contiguous or read-only output, or a wrong shape raises ValueError
naming the binding and the argument (cpp_contact/python/array.h), never a silent cast or copy;
int32 and int64 indices are both accepted. A correct call gives the reference result.
"""

import numpy as np
import pytest
from dolfinx import mesh as dmesh
from dolfinx import cpp as _dcpp
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_forms import _cpp

NNODES = 12  # nodes of the toy "mesh" of the assembly tests (block size 2)


def strided(a):
    """A non-contiguous view with the values (and shape) of a."""
    b = np.zeros(a.shape + (2,), a.dtype)
    b[..., 0] = a
    v = b[..., 0]
    assert not v.flags.c_contiguous or v.size <= 1
    return v


def quadrature_data(rng, nq=20, ni=3, nj=4):
    theta = rng.uniform(0, 2 * np.pi, nq)
    n = np.c_[np.cos(theta), np.sin(theta)]
    t = np.c_[-n[:, 1], n[:, 0]]
    dofs_i = np.array([rng.choice(NNODES // 2, ni, replace=False) for _ in range(nq)], np.int32)
    dofs_j = np.array(
        [NNODES // 2 + rng.choice(NNODES // 2, nj, replace=False) for _ in range(nq)], np.int32
    )
    bi = rng.uniform(0.1, 1, (nq, ni))
    bj = rng.uniform(0.1, 1, (nq, nj))
    bi /= bi.sum(1, keepdims=True)
    bj /= bj.sum(1, keepdims=True)
    return [rng.uniform(0.5, 1, nq), n, t, rng.uniform(-0.02, 0.02, nq), dofs_i, dofs_j, bi, bj]


def frictionless_residual(data, eps_n, u):
    """Reference residual of eq 48 with mu = 0 at the points: r += w tau_n B_n^T."""
    w, n, _, g0, di, dj, bi, bj = data
    U = u.reshape(-1, 2)
    jump = np.einsum("pa,pac->pc", bj, U[dj]) - np.einsum("pa,pac->pc", bi, U[di])
    g_n = g0 + np.sum(jump * n, axis=1)
    tau_n = np.minimum(g_n, 0.0) / eps_n
    r = np.zeros_like(U)
    for p in range(len(w)):
        np.add.at(r, dj[p], w[p] * tau_n[p] * bj[p][:, None] * n[p])
        np.add.at(r, di[p], -w[p] * tau_n[p] * bi[p][:, None] * n[p])
    return r.ravel(), g_n


@pytest.fixture
def assembly():
    rng = np.random.default_rng(5)
    data = quadrature_data(rng)
    u = rng.uniform(-0.02, 0.02, 2 * NNODES)
    return data, _cpp.ContactQuadrature(*data), u


def test_assemble_contact_result(assembly):
    data, q, u = assembly
    b = np.zeros_like(u)
    s = _cpp.assemble_contact(q, 1e-2, 1e-2, 0.0, u, np.zeros(0), b)
    r, g_n = frictionless_residual(data, 1e-2, u)
    assert np.any(g_n < 0) and np.any(g_n > 0)  # open and closed points
    np.testing.assert_allclose(s["g_n"], g_n, rtol=0, atol=1e-15)
    np.testing.assert_allclose(b, r, rtol=1e-13, atol=1e-15)
    # int64 dofs (numpy's default) give the same quadrature
    data64 = data[:4] + [data[4].astype(np.int64), data[5].astype(np.int64)] + data[6:]
    b64 = np.zeros_like(u)
    _cpp.assemble_contact(_cpp.ContactQuadrature(*data64), 1e-2, 1e-2, 0.0, u, np.zeros(0), b64)
    np.testing.assert_array_equal(b64, b)


@pytest.mark.parametrize("which", ["u", "gtp_old", "g_n_shift"])
def test_assemble_contact_float32_input(assembly, which):
    _, q, u = assembly
    args = {"u": u, "gtp_old": np.zeros(len(q)), "g_n_shift": np.zeros(len(q))}
    args[which] = args[which].astype(np.float32)
    with pytest.raises(ValueError, match=f"assemble_contact: {which}: expected float64, got "):
        _cpp.assemble_contact(
            q, 1e-2, 1e-2, 0.4, args["u"], args["gtp_old"], g_n_shift=args["g_n_shift"]
        )


def test_assemble_contact_output(assembly):
    _, q, u = assembly
    gtp = np.zeros(len(q))
    f = "assemble_contact: b: "
    with pytest.raises(ValueError, match=f + "expected a C-contiguous array"):
        _cpp.assemble_contact(q, 1e-2, 1e-2, 0.4, u, gtp, strided(np.zeros_like(u)))
    ro = np.zeros_like(u)
    ro.flags.writeable = False
    with pytest.raises(ValueError, match=f + "expected a writeable array"):
        _cpp.assemble_contact(q, 1e-2, 1e-2, 0.4, u, gtp, ro)
    with pytest.raises(ValueError, match=f + "expected float64, got float32"):
        _cpp.assemble_contact(q, 1e-2, 1e-2, 0.4, u, gtp, np.zeros(len(u), np.float32))
    with pytest.raises(ValueError, match=f + "expected 24 entries, got 22"):
        _cpp.assemble_contact(q, 1e-2, 1e-2, 0.4, u, gtp, np.zeros(len(u) - 2))
    with pytest.raises(ValueError, match=f + "expected a numpy array to write into, got list"):
        _cpp.assemble_contact(q, 1e-2, 1e-2, 0.4, u, gtp, [0.0] * len(u))


def test_assemble_contact_shapes_and_ranges(assembly):
    _, q, u = assembly
    gtp = np.zeros(len(q))
    with pytest.raises(
        ValueError, match=r"assemble_contact: gtp_old: expected an array of shape \(20,\)"
    ):
        _cpp.assemble_contact(q, 1e-2, 1e-2, 0.4, u, np.zeros(len(q) + 1))
    with pytest.raises(ValueError, match="assemble_contact: u: expected an array of shape"):
        _cpp.assemble_contact(q, 1e-2, 1e-2, 0.4, u.reshape(-1, 2), gtp)
    with pytest.raises(ValueError, match="assemble_contact: u: expected a C-contiguous array"):
        _cpp.assemble_contact(q, 1e-2, 1e-2, 0.4, strided(u), gtp)
    # a u too short for the dofs: caught before the kernel reads u[2 dof + c]
    with pytest.raises(ValueError, match=r"dofs_j \(blocks of u\): index \d+ out of range \[0, 6"):
        _cpp.assemble_contact(q, 1e-2, 1e-2, 0.4, u[:12], gtp)


def test_quadrature_arguments():
    rng = np.random.default_rng(1)
    data = quadrature_data(rng)
    f = "ContactQuadrature: "
    bad = list(data)
    bad[1] = data[1].astype(np.float32)
    with pytest.raises(ValueError, match=f + "normals: expected float64, got float32"):
        _cpp.ContactQuadrature(*bad)
    bad = list(data)
    bad[4] = data[4].astype(np.int64) + 2**40
    with pytest.raises(ValueError, match=f + "dofs_i: index 1099511627\\d+ does not fit int32"):
        _cpp.ContactQuadrature(*bad)
    bad = list(data)
    bad[4] = data[4].astype(np.float64)
    with pytest.raises(ValueError, match=f + "dofs_i: expected int32 or int64 indices, got float"):
        _cpp.ContactQuadrature(*bad)
    bad = list(data)
    bad[5] = data[5].astype(np.int16)
    with pytest.raises(ValueError, match=f + "dofs_j: expected int32 or int64 indices, got int16"):
        _cpp.ContactQuadrature(*bad)
    bad = list(data)
    bad[5] = data[5].copy()
    bad[5][3, 1] = -1
    with pytest.raises(ValueError, match=f + r"dofs_j: index -1 out of range \[0, "):
        _cpp.ContactQuadrature(*bad)
    bad = list(data)
    bad[6] = data[6][:, :2].copy()
    with pytest.raises(
        ValueError, match=f + r"basis_i: expected an array of shape \(20, 3\), got \(20, 2\)"
    ):
        _cpp.ContactQuadrature(*bad)
    bad = list(data)
    bad[2] = np.asfortranarray(data[2])
    with pytest.raises(ValueError, match=f + "tangents: expected a C-contiguous array"):
        _cpp.ContactQuadrature(*bad)
    q = _cpp.ContactQuadrature(*data)
    with pytest.raises(ValueError, match="set_multiplier_nodes: nodes: index -2 out of range"):
        q.set_multiplier_nodes(np.full((20, 2), -2), np.full((20, 2), 0.5))
    with pytest.raises(ValueError, match="set_multiplier_nodes: weights: expected float64"):
        q.set_multiplier_nodes(np.zeros((20, 2), np.int32), np.full((20, 2), 0.5, np.float32))
    assert q.num_law_points == 20  # unchanged by the refused calls
    nodes, weights = np.c_[np.arange(20) // 2, np.full(20, -1)], np.c_[np.ones(20), np.zeros(20)]
    q.set_multiplier_nodes(nodes, weights)
    assert q.num_law_points == 10
    with pytest.raises(ValueError, match=r"u_j_prescribed: expected an array of shape \(20, 2\)"):
        q.u_j_prescribed = np.zeros((20, 3))


def petsc_matrix(nodes):
    A = PETSc.Mat().createAIJ(
        (2 * nodes, 2 * nodes), bsize=2, nnz=2 * nodes, comm=PETSc.COMM_SELF
    )
    lg = PETSc.LGMap().create(np.arange(nodes, dtype=np.int32), bsize=2, comm=PETSc.COMM_SELF)
    A.setLGMap(lg, lg)
    A.setUp()
    return A


def test_matrix_dofs_checked(assembly):
    _, q, u = assembly
    with pytest.raises(ValueError, match=r"add_coupling_zeros: .*dofs_j .*out of range \[0, 8\)"):
        _cpp.add_coupling_zeros(petsc_matrix(8), q)
    A = petsc_matrix(NNODES)
    _cpp.add_coupling_zeros(A, q)
    A.assemble()
    with pytest.raises(ValueError, match=r"assemble_contact: .*dofs_j .*out of range \[0, 8\)"):
        _cpp.assemble_contact(q, 1e-2, 1e-2, 0.0, u, np.zeros(0), None, petsc_matrix(8))
    s = _cpp.assemble_contact(q, 1e-2, 1e-2, 0.0, u, np.zeros(0), None, A)
    A.assemble()
    assert A.norm() > 0 and np.any(s["state"] > 0)


def test_sparsity_patterns_checked():
    msh = dmesh.create_unit_square(MPI.COMM_SELF, 2, 2, dmesh.CellType.quadrilateral)
    V = fem.VectorFunctionSpace(msh, ("Lagrange", 1))
    blocks = V.dofmap.index_map.size_local + V.dofmap.index_map.num_ghosts  # 9
    pattern = _dcpp.fem.create_sparsity_pattern(
        msh.topology, [V.dofmap._cpp_object, V.dofmap._cpp_object], {_dcpp.fem.IntegralType.cell}
    )
    msg = rf"insert_blocks: dofs: index 9 out of range \[0, {blocks}\)"
    with pytest.raises(ValueError, match=msg):
        _cpp.insert_blocks(pattern, np.array([[0, 1, 9]]))
    with pytest.raises(
        ValueError, match=r"insert_blocks: dofs: expected an array of shape \(n, m\)"
    ):
        _cpp.insert_blocks(pattern, np.array([0, 1, 8]))
    with pytest.raises(ValueError, match="insert_blocks: dofs: expected int32 or int64"):
        _cpp.insert_blocks(pattern, np.array([[0.0, 1.0]]))
    _cpp.insert_blocks(pattern, np.array([[0, 8]]))  # int64 accepted
    rng = np.random.default_rng(2)
    data = quadrature_data(rng, nq=4)  # dofs up to 11 > 9 blocks
    with pytest.raises(ValueError, match=r"insert_coupling: .*dofs_j .*out of range \[0, 9\)"):
        _cpp.insert_coupling(pattern, _cpp.ContactQuadrature(*data))
    data[5] = data[5] - 3
    _cpp.insert_coupling(pattern, _cpp.ContactQuadrature(*data))
    pattern.assemble()
    assert pattern.num_nonzeros > 0


def quad_mesh():
    """A 2 x 1 quadrilateral mesh in DOLFINx vertex order (0 1 / 2 3 tensor order)."""
    x = np.array([[0, 0], [1, 0], [2, 0], [0, 1], [1, 1], [2, 1]], float)
    cells = np.array([[0, 1, 3, 4], [1, 2, 4, 5]], np.int32)
    return x, cells


def test_locator():
    x, cells = quad_mesh()
    pts = np.array([[0.25, 0.5], [1.5, 0.75]])
    r = _cpp.CellLocator(x, cells).locate(pts, 0.0)
    np.testing.assert_array_equal(r["cells"], [0, 1])
    np.testing.assert_allclose(r["X"], [[0.25, 0.5], [0.5, 0.75]], atol=1e-14)
    r64 = _cpp.CellLocator(x, cells.astype(np.int64), np.array([1, 0])).locate(pts, 0.0)
    np.testing.assert_array_equal(r64["cells"], r["cells"])
    np.testing.assert_array_equal(r64["X"], r["X"])
    f = "CellLocator: "
    with pytest.raises(ValueError, match=f + "x: expected float64, got float32"):
        _cpp.CellLocator(x.astype(np.float32), cells)
    with pytest.raises(ValueError, match=f + r"cells: index 6 out of range \[0, 6\) \(entry 7\)"):
        _cpp.CellLocator(x, np.array([[0, 1, 3, 4], [1, 2, 4, 6]]))
    with pytest.raises(ValueError, match=f + r"subset: index 2 out of range \[0, 2\)"):
        _cpp.CellLocator(x, cells, np.array([0, 2], np.int32))
    with pytest.raises(ValueError, match=f + "cells: index 4294967296 does not fit int32"):
        _cpp.CellLocator(x, cells.astype(np.int64) + 2**32)
    with pytest.raises(ValueError, match=f + "cells: expected int32 or int64 indices, got uint32"):
        _cpp.CellLocator(x, cells.astype(np.uint32))
    with pytest.raises(
        ValueError, match=f + r"x: expected an array of shape \(nv, 2\) or \(nv, 3\), got"
    ):
        _cpp.CellLocator(x[:, 0].copy(), cells)
    loc = _cpp.CellLocator(x, cells)
    with pytest.raises(
        ValueError, match=r"CellLocator.locate: points: expected an array of shape \(n, 2\)"
    ):
        loc.locate(np.zeros((2, 3)), 0.0)
    with pytest.raises(ValueError, match="CellLocator.locate: points: expected a C-contiguous"):
        loc.locate(np.c_[pts, pts][:, ::2], 0.0)


def test_mls():
    rng = np.random.default_rng(3)
    src = rng.uniform(0, 1, (200, 2))
    linear = 1.0 + 2.0 * src[:, 0] - 3.0 * src[:, 1]
    tgt = rng.uniform(0.2, 0.8, (10, 2))
    mls = _cpp.MLSProjector(src, 0.15)
    r = mls.project(linear, tgt)  # a linear basis reproduces a linear field
    np.testing.assert_allclose(r["values"], 1.0 + 2.0 * tgt[:, 0] - 3.0 * tgt[:, 1], atol=1e-11)
    f = "MLSProjector.project: "
    with pytest.raises(ValueError, match="MLSProjector: sources: expected float64, got float32"):
        _cpp.MLSProjector(src.astype(np.float32), 0.15)
    with pytest.raises(ValueError, match=f + "values: expected float64, got float32"):
        mls.project(linear.astype(np.float32), tgt)
    with pytest.raises(
        ValueError, match=f + r"values: expected an array of shape \(200,\) or \(200, m\)"
    ):
        mls.project(linear[:-1], tgt)
    with pytest.raises(ValueError, match=f + "targets: expected a C-contiguous array"):
        mls.project(linear, strided(tgt))
    with pytest.raises(
        ValueError, match=f + r"targets: expected an array of shape \(n, 2\), got \(10, 3\)"
    ):
        mls.project(linear, np.zeros((10, 3)))
    with pytest.raises(ValueError, match="quadratic_spline_weight: r: expected float64, got int64"):
        _cpp.quadratic_spline_weight(np.arange(3))
    with pytest.raises(ValueError, match=f + "threads: must be >= 1, got 0"):
        mls.project(linear, tgt, 0)


def test_mls_threads_bit_identical():
    """The projection shares its targets among threads in runs fixed by the targets alone:
    the values are the same bit for bit for 1, 2 and 3 threads (cell-ordered Gauss points,
    as the MPM projects them)."""
    rng = np.random.default_rng(4)
    h = 0.025  # 1600 runs: enough for 3 threads (at least 256 runs each)
    g, w = np.polynomial.legendre.leggauss(3)
    g = 0.5 * (g + 1)
    corners = np.stack(np.meshgrid(np.arange(0, 1, h), np.arange(0, 1, h)), -1).reshape(-1, 2)
    gauss = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    tgt = (corners[:, None] + h * gauss[None]).reshape(-1, 2)
    src = tgt + rng.uniform(-0.2 * h, 0.2 * h, tgt.shape)
    vals = rng.normal(size=(len(src), 3))
    mls = _cpp.MLSProjector(src, h)
    one = mls.project(vals, tgt, 1)
    for n in (2, 3):
        r = mls.project(vals, tgt, n)
        assert np.array_equal(r["values"], one["values"])
        assert np.array_equal(r["neighbours"], one["neighbours"])


def test_worker_threads(monkeypatch):
    from mpi4py import MPI

    from dolfinx_forms.common import worker_threads

    monkeypatch.setenv("ILS_THREADS", "3")
    assert worker_threads(MPI.COMM_WORLD) == 3
    for bad in ("0", "two"):
        monkeypatch.setenv("ILS_THREADS", bad)
        with pytest.raises(ValueError, match="ILS_THREADS must be an integer >= 1"):
            worker_threads(MPI.COMM_WORLD)
    monkeypatch.delenv("ILS_THREADS")
    assert worker_threads(MPI.COMM_WORLD) >= 1


def test_evolution():
    d_minus, d_plus = _cpp.weno5_derivatives(0.5 * np.arange(12.0), 0.1)
    np.testing.assert_allclose(d_minus, 5.0, rtol=1e-12)
    np.testing.assert_allclose(d_plus, 5.0, rtol=1e-12)
    with pytest.raises(ValueError, match="weno5_derivatives: line: expected float64, got float32"):
        _cpp.weno5_derivatives(np.arange(12, dtype=np.float32), 0.1)
    with pytest.raises(
        ValueError, match=r"weno5_derivatives: line: expected an array of shape \(n,\)"
    ):
        _cpp.weno5_derivatives(np.zeros((3, 4)), 0.1)
    g = _cpp.StructuredGrid.uniform([0.0, 0.0], [1.0, 1.0], [4, 4])
    xy = g.nodes()
    phi = xy[:, 0] - 0.5
    known = phi < 0
    values = np.where(known, xy[:, 1], 0.0)
    out = _cpp.extend_normal(g, phi, known, values)
    np.testing.assert_allclose(out, xy[:, 1], atol=1e-14)  # constant along the normal (x)
    f = "extend_normal: "
    with pytest.raises(ValueError, match=f + "known: expected bool or int8 flags, got float64"):
        _cpp.extend_normal(g, phi, known.astype(float), values)
    with pytest.raises(ValueError, match=f + "phi: expected float64, got float32"):
        _cpp.extend_normal(g, phi.astype(np.float32), known, values)
    with pytest.raises(ValueError, match=f + "values: expected a C-contiguous array"):
        _cpp.extend_normal(g, phi, known, strided(values))
    with pytest.raises(ValueError, match=f + "known: expected 25 entries, got 24"):
        _cpp.extend_normal(g, phi, known[:-1], values)
    ls = _cpp.LevelSet(g, phi)
    with pytest.raises(
        ValueError, match=r"advect_levelset: velocity: expected an array of shape \(25, 2\)"
    ):
        _cpp.advect_levelset(ls, np.zeros((24, 2)), 0.1)


def test_cut():
    phi = np.array([[-1.0, -1.0, -1.0, -1.0], [1.0, 1.0, 1.0, 1.0], [-1.0, 1.0, -1.0, 1.0]])
    np.testing.assert_allclose(_cpp.inside_fraction(phi), [1.0, 0.0, 0.5], atol=1e-15)
    q = _cpp.cut_quadrature(phi, 2)
    np.testing.assert_array_equal(q["offsets"][[0, 2]], [0, q["offsets"][1]])
    np.testing.assert_allclose(np.add.reduceat(q["weights"], [0, q["offsets"][2]]), [1.0, 0.5])
    with pytest.raises(ValueError, match="cut_quadrature: phi: expected float64, got float32"):
        _cpp.cut_quadrature(phi.astype(np.float32), 2)
    with pytest.raises(
        ValueError, match=r"inside_fraction: phi: expected an array of shape \(n, 4\), got"
    ):
        _cpp.inside_fraction(phi[:, :3].copy())
    with pytest.raises(ValueError, match="cell_contours: phi: expected a C-contiguous array"):
        _cpp.cell_contours(phi[:, ::-1])
    x = np.array([[0.25, 0.25], [0.75, 0.25], [0.25, 0.75], [0.75, 0.75]])
    w = _cpp.cut_moment_weights(phi, x)
    np.testing.assert_allclose(w.sum(axis=1), [1.0, 0.0, 0.5], atol=1e-14)
    with pytest.raises(ValueError, match="cut_moment_weights: points: expected a C-contiguous"):
        _cpp.cut_moment_weights(phi, x.T.copy().T)


def test_schur():
    rng = np.random.default_rng(4)
    n, m = 8, 3
    M = rng.uniform(-1, 1, (n, n))
    K = M @ M.T + n * np.eye(n)  # SPD
    A = PETSc.Mat().createAIJ((n, n), nnz=n, comm=PETSc.COMM_SELF)
    A.setUp()
    A.setValues(range(n), range(n), K.ravel())
    A.assemble()
    c = np.arange(n - m, n, dtype=np.int32)
    i = np.arange(n - m)
    IS = PETSc.IS().createGeneral(c, comm=PETSc.COMM_SELF)
    F, S0 = _cpp.schur_factor(A, IS, False)
    ref = K[np.ix_(c, c)] - K[np.ix_(c, i)] @ np.linalg.solve(K[np.ix_(i, i)], K[np.ix_(i, c)])
    np.testing.assert_allclose(S0, ref, rtol=1e-12, atol=1e-12)
    D = np.diag([1.0, 2.0, 3.0])
    f = "schur_update: S: "
    with pytest.raises(ValueError, match=f + "expected float64, got float32"):
        _cpp.schur_update(F, (S0 + D).astype(np.float32))
    # the shape is checked with the factor's Schur complement taken: it is given back
    with pytest.raises(ValueError, match=f + r"expected an array of shape \(3, 3\), got \(2, 3\)"):
        _cpp.schur_update(F, (S0 + D)[:2].copy())
    with pytest.raises(ValueError, match=f + "expected a C-contiguous array"):
        _cpp.schur_update(F, (S0 + D).T)
    _cpp.schur_update(F, S0 + D)  # the factor still works after the refused calls
    J = K.copy()
    J[np.ix_(c, c)] += D
    rhs = rng.uniform(-1, 1, n)
    b, xs = A.createVecs()
    b.array[:] = rhs
    F.solve(b, xs)
    np.testing.assert_allclose(xs.array, np.linalg.solve(J, rhs), rtol=1e-10)


def test_geometry_and_laws():
    with pytest.raises(ValueError, match="Shape.__call__: points: expected float64, got float32"):
        _cpp.Circle((0.0, 0.0), 1.0)(np.zeros((2, 2), np.float32))
    np.testing.assert_allclose(_cpp.Circle((0.0, 0.0), 1.0)([[0.0, 0.0], [2.0, 0.0]]), [-1.0, 1.0])
    with pytest.raises(ValueError, match="candidate_pairs: boxes: expected float64, got int64"):
        _cpp.candidate_pairs(np.array([[0, 0, 1, 1]]))
    g_n = np.array([-0.1, 0.2])
    r = _cpp.return_mapping(g_n, np.zeros(2), np.zeros(2), 0.1, 0.1, 0.3)
    np.testing.assert_allclose(r["tau_n"], [-1.0, 0.0])
    with pytest.raises(ValueError, match="return_mapping: g_t: expected float64, got float32"):
        _cpp.return_mapping(g_n, np.zeros(2, np.float32), np.zeros(2), 0.1, 0.1, 0.3)
    with pytest.raises(ValueError, match=r"return_mapping: gtp_old: expected the shape of g_t"):
        _cpp.return_mapping(g_n, np.zeros(2), np.zeros((2, 1)), 0.1, 0.1, 0.3)
    h = _cpp.FrictionHistory(2, 1)
    with pytest.raises(ValueError, match="FrictionHistory: trial: expected a C-contiguous array"):
        h.trial = strided(np.ones(2))
    g = _cpp.StructuredGrid.uniform([0.0, 0.0], [1.0, 1.0], [4, 4])
    phi = _cpp.LevelSet(g, g.nodes()[:, 0] - 0.5)
    with pytest.raises(ValueError, match=r"segment_quadrature: cells: index 16 out of range"):
        _cpp.segment_quadrature(phi, np.zeros((1, 2, 2)), np.array([16]), 2)
    with pytest.raises(
        ValueError, match=r"segment_quadrature: segments: expected an array of shape \(1, 2, 2"
    ):
        _cpp.segment_quadrature(phi, np.zeros((2, 2, 2)), np.array([3]), 2)
    with pytest.raises(ValueError, match=r"LevelSet: values: expected an array of shape \(5, 5\)"):
        _cpp.LevelSet(g, np.zeros((5, 4)))
    with pytest.raises(ValueError, match=r"LevelSet: values: expected an array of shape \(25,\)"):
        _cpp.LevelSet(g, np.zeros(24))
