"""Moment-fitted weights of FFCx's tensor Gauss rule on cut cells (_cpp.cut_moment_weights).

The reference is independent of the C++ clipping: the inside polygon is rebuilt here from the
vertex values in exact rational arithmetic (the straight contour between the linear edge
crossings, saddles decided by the centre value as in contact/cut_cell.h) and polynomials are
integrated over it exactly with sympy (Green's theorem). The points are basix's default
quadrilateral rule, the one FFCx uses, in basix's order.
"""


import basix
import numpy as np
import pytest
import sympy as sp
import ufl
from dolfinx import fem
from dolfinx import mesh as dmesh
from mpi4py import MPI

from dolfinx_forms import _cpp

X, Y, T = sp.symbols("X Y t")
CORNERS = [(0, 0), (1, 0), (0, 1), (1, 1)]  # tensor order
CCW = [0, 1, 3, 2]


def _gauss(q):
    x, w = basix.make_quadrature(basix.CellType.quadrilateral, q)
    return x, w


def inside_loops(phi):
    """Closed loops (lists of exact points, counter-clockwise) of the inside part {phi < 0}."""
    f = [sp.Rational(float(v)) for v in phi]
    inside = [v < 0 for v in f]

    def crossing(a, b):
        s = f[a] / (f[a] - f[b])
        return tuple(sp.Rational(c[0]) + s * (c[1] - c[0]) for c in zip(CORNERS[a], CORNERS[b]))

    poly, cross_at = [], {}
    for k in range(4):
        a, b = CCW[k], CCW[(k + 1) % 4]
        if inside[a]:
            poly.append(CORNERS[a])
        if inside[a] != inside[b]:
            cross_at[k] = crossing(a, b)
            poly.append(cross_at[k])
    if not poly:
        return []
    if len(cross_at) == 4 and sum(f) / 4 >= 0:
        # saddle, centre outside: each inside corner with its two neighbouring crossings
        return [
            [cross_at[(k - 1) % 4], CORNERS[CCW[k]], cross_at[k]]
            for k in range(4)
            if inside[CCW[k]]
        ]
    return [poly]


def exact_integral(p, loops):
    """int p over the loops by Green's theorem: int p dA = oint (int p dX) dY."""
    G = sp.integrate(p, X)
    total = sp.Integer(0)
    for loop in loops:
        for P, Q in zip(loop, loop[1:] + loop[:1]):
            dy = sp.Rational(Q[1]) - P[1]
            if dy == 0:
                continue
            g = sp.Poly(
                G.subs({X: P[0] + T * (Q[0] - P[0]), Y: P[1] + T * dy}, simultaneous=True) * dy, T
            ).integrate()
            total += g.eval(1) - g.eval(0)
    return total


def random_poly(rng, m):
    """A random polynomial in Q_{m-1}: sympy expression and numpy evaluator."""
    c = rng.uniform(-1, 1, (m, m))
    expr = sum(sp.Rational(c[a, b]) * X**a * Y**b for a in range(m) for b in range(m))
    return expr, lambda x: np.einsum(
        "ab,ka,kb->k", c, x[:, :1] ** np.arange(m), x[:, 1:] ** np.arange(m)
    )


def vertex_values(fn):
    return np.array([fn(np.array(c, float)) for c in CORNERS])


def straight_cuts(rng, n):
    out = []
    for _ in range(n):
        p0, th = rng.uniform(0, 1, 2), rng.uniform(0, 2 * np.pi)
        nrm = np.array([np.cos(th), np.sin(th)])
        out.append(vertex_values(lambda x: nrm @ (x - p0)))
    return out


def curved_cuts(rng, n):
    out = []
    while len(out) < n:
        c, r, s = rng.uniform(-0.5, 1.5, 2), rng.uniform(0.2, 1.5), rng.choice([-1, 1])
        phi = vertex_values(lambda x: s * (np.linalg.norm(x - c) - r))  # disc or its outside
        if phi.min() < 0 < phi.max():
            out.append(phi)
    return out


def saddle_cuts(rng, n):
    """Two discs at opposite corners: small radii leave the centre outside (two triangles),
    large radii connect the corners (hexagon)."""
    out = []
    for k in range(n):
        diag = [(0, 0), (1, 1)] if k % 2 else [(1, 0), (0, 1)]
        r = rng.uniform(0.3, 0.45, 2) if k % 4 < 2 else rng.uniform(0.6, 0.9, 2)
        cs = [np.array(d) + rng.uniform(-0.05, 0.05, 2) for d in diag]
        out.append(vertex_values(lambda x: min(np.linalg.norm(x - cs[i]) - r[i] for i in (0, 1))))
    return out


FAMILIES = {"straight": straight_cuts, "curved": curved_cuts, "saddle": saddle_cuts}


