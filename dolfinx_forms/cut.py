"""Cut-cell forms: FFCx kernels on interior cells, C++ kernels on cut cells, in ONE dolfinx Form.

A cut scene (`meshes.cut`) holds the active cells of every body on a structured grid, tagged
interior (0) or cut (1), and the interior facets of cut cells (ghost-penalty facets). Here

* bilinear form: plane-strain elasticity, integral id 0 on interior cells is the FFCx kernel of
  the UFL form, id 1 on cut cells is `contact::cut::elasticity_q1` (the cell split by the
  straight zero contour of phi, the inside part triangulated, a degree-2 rule per triangle:
  exact for Q1 on the grid's rectangles); the ghost penalty (eq. below) is an FFCx interior-facet
  integral of the same Form;
* traction forms: FFCx on boundary facets of interior cells, `contact::cut::traction_q1` (the
  facet clipped by phi, the traction interpolated in vector Q2) on facets of cut cells.

Ghost penalty (Burman 2010) on the faces F of cut cells, Q1: gamma * (2 mu + lambda) * h_n *
int_F [grad u . n] . [grad v . n], with h_n the cell width normal to F. It vanishes on linear
fields (patch test untouched) and bounds the condition number as cut fractions go to zero.

The kernels read their coefficients at fixed offsets (`_cpp.cut_layout()`, defined in
`contact/cut_cell.h`): phi (vertex values) first, then the cell data. The forms below are built
so that FFCx packs them in that order, and `_check_layout` verifies it.
"""

import numpy as np
import ufl
from dolfinx import cpp as _dcpp
from dolfinx import fem, jit

from . import _cpp

LAYOUT = _cpp.cut_layout()
KERNELS = _cpp.cut_kernels()
# kind_tags values = integral ids of the cell integrals; ghost-facet tag = interior-facet id.
# One source of truth: the scene builders (meshes.cut) import these.
INTERIOR, CUT = 0, 1
GHOST_FACET = GHOST = 1
_TYPES = {0: _dcpp.fem.IntegralType.cell, 1: _dcpp.fem.IntegralType.exterior_facet,
          2: _dcpp.fem.IntegralType.interior_facet}


def _mixed_form(ufl_form, replace, subdomains):
    """Compile `ufl_form` with FFCx and build a dolfinx Form whose integrals `replace`
    {(type index, id): kernel address} are the C++ kernels instead of FFCx's.

    Returns (form, module): keep the module alive as long as the form."""
    mesh = ufl_form.ufl_domain().ufl_cargo()
    ufcx_form, module, _ = jit.ffcx_jit(mesh.comm, ufl_form,
                                        form_compiler_params={"scalar_type": "double"})
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
            kernels.append((i, ptr))
        integrals[itype] = (kernels, subdomains[t])
    original = ufl_form.coefficients()
    coeffs = [original[ufcx_form.original_coefficient_position[i]]._cpp_object
              for i in range(ufcx_form.num_coefficients)]
    consts = [c._cpp_object for c in ufl_form.constants()]
    spaces = [a.ufl_function_space()._cpp_object for a in ufl_form.arguments()]
    if perm:
        mesh.topology.create_entity_permutations()
    form = _dcpp.fem.Form_float64(spaces, integrals, coeffs, consts, perm, mesh)
    return form, module


def levelset_values(scene, V):
    """A Function on the scalar Q1 space V of scene.mesh holding at each dof the cut shape of the
    body owning it (the bodies are disjoint: every dof belongs to one body); ghosts updated."""
    phi = fem.Function(V)
    ncells = len(scene.cell_tags.values)
    cell_dofs = V.dofmap.list.array.reshape(ncells, -1)
    xdof = V.tabulate_dof_coordinates()[:, :2]
    for tag, shape in scene.cut.levelsets.items():
        dofs = np.unique(cell_dofs[scene.cell_tags.values == tag])
        if len(dofs):
            phi.x.array[dofs] = np.asarray(shape(np.ascontiguousarray(xdof[dofs])))
    phi.x.scatter_forward()
    return phi


def _check_layout(form, names):
    got = [c.name for c in form.coefficients]
    if got[:len(names)] != names:
        raise RuntimeError(f"cut form coefficients packed as {got}, the C++ kernels expect "
                           f"{names} first (contact/cut_cell.h Layout)")


