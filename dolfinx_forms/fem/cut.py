"""Cut-cell integration: any UFL integrand on the inside part of cut cells, in dolfinx Forms.

A cut scene (`meshes.cut`) holds the active cells of every body on a structured grid, tagged
interior (0) or cut (1), and the interior facets of cut cells (ghost-penalty facets).

* Cell integrals (any UFL law, body force, energy): on interior cells FFCx's own rule; on cut
  cells FFCx's tensor Gauss rule of degree `degree` (m = (degree + 2) // 2 points per direction)
  with per-point factors held by a `Quadrature`-element coefficient. The factors make the
  effective weights the moment-fitted weights of the inside part {phi_h < 0} (C++
  `contact::cut::moment_fitted_weights`): exact for every integrand in Q_{m-1}, i.e. for
  Q1 elasticity on the grid's rectangles (integrand in Q2) with the default degree 4. The
  user's form is compiled by FFCx unchanged; history variables can live at the same points.
  `CutIntegration.measure(tag)` is the measure: `integrand * measure` gives both parts.
  Several bodies (a law over 100 grains) share one integral per part: its id stands for the
  group's ids (`ALIAS_BASE`), and `CutIntegration.form` compiles it once and hands the kernel
  to each id. Per id, FFCx would compile 2 x 100 copies of the kernel (a neo-Hookean grain
  assembly: ~10 s a form) and UFL would carry 200 integrals through every step's forms.
* Ghost penalty (Burman 2010) on the faces F of cut cells, Q1: gamma * p_modulus * h_n *
  int_F [grad u . n] . [grad v . n], with h_n the cell width normal to F. It vanishes on linear
  fields (patch test untouched) and bounds the condition number as cut fractions go to zero.
* Traction forms: FFCx on boundary facets of interior cells, `contact::cut::traction_q1` (the
  facet clipped by phi, the traction interpolated in vector Q2) on facets of cut cells. That
  kernel reads its coefficients at fixed offsets (`_cpp.cut_layout()`, from
  `contact/cut_cell.h`): phi (vertex values) first, then the traction; `_check_layout` checks.
"""

import zlib

import basix
import numpy as np
import ufl
from dolfinx import cpp as _dcpp
from dolfinx import fem, jit

from dolfinx_forms import _cpp
from dolfinx_forms.fem import jit_memo

LAYOUT = _cpp.cut_layout()
KERNELS = _cpp.cut_kernels()
# kind_tags values; ghost-facet tag = interior-facet id. One source of truth: the scene
# builders (meshes.cut) import these. Cell-integral ids: body tag + CUT_ID * kind.
INTERIOR, CUT = 0, 1
GHOST_FACET = GHOST = 1
CUT_ID = 1000
# cell-integral ids from here on stand for a group of bodies' ids (`CutIntegration.measure`);
# forms holding them are compiled by `CutIntegration.form` (elsewhere they would integrate over
# nothing: `jit_memo`, which a CutIntegration installs, refuses them)
ALIAS_BASE = jit_memo.ALIAS_BASE
_TYPES = {
    0: _dcpp.fem.IntegralType.cell,
    1: _dcpp.fem.IntegralType.exterior_facet,
    2: _dcpp.fem.IntegralType.interior_facet,
}


