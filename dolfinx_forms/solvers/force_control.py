"""Force control inside Newton: the value s of one Dirichlet condition is an unknown, and the
reaction it produces is an equation.

Unknowns (u, s); equations R(u, s) = 0 on the free dofs, u = s g on the condition's dofs and
F(u) = F*(lam), with F = sum of the full residual over one component of a boundary's dofs (the
force exerted by that boundary's supports, as `ContactProblem.reaction`) and F* ramped from
the committed reaction to the target over the stage. Each Newton step is a bordered solve with
the one factorisation of J (Dirichlet rows eliminated, columns kept):

    J du1 = -R,   J du2 = g,   ds = (F* - F - k.du1) / (k.du2),   du = du1 + ds du2,

k = J_full^T 1_b the gradient of F. A load is then reached in one Newton solve instead of a
secant over whole solves (issue 12: 4 solves, 23 iterations -> one solve).

While no contact couples the moving condition to the boundary (k.du2 = 0, e.g. the first
iteration from an open gap) the step keeps s: a displacement-controlled iteration at the guess.
"""


class ForceControl:
    """The condition `problem.dirichlet[index]` (a constant value) driven by the reaction
    component `component` at `boundary`: F*(lam) = start + lam (target - start)."""

    def __init__(self, problem, index, boundary, component, target, guess):
        from dolfinx import fem

        self.problem, self.index = problem, index
        pb = problem
        facets = pb.scene.facet_tags.find(pb.scene.boundaries[boundary])
        dofs = fem.locate_dofs_topological(pb.V.sub(component), pb.mesh.topology.dim - 1, facets)
        self.sel = pb.K.createVecLeft()  # 1 on the reaction's dofs (owned)
        self.sel.array[dofs[dofs < pb.n_owned]] = 1.0
        self.g = pb.K.createVecLeft()  # 1 on the moving condition's dofs (owned)
        own = pb.bc_dofs[index]
        self.g.array[own[own < pb.n_owned]] = 1.0
        self.k = pb.K.createVecLeft()  # gradient of F (filled with the tangent)
        self.w = pb.K.createVecLeft()  # response to a unit increment of s
        self.w_of = None  # the operator w was solved with (`linear.py`'s operator number)
        self.start = float(pb.reaction(boundary)[component])
        self.target = float(target)
        self.s = self.s_committed = self.s_start = float(pb.dirichlet[index].at(pb.lam))
        self.lam_committed = 0.0
        self.slope = float(guess) - self.s  # ds/dlam of the first step's prediction
        self.force, self.ds = self.start, 0.0

    def destroy(self):
        """Free the PETSc vectors (petsc4py frees none when garbage-collected)."""
        for v in (self.sel, self.g, self.k, self.w):
            v.destroy()

    def __call__(self, lam):  # the condition's value: the unknown, whatever the load level
        return self.s

    def aim(self, lam):
        return self.start + lam * (self.target - self.start)

    def predict(self, lam):
        """The step's first s: extrapolated along the stage (the first guess in step one)."""
        self.s = self.s_committed + (lam - self.lam_committed) * self.slope

    def measure(self, R):
        """F from the full residual R (before its Dirichlet rows are zeroed)."""
        self.force = float(self.sel.dot(R))  # a global dot product
        return self.force

    def linearise(self, J):
        """k = J^T 1_b from the full tangent (before its Dirichlet rows are zeroed)."""
        J.multTranspose(self.sel, self.k)

    def border(self, linear, du, lam):
        """Turn the step du = -J^-1 R into the bordered step: linear (`linear.py`) solves
        with J, one more solve with the same factors unless J is the one w was solved with
        (the later iterations of a settled active set, most of an augmented Lagrangian loop)."""
        of = linear.operator
        if of == 0 or of != self.w_of:
            linear.solve(self.g, self.w)
            self.w_of = of
        dF1, dF2 = self.k.dot(du), self.k.dot(self.w)
        scale = self.k.norm() * self.w.norm()
        if abs(dF2) <= 1e-12 * scale:  # nothing couples s to F yet: keep s this iteration
            self.ds = 0.0
            return
        self.ds = (self.aim(lam) - self.force - dF1) / dF2
        du.axpy(self.ds, self.w)
        self.s += self.ds

    def backtrack(self, fraction):
        self.s -= fraction * self.ds

    def commit(self, lam):
        if lam > self.lam_committed:
            self.slope = (self.s - self.s_start) / lam
        self.s_committed, self.lam_committed = self.s, lam

    def restore(self):
        self.s = self.s_committed

    def residual(self, lam):
        return self.force - self.aim(lam)
