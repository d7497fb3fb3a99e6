"""UFL bulk laws on a user-built scene: isotropic limit of the orthotropic law, linearisation of
neo-Hookean, and a neo-Hookean block under a rigid flat punch (linear at small load, quadratic
Newton convergence at large load)."""

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh as dmesh
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_forms import Box
from dolfinx_forms.fem.boundary import Dirichlet
from dolfinx_forms.fem.laws import LinearElastic, NeoHookean, OrthotropicElastic
from dolfinx_forms.mesh.scene import Body, Scene, tag_boundaries
from dolfinx_forms.solvers.newton import NewtonOptions
from dolfinx_forms.solvers.options import options
from dolfinx_forms.solvers.problem import ContactProblem

E, NU = 1000.0, 0.3
W, H, A = 2.0, 1.0, 0.25  # block [-W/2, W/2] x [0, H], punch half-width A


def block_scene(n=16, cell=dmesh.CellType.triangle, comm=MPI.COMM_WORLD):
    """One body, no contact pair: the block with its bottom, the punch and the top outside it."""
    m = dmesh.create_rectangle(comm, [[-W / 2, 0], [W / 2, H]], [2 * n, n], cell)
    ncells = m.topology.index_map(2).size_local + m.topology.index_map(2).num_ghosts
    values = np.ones(ncells, np.int32)
    body = Body("block", 1, Box([-W / 2, 0], [W / 2, H]), np.array([[-W / 2, 0], [W / 2, H]]))
    tol = 1e-9
    markers = {
        "bottom": (1, lambda x: np.isclose(x[1], 0, atol=tol)),
        "punch": (2, lambda x: np.isclose(x[1], H, atol=tol) & (np.abs(x[0]) <= A + tol)),
    }
    facet_tags, boundaries = tag_boundaries(m, values, [body], markers)
    cell_tags = dmesh.meshtags(m, 2, np.arange(ncells, dtype=np.int32), values)
    return Scene(
        m,
        cell_tags,
        facet_tags,
        boundaries,
        [body],
        [],
        H / n,
        "triangle" if cell == dmesh.CellType.triangle else "quadrilateral",
    )


def punch(scene, law, depth, steps=1):
    bcs = [
        Dirichlet("bottom", None, 0.0),
        Dirichlet("punch", 0, 0.0),
        Dirichlet("punch", 1, lambda lam: -lam * depth),
    ]
    p = ContactProblem(
        scene,
        {1: law},
        dirichlet=bcs,
        log=lambda *a: None,
        **options(newton=NewtonOptions(rtol=1e-11)),
    )
    p.solve(steps)
    return p


def matrix(law, scene):
    V = fem.VectorFunctionSpace(scene.mesh, ("Lagrange", 1))
    u, v, du = fem.Function(V), ufl.TestFunction(V), ufl.TrialFunction(V)
    dx = ufl.Measure("dx", metadata={"quadrature_degree": 2})
    A = fem.petsc.assemble_matrix(fem.form(ufl.derivative(law.residual(u, v, dx), u, du)))
    A.assemble()
    return A.convert("dense").getDenseArray()


def test_orthotropic_isotropic_limit_and_rotation():
    scene = block_scene(4)
    G = E / (2 * (1 + NU))
    iso = OrthotropicElastic(E, E, E, NU, NU, NU, G, angle=40.0)  # rotation-invariant
    K0, K1 = matrix(LinearElastic(E, NU), scene), matrix(iso, scene)
    assert np.allclose(K1, K0, rtol=0, atol=1e-10 * np.abs(K0).max())
    # a genuinely orthotropic law rotated by pi/2 swaps the roles of E1 and E2
    a = matrix(OrthotropicElastic(3 * E, E, E, 0.2, 0.25, 0.3, 0.4 * E, angle=90.0), scene)
    nu21 = 0.2 * E / (3 * E)  # reciprocity nu21 / E2 = nu12 / E1
    b = matrix(OrthotropicElastic(E, 3 * E, E, nu21, 0.3, 0.25, 0.4 * E), scene)
    assert np.allclose(a, b, rtol=0, atol=1e-10 * np.abs(b).max())
    with pytest.raises(ValueError, match="positive definite"):
        OrthotropicElastic(E, E, E, 0.9, 0.9, 0.9, G)