def _mixed_form(ufl_form, replace, subdomains, expand=None):
    """Compile `ufl_form` with FFCx and build a dolfinx Form whose integrals `replace`
    {(type index, id): kernel address} are the C++ kernels instead of FFCx's, and whose cell
    integral of an id in `expand` {id: ids} is the kernel of each of those ids instead.

    Returns (form, module): keep the module alive as long as the form."""
    mesh = ufl_form.ufl_domain().ufl_cargo()
    expand = expand or {}
    with jit_memo.aliases_allowed(bool(expand)):
        ufcx_form, module, _ = jit.ffcx_jit(
            mesh.comm, ufl_form, form_compiler_params={"scalar_type": "double"}
        )
    integrals, perm = {}, False
    for t, itype in _TYPES.items():
        ids = [ufcx_form.integral_ids(t)[k] for k in range(ufcx_form.num_integrals(t))]
        if not ids:
            continue
        kernels = []
        for k, i in enumerate(ids):
            integral = ufcx_form.integrals(t)[k]
            perm = perm or bool(integral.needs_facet_permutations)
            ptr = replace.get((t, i))
            if ptr is None:
                ptr = int(module.ffi.cast("uintptr_t", integral.tabulate_tensor_float64))
            kernels += [(j, ptr) for j in (expand.get(i, (i,)) if t == 0 else (i,))]
        integrals[itype] = (kernels, subdomains[t])
    original = ufl_form.coefficients()
    coeffs = [
        original[ufcx_form.original_coefficient_position[i]]._cpp_object
        for i in range(ufcx_form.num_coefficients)
    ]
    consts = [c._cpp_object for c in ufl_form.constants()]
    spaces = [a.ufl_function_space()._cpp_object for a in ufl_form.arguments()]
    if perm:
        mesh.topology.create_entity_permutations()
    form = _dcpp.fem.Form_float64(spaces, integrals, coeffs, consts, perm, mesh)
    return form, module


def shape_values(shape, points, clamp=False):
    """Values (n,) at points (n, 2) of a body's cut level set: a shape (callable, e.g. a
    `_cpp.Shape`) or a grid `_cpp.LevelSet` (its C1 interpolant; node values at grid nodes).
    clamp: a grid level set is evaluated at the nearest point of its grid for points beyond it
    (a body's level set is positive there; the reference map asks anywhere), not only for those
    off its edge by round-off."""
    points = np.ascontiguousarray(points, dtype=float)
    if isinstance(shape, _cpp.LevelSet):
        g = shape.grid  # dof coordinates on the grid's edge may be off by round-off: clip those
        lo = np.array([g.x[0], g.y[0]])
        hi = np.array([g.x[-1], g.y[-1]])
        tol = np.inf if clamp else 1e-9 * np.max(hi - lo)
        near = np.all((points[:, :2] >= lo - tol) & (points[:, :2] <= hi + tol), axis=1)
        p = points[:, :2].copy()
        p[near] = np.clip(p[near], lo, hi)
        return shape.evaluate(np.ascontiguousarray(p))[0]
    return np.asarray(shape(points), float)


def grid_cells(X, Y, phi):
    """The active cells of a level set on the tensor grid X x Y (node values phi, x-fastest):
    quads (nc, 4) vertex indices in DOLFINx order, active (nc,) (min phi < 0 at the vertices),
    kinds of the active cells (CUT if max phi > 0, else INTERIOR) and the bounding box (2, 2)
    of the material (vertices inside plus the ends of the zero contour in the cut cells). The
    one classification of cells: the cut scenes (meshes.cut) and the MPM's reuse test use it."""
    nx, ny = len(X) - 1, len(Y) - 1
    pts = np.stack(np.meshgrid(X, Y), axis=-1).reshape(-1, 2)
    v = (np.arange(ny)[:, None] * (nx + 1) + np.arange(nx)[None, :]).ravel()
    quads = np.stack([v, v + 1, v + nx + 1, v + nx + 2], axis=1)
    pc = phi[quads]
    active = pc.min(axis=1) < 0
    kinds = np.where(pc[active].max(axis=1) > 0, CUT, INTERIOR).astype(np.int32)
    bbox = None
    if active.any():
        cut = quads[active][kinds == CUT]
        c = _cpp.cell_contours(phi[cut])  # marching squares of the cut kernels (linear crossings)
        k, e = np.nonzero(np.isfinite(c["t"]))
        a, b = (cut[k, np.asarray(c["edges"])[e, m]] for m in (0, 1))
        found = np.concatenate([pts[phi <= 0], pts[a] + c["t"][k, e][:, None] * (pts[b] - pts[a])])
        bbox = np.array([found.min(axis=0), found.max(axis=0)])
    return dict(points=pts, quads=quads, active=active, kinds=kinds, bbox=bbox)


