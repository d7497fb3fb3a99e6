"""Bulk forms of all bodies: UFL laws per body, loads, tractions, ghost penalty.

Each body carries a `laws.Law`; its internal virtual work inner(P(u), grad v) is integrated over
the body's material (`measure(tag)`: the body's cells on a body-fitted mesh; interior cells
and the inside part of cut cells on a cut scene, see `cut.CutIntegration`), and the Jacobian
is `ufl.derivative`. Linear laws (and the ghost penalty) form the matrix K assembled once, so
that their residual is K u; nonlinear laws are assembled at every Newton iteration.
"""

import numpy as np
import ufl
from dolfinx import fem
from petsc4py import PETSc

from dolfinx_forms.fem.laws import as_law, law_key


class BulkForms:
    """Forms of the bulk for displacement u (a Function of the vector Lagrange space V).

    laws: {body tag: Law or (E, nu)}; tractions: `boundary.Traction`s; loads: `BodyForce` /
    `Load`s; integration: a `cut.CutIntegration` on cut scenes (None: body-fitted);
    quadrature_degree: FFCx degree on body-fitted cells and interior cut cells (None: FFCx's
    estimate for linear laws, 2 p for nonlinear ones); rigid_mode_stiffness: alpha of a spring
    alpha E / L^2 on every body's displacement (0: none; see __init__)."""

    def __init__(
        self,
        u,
        scene,
        laws,
        *,
        tractions=(),
        loads=(),
        integration=None,
        ghost_penalty=0.0,
        quadrature_degree=None,
        rigid_mode_stiffness=0.0,
    ):
        self.u, self.V, self.scene = u, u.function_space, scene
        mesh = scene.mesh
        self.laws = {int(tag): as_law(m) for tag, m in laws.items()}
        missing = set(np.unique(scene.cell_tags.values).tolist()) - set(self.laws)
        if missing:
            raise ValueError(f"materials: no law for body tag(s) {sorted(missing)}")
        self.integration = integration
        du, v = ufl.TrialFunction(self.V), ufl.TestFunction(self.V)
        p = self.V.ufl_element().degree()

        def measure(tag=None, nonlinear=False, degree=None):
            if integration is not None:
                return integration.measure(tag, degree)
            md = {}
            if degree is not None:
                md = {"quadrature_degree": int(degree)}
            elif quadrature_degree is not None:
                md = {"quadrature_degree": int(quadrature_degree)}
            elif nonlinear:
                md = {"quadrature_degree": 2 * p}
            dx = ufl.Measure("dx", domain=mesh, subdomain_data=scene.cell_tags, metadata=md)
            if tag is None:
                return dx
            return dx(tuple(int(t) for t in tag)) if np.ndim(tag) else dx(int(tag))

        self.measure = measure
        # a cut scene's measure of several bodies is one integral per part (`cut.CutIntegration`)
        compile_form = fem.form if integration is None else integration.form
        # one integral per distinct law, over all its bodies (100 grains of one material: one
        # FFCx kernel, not 100)
        # the forms read each law's parameters as Constants (`Law.on`): compiled once a law type
        groups = {}
        for t, law in self.laws.items():
            key = law_key(law)
            if key not in groups:
                groups[key] = (law.on(mesh), [])
            groups[key][1].append(t)
        lin = [
            law.residual(u, v, measure(ts, degree=getattr(law, "quadrature_degree", None)))
            for law, ts in groups.values()
            if law.linear
        ]
        # a law whose coefficients live at quadrature points names their degree (the MPM's F_n)
        nl = [
            law.residual(u, v, measure(ts, True, getattr(law, "quadrature_degree", None)))
            for law, ts in groups.values()
            if not law.linear
        ]
        a_lin = [ufl.derivative(sum(lin[1:], lin[0]), u, du)] if lin else []
        if rigid_mode_stiffness > 0:
            # alpha E / L^2 int u . v on each body (L: its bbox diagonal): a floor under the
            # rigid modes of bodies held only by contact (a grain before its contacts close),
            # relative size alpha on the body's elastic stiffness. alpha E / L^2 per cell (DG0):
            # one integral per law group, as the laws' own
            c = fem.Function(fem.FunctionSpace(mesh, ("DG", 0)), name="rigid_mode_stiffness")
            cell_dof = c.function_space.dofmap.list.array
            for tag, law in self.laws.items():
                body = next(b for b in scene.bodies if b.tag == tag)
                L2 = float(np.sum(np.ptp(np.asarray(body.bbox, float), axis=0) ** 2))
                c.x.array[cell_dof[scene.body_cells(tag)]] = rigid_mode_stiffness * law.modulus / L2
            c.x.scatter_forward()
            self._rigid = c
            a_lin += [c * ufl.inner(du, v) * measure(ts) for _, ts in groups.values()]
        if integration is not None and ghost_penalty > 0:
            pm = fem.Function(fem.FunctionSpace(mesh, ("DG", 0)), name="p_modulus")
            cell_dof = pm.function_space.dofmap.list.array
            for tag, law in self.laws.items():
                pm.x.array[cell_dof[scene.body_cells(tag)]] = law.p_modulus
            pm.x.scatter_forward()
            self._pm = pm
            a_lin.append(integration.ghost_penalty(du, v, ghost_penalty, pm))
        self.a_lin = compile_form(sum(a_lin[1:], a_lin[0])) if a_lin else None
        self.nonlinear = bool(nl)
        if self.nonlinear:
            F_nl = sum(nl[1:], nl[0])
            self.F_nl = compile_form(F_nl)
            self.J_nl = compile_form(ufl.derivative(F_nl, u, du))
            self.b_nl = fem.petsc.create_vector(self.F_nl)
            # explicit zeros on the nonlinear bodies' cells: PETSc drops preallocated entries
            # never set at the first final assembly, and the Jacobian is a copy of K's pattern
            zero = fem.Constant(mesh, 0.0)
            tags = tuple(t for t, law in self.laws.items() if not law.linear)
            if integration is None:
                dxb = ufl.Measure("dx", domain=mesh, subdomain_data=scene.cell_tags,
                                  metadata={"quadrature_degree": 0})  # fmt: skip
                self.a_fill = fem.form(zero * ufl.inner(du, v) * dxb(tags))
            else:  # every cell of those bodies, interior and cut
                dxb = integration.measure(tags, degree=0)
                self.a_fill = compile_form(zero * ufl.inner(du, v) * dxb)
        # right-hand sides, assembled once: f(lam) = sum scale_k(lam) f_k
        self.rhs = []
        for t in tractions:
            if t.boundary not in scene.boundaries:
                raise ValueError(
                    f"Traction: unknown boundary {t.boundary!r}; the scene has "
                    f"{sorted(scene.boundaries)}"
                )
            tag = scene.boundaries[t.boundary]
            if integration is not None:
                L = integration.traction_form(self.V, t.traction, tag)
            else:
                ds = ufl.Measure("ds", domain=mesh, subdomain_data=scene.facet_tags)
                L = fem.form(ufl.inner(t.traction, v) * ds(tag))
            self.rhs.append((t, L))
        for load in loads:
            self.rhs.append((load, compile_form(load.form(v, measure))))
        self.f_vectors = []
        for _, L in self.rhs:
            b = fem.petsc.assemble_vector(L)
            b.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
            self.f_vectors.append(b)

    def destroy(self):
        """Free the PETSc vectors (petsc4py frees none when garbage-collected)."""
        for b in self.f_vectors + ([self.b_nl] if self.nonlinear else []):
            b.destroy()
        self.f_vectors = []

    def update_loads(self):
        """Assemble the right-hand sides again (loads whose coefficients changed, e.g. the
        Newmark inertia load of solvers/dynamics.py)."""
        for (_, L), b in zip(self.rhs, self.f_vectors):
            with b.localForm() as loc:
                loc.set(0.0)
            fem.petsc.assemble_vector(b, L)
            b.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)

    def assemble_linear(self, K):
        """Add the linear part into K (its pattern must hold the mesh couplings), and explicit
        zeros on the cells of nonlinear bodies."""
        if self.nonlinear:
            fem.petsc.assemble_matrix(K, self.a_fill)
        if self.a_lin is not None:
            fem.petsc.assemble_matrix(K, self.a_lin)

    def external(self, lam, f):
        """f <- sum_k scale_k(lam) f_k."""
        f.set(0.0)
        for (load, _), b in zip(self.rhs, self.f_vectors):
            f.axpy(load.at(lam), b)

    def add_nonlinear(self, R, J=None):
        """R += F_nl(u) (owned part); J += dF_nl/du (J in ADD mode, not finally assembled)."""
        if not self.nonlinear:
            return
        with self.b_nl.localForm() as loc:
            loc.set(0.0)
        fem.petsc.assemble_vector(self.b_nl, self.F_nl)
        self.b_nl.ghostUpdate(PETSc.InsertMode.ADD, PETSc.ScatterMode.REVERSE)
        R.axpy(1.0, self.b_nl)
        if J is not None:
            fem.petsc.assemble_matrix(J, self.J_nl)

    def stress(self, space=("DG", 0)):
        """The output (Cauchy) stress of each body's law, interpolated into a tensor space
        (cellwise) on that body's cells: one stress expression, the law's."""
        S = fem.TensorFunctionSpace(self.scene.mesh, space)
        sig = fem.Function(S, name="stress")
        pts = S.element.interpolation_points()
        for tag, law in self.laws.items():
            expr = fem.Expression(law.on(self.scene.mesh).cauchy(self.u), pts)
            sig.interpolate(expr, self.scene.body_cells(tag))
        return sig