def test_neo_hookean_linearisation_is_linear_elasticity():
    scene = block_scene(4)
    K0, K1 = matrix(LinearElastic(E, NU), scene), matrix(NeoHookean(E, NU), scene)
    assert np.allclose(K1, K0, rtol=0, atol=1e-10 * np.abs(K0).max())


def test_neo_hookean_punch_small_load_is_linear():
    scene = block_scene(8)
    d = 1e-6 * H
    lin = punch(scene, LinearElastic(E, NU), d).reaction("punch")
    nh = punch(scene, NeoHookean(E, NU), d).reaction("punch")
    assert lin[1] < 0  # the punch pushes the block down
    # finite-strain correction is O(strain) = O(1e-6) relative
    assert abs(nh[1] - lin[1]) <= 1e-4 * abs(lin[1])


def test_neo_hookean_punch_large_load_quadratic_newton():
    scene = block_scene(8)
    p = punch(scene, NeoHookean(E, NU), 0.15 * H)  # 15 % indentation in one step
    r = np.array(p.steps[-1].residuals)
    assert p.steps[-1].iterations <= 10
    # quadratic convergence: once in the basin, r_{k+1} <= C r_k^2 with C bounded, i.e. the
    # number of correct digits roughly doubles (checked on the last three iterations above
    # the round-off floor)
    rr = r / r[0]
    tail = [k for k in range(1, len(rr)) if rr[k - 1] < 1e-2 and rr[k] > 1e-14]
    assert tail, f"no iterate in the quadratic basin: {rr}"
    for k in tail:
        assert np.log10(rr[k]) <= 1.6 * np.log10(rr[k - 1]), rr
    # at 15 % indentation the finite-strain response differs measurably from the linear one
    lin = punch(scene, LinearElastic(E, NU), 0.15 * H).reaction("punch")[1]
    assert abs(p.reaction("punch")[1] - lin) > 1e-3 * abs(lin)


def cut_block_scene(comm=MPI.COMM_WORLD, h=1 / 16):
    """The block on a cut grid, its bottom cut by the slanted line y = 0.1 + 0.1 x (cut cells
    all along it), clamped on its left and right sides, the punch on the top."""
    from dolfinx_forms.mesh.from_spec import build_scene

    from dolfinx_forms.app import scene_spec

    spec = scene_spec.load(
        {
            "name": "cut_punch",
            "discretization": {"kind": "cut", "h": h, "extent": [[-W / 2, 0.0], [W / 2, H]]},
            "bodies": [
                {
                    "name": "block",
                    "window": [[-W / 2, 0.0], [W / 2, H]],
                    "shape": {"type": "half_plane", "point": [0.0, 0.1], "normal": [0.1, -1.0]},
                    "law": {"type": "linear", "E": E, "nu": NU},
                }
            ],
            "boundaries": [
                {"name": "sides", "body": "block", "side": ["left", "right"]},
                {
                    "name": "punch",
                    "box": {"x_min": -A, "x_max": A, "y_min": H - 1e-9, "y_max": H + 1e-9},
                },
            ],
        }
    )
    return build_scene(comm, spec)


def cut_punch(scene, law, depth):
    bcs = [
        Dirichlet("sides", None, 0.0),
        Dirichlet("punch", 0, 0.0),
        Dirichlet("punch", 1, lambda lam: -lam * depth),
    ]
    p = ContactProblem(
        scene,
        {1: law},
        dirichlet=bcs,
        log=lambda *a: None,
        **options(newton=NewtonOptions(rtol=1e-11)),
    )
    p.solve(1)
    return p


def test_neo_hookean_on_cut_cells_linear_limit_and_quadratic_newton():
    scene = cut_block_scene()
    assert scene.cut is not None and np.any(scene.cut.kind_tags.values == 1)  # cells are cut
    d = 1e-6 * H
    lin = cut_punch(scene, LinearElastic(E, NU), d).reaction("punch")[1]
    nh = cut_punch(scene, NeoHookean(E, NU), d).reaction("punch")[1]
    assert lin < 0 and abs(nh - lin) <= 1e-4 * abs(lin)
    p = cut_punch(scene, NeoHookean(E, NU), 0.1 * H)  # 10 % indentation of a clamped block
    rr = np.array(p.steps[-1].residuals) / p.steps[-1].residuals[0]
    tail = [k for k in range(1, len(rr)) if rr[k - 1] < 1e-2 and rr[k] > 1e-14]
    assert tail, rr
    for k in tail:
        assert np.log10(rr[k]) <= 1.6 * np.log10(rr[k - 1]), rr