def material_window(phi):
    """Node index bounds (i0, i1, j0, j1) of the sub-grid that holds every active cell of a
    level set with node values phi (ny, nx): the nodes with phi < 0 and one more line on each
    side (a cell is active when one of its vertices has phi < 0), within the grid; the whole
    grid if no node is inside. Work on a body then costs its own size, not the grid's."""
    ny, nx = phi.shape
    rows, cols = np.flatnonzero((phi < 0).any(axis=1)), np.flatnonzero((phi < 0).any(axis=0))
    if len(rows) == 0:
        return 0, nx - 1, 0, ny - 1
    return (
        max(cols[0] - 1, 0),
        min(cols[-1] + 1, nx - 1),
        max(rows[0] - 1, 0),
        min(rows[-1] + 1, ny - 1),
    )


def levelset_values(scene, V):
    """A Function on the scalar Q1 space V of scene.mesh holding at each dof the cut shape of the
    body owning it (the bodies are disjoint: every dof belongs to one body); ghosts updated."""
    phi = fem.Function(V)
    ncells = len(scene.cell_tags.values)
    cell_dofs = V.dofmap.list.array.reshape(ncells, -1)
    xdof = V.tabulate_dof_coordinates()[:, :2]
    for tag, shape in scene.cut.levelsets.items():
        dofs = np.unique(cell_dofs[scene.body_cells(tag)])
        if len(dofs):
            phi.x.array[dofs] = shape_values(shape, xdof[dofs])
    phi.x.scatter_forward()
    return phi


def _check_layout(form, names):
    got = [c.name for c in form.coefficients]
    if got[: len(names)] != names:
        raise RuntimeError(
            f"cut form coefficients packed as {got}, the C++ kernels expect "
            f"{names} first (contact/cut_cell.h Layout)"
        )


class BodyMeasure:
    """`integrand * BodyMeasure` = the integral over the bodies' material: interior cells with
    FFCx's rule, cut cells with the moment-fitted weights (a sum of UFL forms)."""

    def __init__(self, parts):
        self.parts = parts  # [(ufl Measure, factor or None)]

    def __rmul__(self, integrand):
        # UFL expands a measure over a tuple of ids into one form per id summed one by one, each
        # sum a new Form that traverses all integrals so far: O(ids^2) (100 grains: 11 ms a
        # form). The same integrals, one per id, in one Form instead.
        integrals = []
        for dx, factor in self.parts:
            f = integrand if factor is None else integrand * factor
            ids = dx.subdomain_id()
            if not isinstance(ids, tuple):
                integrals += (f * dx).integrals()
                continue
            if not ids:
                continue
            one = (f * dx.reconstruct(subdomain_id=ids[0])).integrals()
            integrals += [i.reconstruct(subdomain_id=d) for d in ids for i in one]
        return ufl.Form(integrals)