class CutForms:
    """Bulk forms of a cut scene for vector Q1 space V (see the module docstring).

    materials: {body tag: (E, nu)}; ghost_penalty: gamma (0 switches it off); phi: a scalar Q1
    Function of the level sets (default: `levelset_values` of the scene), created
    before this object (coefficient order)."""

    def __init__(self, V, scene, materials, ghost_penalty=0.01, phi=None):
        from .solver import plane_strain

        if V.ufl_element().degree() != 1 or scene.cell_type != "quadrilateral":
            raise ValueError("degree: the cut path supports Q1 (degree 1) on quadrilaterals only")
        self.V, self.scene, self.mesh = V, scene, scene.mesh
        cut, mesh = scene.cut, scene.mesh
        self.gamma = float(ghost_penalty)
        # coefficients in kernel-layout order: phi first (created first), then cell data
        if phi is None:
            phi = levelset_values(scene, fem.FunctionSpace(mesh, ("Lagrange", 1)))
        self.phi = phi
        self.phi.name = "phi"
        D = fem.VectorFunctionSpace(mesh, ("DG", 0), dim=4)
        self.cell_data = fem.Function(D, name="cell_data")  # (mu, lambda, hx, hy) per cell
        data = self.cell_data.x.array.reshape(-1, 4)
        ddofs = D.dofmap.list.array
        for tag, (E, nu) in materials.items():
            cells = scene.cell_tags.indices[scene.cell_tags.values == tag]
            data[ddofs[cells], 0], data[ddofs[cells], 1] = plane_strain(E, nu)
        x = mesh.geometry.x
        g = mesh.geometry.dofmap.array.reshape(-1, 4)
        data[ddofs[np.arange(len(g))], 2:] = np.ptp(x[g][:, :, :2], axis=1)  # grid cells
        self.cell_data.x.scatter_forward()

        u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
        mu, lmb, hx, hy = (self.cell_data[k] for k in range(4))
        eps = lambda w: ufl.sym(ufl.grad(w))  # noqa: E731
        sig = 2 * mu * eps(u) + lmb * ufl.tr(eps(u)) * ufl.Identity(2)
        dx = ufl.Measure("dx", domain=mesh, subdomain_data=cut.kind_tags)
        # the dx(CUT) integrand only makes FFCx pack phi; its kernel is replaced by C++
        a = ufl.inner(sig, eps(v)) * dx(INTERIOR) + self.phi * ufl.inner(sig, eps(v)) * dx(CUT)
        if self.gamma > 0:
            n = ufl.FacetNormal(mesh)
            dS = ufl.Measure("dS", domain=mesh, subdomain_data=cut.ghost_facets)
            h_n = ufl.avg(abs(n[0]) * hx + abs(n[1]) * hy)  # cell width across the face
            a += (self.gamma * ufl.avg(2 * mu + lmb) * h_n
                  * ufl.inner(ufl.jump(ufl.grad(u), n), ufl.jump(ufl.grad(v), n)) * dS(GHOST))
        self.a, self._module = _mixed_form(
            a, {(0, CUT): KERNELS["elasticity_q1"]},
            {0: cut.kind_tags, 1: None, 2: cut.ghost_facets})
        _check_layout(self.a, ["phi", "cell_data"])
        self._keep = []

    def insert_ghost_couplings(self, pattern):
        """Add the cell-pair couplings of the ghost-penalty facets to a SparsityPattern."""
        if self.gamma <= 0:
            return
        top = self.mesh.topology
        top.create_connectivity(1, 2)
        f2c = top.connectivity(1, 2)
        facets = self.scene.cut.ghost_facets.indices
        if len(facets) == 0:
            return
        cells = np.array([f2c.links(f) for f in facets])  # two cells per interior facet
        dofs = self.V.dofmap.list.array.reshape(-1, 4)
        _cpp.insert_blocks(pattern, np.hstack([dofs[cells[:, 0]], dofs[cells[:, 1]]]))

    def traction_form(self, traction, boundary_tag):
        """Linear form int t . v ds over the facets tagged `boundary_tag`; on facets of cut
        cells only their inside part (t interpolated in vector Q2 there)."""
        mesh, scene = self.mesh, self.scene
        facets = scene.facet_tags.find(boundary_tag)
        top = mesh.topology
        top.create_connectivity(1, 2)
        f2c = top.connectivity(1, 2)
        kind = np.zeros(top.index_map(2).size_local + top.index_map(2).num_ghosts, np.int32)
        kind[scene.cut.kind_tags.indices] = scene.cut.kind_tags.values
        cells = f2c.array[f2c.offsets[facets]]
        tags = _dcpp.mesh.MeshTags_int32(mesh._mesh, 1, facets.astype(np.int32),
                                         kind[cells].astype(np.int32))
        V2 = fem.VectorFunctionSpace(mesh, ("Lagrange", 2))
        t_h = fem.Function(V2, name="traction")
        t_h.interpolate(fem.Expression(traction, V2.element.interpolation_points()))
        v = ufl.TestFunction(self.V)
        ds = ufl.Measure("ds", domain=mesh, subdomain_data=tags)
        L = ufl.inner(traction, v) * ds(INTERIOR) + self.phi * ufl.inner(t_h, v) * ds(CUT)
        form, module = _mixed_form(L, {(1, CUT): KERNELS["traction_q1"]}, {0: None, 1: tags, 2: None})
        _check_layout(form, ["phi", "traction"])
        self._keep += [module, t_h, tags]
        return form