@pytest.mark.parametrize("family", FAMILIES)
@pytest.mark.parametrize("q", [2, 4, 6])
def test_weights_integrate_tensor_polynomials_exactly(q, family):
    m = (q + 2) // 2
    x, _ = _gauss(q)
    assert len(x) == m * m
    rng = np.random.default_rng(100 * q + len(family))
    phis = np.array(FAMILIES[family](rng, 12))
    if family == "saddle":  # both saddle resolutions are exercised
        assert np.all([(p < 0).sum() == 2 and (p[0] < 0) == (p[3] < 0) for p in phis])
        assert np.any(phis.mean(axis=1) >= 0) and np.any(phis.mean(axis=1) < 0)
    W = _cpp.cut_moment_weights(phis, x)
    assert W.shape == (len(phis), m * m)
    for phi, w in zip(phis, W):
        loops = inside_loops(phi)
        area = float(exact_integral(sp.Integer(1), loops))
        # the polygon rebuilt here is clip_square's
        assert area == pytest.approx(_cpp.inside_fraction(phi[None])[0], rel=1e-13, abs=1e-16)
        for _ in range(2):
            expr, f = random_poly(rng, m)
            assert w @ f(x) == pytest.approx(
                float(exact_integral(expr, loops)), rel=1e-13, abs=1e-14
            )


@pytest.mark.parametrize("q", [2, 4, 6])
def test_tiny_cuts_exact_and_bounded_weights(q):
    """Cut fractions 1e-2 .. 1e-8: corner triangles at v0 / v3 and strips along X = 0 / X = 1.

    The weights stay O(area) (|W| <= 2.5 area: Lagrange values at the cell's corners), so no
    blow-up. Accuracy is relative to the area for the corners; for the strips it is absolute:
    the crossings are reference coordinates in [0, 1], exact only to 1e-16 (strip X > 1 - a).
    """
    m = (q + 2) // 2
    x, _ = _gauss(q)
    rng = np.random.default_rng(q)
    for e in range(2, 9):
        a = 10.0**-e
        s = np.sqrt(2 * a)
        for phi, rel, ab in [
            ([-s, 1 - s, 1 - s, 2 - s], 1e-12, 0),
            ([2 - s, 1 - s, 1 - s, -s], 1e-12, 0),
            ([-a, 1 - a, -a, 1 - a], 1e-13, 1e-15),
            ([1 - a, -a, 1 - a, -a], 1e-13, 1e-15),
        ]:
            phi = np.array(phi)
            w = _cpp.cut_moment_weights(phi[None], x)[0]
            area = float(exact_integral(sp.Integer(1), inside_loops(phi)))
            assert area == pytest.approx(a, rel=1e-6)
            assert np.abs(w).max() <= 2.5 * area
            expr, f = random_poly(rng, m)
            exact = float(exact_integral(expr, inside_loops(phi)))
            assert w @ f(x) == pytest.approx(exact, rel=rel, abs=ab), (phi, e)


@pytest.mark.parametrize("q", [2, 4, 6, 10])
def test_full_cell_gives_basix_weights_empty_cell_zeros(q):
    x, w = _gauss(q)
    W = _cpp.cut_moment_weights(np.array([[-1.0, -0.5, -2.0, -0.1], [0.0, 1.0, 2.0, 0.5]]), x)
    assert np.abs(W[0] - w).max() <= 4e-16
    assert np.all(W[1] == 0)
    # the order of the points is free: a permutation permutes the weights
    perm = np.random.default_rng(q).permutation(len(w))
    Wp = _cpp.cut_moment_weights(np.array([[-0.3, 0.4, -0.2, 0.6]]), x[perm])
    Wr = _cpp.cut_moment_weights(np.array([[-0.3, 0.4, -0.2, 0.6]]), x)
    assert np.abs(Wp[0] - Wr[0, perm]).max() <= 1e-16


def test_shape_errors():
    x, _ = _gauss(4)
    with pytest.raises(ValueError, match=r"phi: expected an array of shape \(n, 4\)"):
        _cpp.cut_moment_weights(np.zeros((2, 3)), x)
    with pytest.raises(ValueError, match=r"points: expected an array of shape \(nq, 2\)"):
        _cpp.cut_moment_weights(np.zeros((2, 4)), x.T)
    with pytest.raises(ValueError, match="full tensor grid"):
        _cpp.cut_moment_weights(np.zeros((2, 4)), x[:-1])