def _residual_and_signature(law, mesh, u, bind):
    """(the assembled residual of `law` at u, the FFCx signature of its form): the law bound to
    the mesh (its parameters Constants, `Law.on`) or with its numbers as UFL literals."""
    import ffcx.naming

    from dolfinx_forms.fem.history import HistoryLaw

    v = ufl.TestFunction(u.function_space)
    dx = ufl.dx(metadata={"quadrature_degree": 4})
    w = HistoryLaw(law, mesh) if law.finite_strain and law.history_size else law
    form = (w.on(mesh) if bind else w).residual(u, v, dx)
    b = fem.petsc.assemble_vector(fem.form(form))
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    r = b.array.copy()
    b.destroy()
    return r, ffcx.naming.compute_signature([form], "")


def test_a_shipped_laws_parameters_are_runtime_constants():
    """`Law.on(mesh)`: the parameters a shipped law's UFL reads become fem.Constants, so the
    compiled form is the same for every value (one compile per law type: another E, nu or
    yield stress finds it in FFCx's cache), and the residual equals the one of the law with
    its numbers as literals (an independent compile) to round-off."""

    from dolfinx_forms.fem.plasticity import DruckerPrager, J2Plasticity

    mesh = dmesh.create_unit_square(MPI.COMM_WORLD, 4, 4, dmesh.CellType.quadrilateral)
    V = fem.VectorFunctionSpace(mesh, ("Lagrange", 1))
    u = fem.Function(V)
    # DOLFINx gives the mesh's coordinate element its variant at the first form compiled on it
    # (a cold FFCx cache), which changes the signature of every form made after: one first
    fem.form(ufl.inner(u, u) * ufl.dx)
    # a deformation that yields J2 and the cone at these parameters: stretch and shear
    u.interpolate(lambda x: np.stack([0.08 * x[0] + 0.05 * x[1] ** 2, -0.06 * x[1] + 0.02 * x[0]]))
    ortho = lambda E1: OrthotropicElastic(E1, 400.0, 300.0, 0.25, 0.3, 0.2, 150.0, 30.0)  # noqa
    pairs = [
        (LinearElastic(E, NU), LinearElastic(3 * E, 0.2)),
        (NeoHookean(E, NU), NeoHookean(2 * E, 0.45)),
        (J2Plasticity(E, NU, 5.0, 10.0), J2Plasticity(2 * E, 0.25, 3.0, 0.0)),
        (DruckerPrager(E, NU, 1.0, 30.0, 10.0, 5.0), DruckerPrager(E, 0.2, 2.0, 20.0, 15.0)),
        (ortho(1000.0), ortho(2000.0)),
    ]
    for k, (a, b) in enumerate(pairs):
        ra, sa = _residual_and_signature(a, mesh, u, True)
        # UFL numbers Constants by creation: 10^k more of them made in between must not change
        # the signature (separate Constants per parameter did, past a power of ten)
        junk = [fem.Constant(mesh, 0.0) for _ in range(10**k % 1000 + 7)]
        rb, sb = _residual_and_signature(b, mesh, u, True)
        del junk
        assert sa == sb, type(a).__name__  # one compiled form for both parameter sets
        for law, r in ((a, ra), (b, rb)):
            literal, s_lit = _residual_and_signature(law, mesh, u, False)
            assert s_lit != sa  # the literals' form is another compile
            scale = np.abs(literal).max()
            assert scale > 0
            assert np.abs(r - literal).max() <= 1e-12 * scale, type(law).__name__
        assert np.abs(ra - rb).max() > 1e-3 * np.abs(ra).max()  # the values reach the kernel
    # the numbers stay the law's: describe and the law's key read them, not the Constants
    law = NeoHookean(E, NU)
    bound = law.on(mesh)
    assert not isinstance(bound.mu, float) and law.mu == E / (2 * (1 + NU))
    assert bound.describe() == law.describe()