class CutIntegration:
    """Measures, ghost penalty and traction forms of a cut scene (see the module docstring).

    degree: FFCx quadrature degree on cut cells (4: 3x3 Gauss points, exact for Q2
    integrands over the inside part); phi: a scalar Q1 Function of the level sets (default
    `levelset_values` of the scene), created before any form that uses `traction_form`."""

    def __init__(self, scene, degree=4, phi=None):
        if scene.cell_type != "quadrilateral":
            raise ValueError("cut integration: quadrilateral cells only")
        # the memo's check: a form on this scene's alias ids (`measure` of several bodies)
        # compiled by fem.form, which would integrate over no cell, raises (library use too)
        jit_memo.install()
        self.scene, self.mesh, self.degree = scene, scene.mesh, int(degree)
        mesh, cut = scene.mesh, scene.cut
        self.phi = (
            phi
            if phi is not None
            else levelset_values(scene, fem.FunctionSpace(mesh, ("Lagrange", 1)))
        )
        self.phi.name = "phi"
        # one cell-integral id per (body, kind)
        ncells = len(scene.cell_tags.values)
        kind = np.zeros(ncells, np.int32)
        kind[cut.kind_tags.indices] = cut.kind_tags.values
        body = np.zeros(ncells, np.int32)
        body[scene.cell_tags.indices] = scene.cell_tags.values
        self.cell_ids = _dcpp.mesh.MeshTags_int32(
            mesh._mesh, 2, np.arange(ncells, dtype=np.int32), body + CUT_ID * kind
        )
        # moment-fitted weights on cut cells, as factors on FFCx's Gauss weights
        points, wref = basix.make_quadrature(basix.CellType.quadrilateral, self.degree)
        Qe = ufl.FiniteElement("Quadrature", mesh.ufl_cell(), self.degree, quad_scheme="default")
        self.factor = fem.Function(fem.FunctionSpace(mesh, Qe), name="cut_weight_factor")
        qdofs = self.factor.function_space.dofmap.list.array.reshape(ncells, -1)
        pdofs = self.phi.function_space.dofmap.list.array.reshape(ncells, 4)
        cells = np.flatnonzero(kind == CUT)
        f = self.factor.x.array
        f[:] = 1.0
        self.fraction = np.ones(ncells)  # the share of each cell's area inside its body
        if len(cells):
            W = _cpp.cut_moment_weights(
                np.ascontiguousarray(self.phi.x.array[pdofs[cells]]), np.ascontiguousarray(points)
            )
            f[qdofs[cells]] = W / wref
            self.fraction[cells] = np.asarray(W).reshape(len(cells), -1).sum(axis=1) / wref.sum()
        self.kind = kind
        self.num_cut_cells = len(cells)
        self._keep = []
        self.aliases = {}  # an alias id: the ids of its group (`measure`, `form`)

    def _alias(self, ids):
        """The integral id of the cells of `ids` (None for none): the id itself, or for several
        an alias id in [ALIAS_BASE, ALIAS_BASE + 2^24) named by their values (the same group
        gets the same id at every step of a run and in every run: the compiled form is found
        again)."""
        ids = tuple(sorted(int(i) for i in ids))
        if len(ids) <= 1:
            return ids[0] if ids else None
        a = ALIAS_BASE + (zlib.crc32(np.asarray(ids, np.int64).tobytes()) & 0xFFFFFF)
        while self.aliases.setdefault(a, ids) != ids:  # another group's (a hash collision)
            a += 1
        return a

    def form(self, ufl_form):
        """`fem.form` of a form whose cell integrals may be on groups of bodies (`measure`):
        each group's kernel compiled once and given every id of the group. A form in which a
        body's cells are in two of its integrals (two groups, or a group and the body alone)
        is compiled per id (one kernel per id and integral type)."""
        cell = [i.subdomain_id() for i in ufl_form.integrals() if i.integral_type() == "cell"]
        expand = {a: self.aliases[a] for a in set(cell) if a in self.aliases}
        if not expand:
            return fem.form(ufl_form)
        ids = [j for a in set(cell) for j in expand.get(a, (a,))]
        if len(ids) != len(set(ids)):
            per_id = [
                itg.reconstruct(subdomain_id=j)
                for itg in ufl_form.integrals()
                for j in (
                    expand.get(itg.subdomain_id(), (itg.subdomain_id(),))
                    if itg.integral_type() == "cell"
                    else (itg.subdomain_id(),)
                )
            ]
            return fem.form(ufl.Form(per_id))
        (sd,) = ufl_form.subdomain_data().values()
        types = ("cell", "exterior_facet", "interior_facet")
        form, module = _mixed_form(ufl_form, {}, {k: sd.get(t) for k, t in enumerate(types)},
                                   expand)  # fmt: skip
        self._keep.append(module)
        return form

    def measure(self, tags=None, degree=None):
        """The measure over the material of the bodies `tags` (a tag, a list, or None: all).
        degree: FFCx degree on interior cells (None: FFCx's estimate); `self.degree` puts the
        cut cells' Gauss points on every cell, where a `Quadrature` coefficient of that degree
        (e.g. the MPM's projected stress) lives."""
        bodies = sorted(set(self.scene.cell_tags.values)) if tags is None else np.atleast_1d(tags)
        md = {} if degree is None else {"quadrature_degree": int(degree)}
        dx = ufl.Measure("dx", domain=self.mesh, subdomain_data=self.cell_ids, metadata=md)
        dxq = ufl.Measure(
            "dx",
            domain=self.mesh,
            subdomain_data=self.cell_ids,
            metadata={"quadrature_degree": self.degree},
        )
        ids = [int(t) for t in bodies]
        if not ids:
            return BodyMeasure([])
        cut_ids = [t + CUT_ID for t in ids]
        return BodyMeasure([(dx(self._alias(ids)), None), (dxq(self._alias(cut_ids)), self.factor)])

    def ghost_penalty(self, u, v, gamma, p_modulus):
        """gamma p_modulus h_n [grad u . n][grad v . n] on the ghost facets (a UFL form);
        p_modulus: a DG0 Function (stiffness across a face per cell)."""
        mesh = self.mesh
        D = fem.VectorFunctionSpace(mesh, ("DG", 0), dim=2)
        hxy = fem.Function(D, name="cell_size")  # grid cells: widths in x and y
        x = mesh.geometry.x
        g = mesh.geometry.dofmap.array.reshape(-1, 4)
        ddofs = D.dofmap.list.array
        hxy.x.array.reshape(-1, 2)[ddofs[np.arange(len(g))]] = np.ptp(x[g][:, :, :2], axis=1)
        hxy.x.scatter_forward()
        self._keep.append(hxy)
        n = ufl.FacetNormal(mesh)
        dS = ufl.Measure("dS", domain=mesh, subdomain_data=self.scene.cut.ghost_facets)
        h_n = ufl.avg(abs(n[0]) * hxy[0] + abs(n[1]) * hxy[1])  # cell width across the face
        return (
            gamma
            * ufl.avg(p_modulus)
            * h_n
            * ufl.inner(ufl.jump(ufl.grad(u), n), ufl.jump(ufl.grad(v), n))
            * dS(GHOST)
        )

    def insert_ghost_couplings(self, pattern, V):
        """Add the cell-pair couplings of the ghost-penalty facets to a SparsityPattern."""
        top = self.mesh.topology
        top.create_connectivity(1, 2)
        f2c = top.connectivity(1, 2)
        facets = self.scene.cut.ghost_facets.indices
        if len(facets) == 0:
            return
        # two cells per interior facet (a ghost facet is one), read off the CSR arrays: a
        # Python loop over the facets cost 0.15 s a step at 400 grains
        cells = f2c.array[f2c.offsets[facets][:, None] + np.arange(2)]
        dofs = V.dofmap.list.array.reshape(-1, 4)
        _cpp.insert_blocks(pattern, np.hstack([dofs[cells[:, 0]], dofs[cells[:, 1]]]))

    def traction_form(self, V, traction, boundary_tag):
        """Linear form int t . v ds over the facets tagged `boundary_tag`; on facets of cut
        cells only their inside part (t interpolated in vector Q2 there)."""
        mesh, scene = self.mesh, self.scene
        facets = scene.facet_tags.find(boundary_tag)
        top = mesh.topology
        top.create_connectivity(1, 2)
        f2c = top.connectivity(1, 2)
        cells = f2c.array[f2c.offsets[facets]]
        tags = _dcpp.mesh.MeshTags_int32(
            mesh._mesh, 1, facets.astype(np.int32), self.kind[cells].astype(np.int32)
        )
        V2 = fem.VectorFunctionSpace(mesh, ("Lagrange", 2))
        t_h = fem.Function(V2, name="traction")
        t_h.interpolate(fem.Expression(traction, V2.element.interpolation_points()))
        v = ufl.TestFunction(V)
        ds = ufl.Measure("ds", domain=mesh, subdomain_data=tags)
        L = ufl.inner(traction, v) * ds(INTERIOR) + self.phi * ufl.inner(t_h, v) * ds(CUT)
        form, module = _mixed_form(
            L, {(1, CUT): KERNELS["traction_q1"]}, {0: None, 1: tags, 2: None}
        )
        _check_layout(form, ["phi", "traction"])
        self._keep += [module, t_h, tags]
        return form