def test_elastic_energy_of_q1_fields_exact_with_three_points():
    # an hx x hy rectangle cut by a circle (phi on the reference square); Q1 vector field u
    hx, hy = sp.Rational(7, 10), sp.Rational(2, 5)
    E, nu = sp.Integer(3), sp.Rational(3, 10)
    mu, lmbda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    rng = np.random.default_rng(11)
    U = rng.uniform(-1, 1, (4, 2))
    phi = vertex_values(lambda x: np.hypot(x[0] - 0.9, x[1] - 1.1) - 0.8)
    assert phi.min() < 0 < phi.max()
    N = [(1 - X) * (1 - Y), X * (1 - Y), (1 - X) * Y, X * Y]
    u = [sum(sp.Rational(U[n, i]) * N[n] for n in range(4)) for i in range(2)]
    g = [[sp.diff(u[i], X) / hx, sp.diff(u[i], Y) / hy] for i in range(2)]  # grad u, physical
    eps = [[(g[i][j] + g[j][i]) / 2 for j in range(2)] for i in range(2)]
    psi = sp.expand(
        mu * sum(eps[i][j] ** 2 for i in range(2) for j in range(2))
        + lmbda / 2 * (eps[0][0] + eps[1][1]) ** 2
    )  # in Q2
    exact = float(exact_integral(psi, inside_loops(phi)) * hx * hy)
    psi_np = sp.lambdify((X, Y), psi, "numpy")
    errors = {}
    for q in (2, 4):
        x, _ = _gauss(q)
        w = _cpp.cut_moment_weights(phi[None], x)[0]
        errors[q] = abs(w @ psi_np(x[:, 0], x[:, 1]) * float(hx * hy) - exact) / exact
    assert errors[4] < 1e-13, errors
    assert errors[2] > 1e-6, errors  # m = 2 is not enough (Q2 integrand): the check has teeth

    # the quadratic form itself: K = sum_k W_k B_k^T D B_k gives the exact energy of the field
    # and is positive semi-definite despite negative weights
    x, _ = _gauss(4)
    w = _cpp.cut_moment_weights(phi[None], x)[0]
    assert w.min() < 0  # this cut does produce negative weights
    hxf, hyf, muf, lf = (float(v) for v in (hx, hy, mu, lmbda))
    K = np.zeros((8, 8))
    for (Xk, Yk), wk in zip(x, w):
        dN = np.array(
            [
                [-(1 - Yk) / hxf, -(1 - Xk) / hyf],
                [(1 - Yk) / hxf, -Xk / hyf],
                [-Yk / hxf, (1 - Xk) / hyf],
                [Yk / hxf, Xk / hyf],
            ]
        )
        B = np.zeros((3, 8))  # Voigt (exx, eyy, 2 exy), dof = node * 2 + component
        B[0, 0::2], B[1, 1::2] = dN[:, 0], dN[:, 1]
        B[2, 0::2], B[2, 1::2] = dN[:, 1], dN[:, 0]
        D = np.array([[2 * muf + lf, lf, 0], [lf, 2 * muf + lf, 0], [0, 0, muf]])
        K += wk * hxf * hyf * B.T @ D @ B
    assert np.linalg.eigvalsh(K).min() >= -1e-13 * np.abs(K).max()
    assert 0.5 * U.ravel() @ K @ U.ravel() == pytest.approx(exact, rel=1e-13)


def test_factors_follow_ffcx_points_in_a_quadrature_function():
    """End to end, as dolfinx_forms.fem.cut uses the weights: factor W_k / w_k in a Quadrature
    function (dof k <-> basix point k), phi from the P1 dofmap (reference vertex order)."""
    q = 4
    msh = dmesh.create_rectangle(
        MPI.COMM_WORLD, [[0, 0], [2, 1]], [2, 2], dmesh.CellType.quadrilateral
    )
    points, wref = _gauss(q)
    F = fem.Function(
        fem.FunctionSpace(
            msh, ufl.FiniteElement("Quadrature", msh.ufl_cell(), q, quad_scheme="default")
        )
    )
    P = fem.FunctionSpace(msh, ("Lagrange", 1))
    phi = fem.Function(P)
    phi.interpolate(lambda x: 0.9 * x[0] + 0.35 * x[1] - 1.1)
    ncells = msh.topology.index_map(2).size_local
    pv = phi.x.array[P.dofmap.list.array.reshape(-1, 4)[:ncells]]
    W = _cpp.cut_moment_weights(pv, points)
    F.x.array[F.function_space.dofmap.list.array.reshape(-1, len(wref))[:ncells]] = W / wref
    x = ufl.SpatialCoordinate(msh)
    value = fem.assemble_scalar(
        fem.form(F * x[0] ** 2 * x[1] * ufl.dx(metadata={"quadrature_degree": q}))
    )
    # exact: per cell, the reference polygon, the bilinear geometry map and |det J|
    N = [(1 - X) * (1 - Y), X * (1 - Y), (1 - X) * Y, X * Y]
    exact = sp.Integer(0)
    for c in range(ncells):
        g = msh.geometry.x[msh.geometry.dofmap.links(c), :2]
        xp = [sum(N[i] * sp.Rational(g[i, d]) for i in range(4)) for d in range(2)]
        det = sp.Matrix([[sp.diff(xp[i], v) for v in (X, Y)] for i in range(2)]).det()
        exact += exact_integral(sp.expand(xp[0] ** 2 * xp[1] * abs(det)), inside_loops(pv[c]))
    assert np.sum((pv < 0).any(axis=1) & (pv >= 0).any(axis=1)) >= 2  # some cells are cut
    assert value == pytest.approx(float(exact), rel=1e-13)
