"""The options of a ContactProblem, grouped by what they set: the contact law and its
enforcement (`ContactOptions`), the bulk discretisation (`FemOptions`) and the solvers
(`SolverOptions`). `options(**kw)` sorts flat keywords into the three groups (the demos' and
scenes' parameters name them flat); an unknown name is a TypeError naming it.

    ContactProblem(scene, laws, dirichlet=bcs, contact=ContactOptions(mu=0.3, eps0=0.5))
    ContactProblem(scene, laws, dirichlet=bcs, **options(mu=0.3, eps0=0.5, degree=2))
"""

from dataclasses import dataclass, fields


@dataclass
class ContactOptions:
    """The contact law (eqs 8-12) and its enforcement.

    mu: Coulomb friction coefficient (0: frictionless, no friction work). eps0: the penalty
    factor of eq 51, eps_n = eps_t = eps0 h / E_c (`contact.penalty`); with "augmented" it sets
    only the Uzawa step. band: the largest initial gap that Gamma_c covers (a length; default
    2 h) at the start; band_growth: how often it may double (`ContactProblem.grow_band`: a
    converged load step whose active points reach 0.9 band is done again with the band
    doubled; 0: a fixed band, as the MPM steps, which grow their own). enforcement:
    "penalty" (the answer depends on eps0) or "augmented" (augmented Lagrangian, Uzawa loop,
    `contact.contact_set`). multipliers: None (a traction per contact
    point), "P0" or "P1" (one traction per node along Gamma_c, nodes multiplier_length apart);
    "default": "P1" with "augmented", None with "penalty". multiplier_length: default h
    body-fitted, 1.5 h cut (consistent_length h with the consistent or hybrid projection).
    traction: "nodes" (the law on each node's weighted mean gap) or "points" (the law at each
    point with the multipliers interpolated; eps_n and eps_t then the tuned factors of
    `defaults.TUNING` times h / E_c); "default": "points" with "augmented". multiplier_mass
    (augmented, P1, traction "points"): "hybrid" (default), "consistent" or "lumped".
    grid_refine, num_gauss: the pair level-set grid's refinement and the Gauss points per
    Gamma_c segment. pair_grid_origin: None, or a point every pair's level-set grid passes
    through (symmetric scenes stay symmetric). predictor_gap: in a step's first Newton
    iteration, open points with a gap below it add a closed point's tangent (no force; holds
    bodies whose contacts touch but are not closed yet). contact_rank: the rank that holds
    Gamma_c's cells (contact_box partitioning). regularisation: the augmented Lagrangian's
    point-wise eps_n (traction "points") times this: 1 the tuned one (`defaults.TUNING`), below
    1 stiffer (the MPM's bodies at finite strain: `mpm.implicit.FINITE_STRAIN_REGULARISATION`)."""

    mu: float = 0.0
    eps0: float = 1.0
    band: float | None = None
    band_growth: int = 4
    enforcement: str = "penalty"
    multipliers: str | None = "default"
    multiplier_length: float | None = None
    traction: str = "default"
    multiplier_mass: str | None = None
    grid_refine: int = 4
    num_gauss: int = 2
    pair_grid_origin: object = None
    predictor_gap: float = 0.0
    contact_rank: int = 0
    regularisation: float = 1.0


@dataclass
class FemOptions:
    """The bulk discretisation. degree: Lagrange degree (1 or 2; 1 on a cut scene).
    quadrature_degree: see `fem.bulk.BulkForms`. cut_degree: the cut cells' moment-fitted
    rule (`fem.cut.CutIntegration`). ghost_penalty: on the faces of cut cells (0: none).
    rigid_mode_stiffness: alpha of a spring alpha E / L^2 on every body's displacement, for
    bodies held by contact alone (free grains; changes the answer by ~alpha; 0: none)."""

    degree: int = 1
    quadrature_degree: int | None = None
    cut_degree: int = 4
    ghost_penalty: float = 0.01
    rigid_mode_stiffness: float = 0.0


@dataclass
class SolverOptions:
    """newton: `solvers.newton.NewtonOptions` (default: its defaults). petsc_options: PETSc
    options of the linear solves. linear_solver: "auto", "condensed", "factorised" or
    "iterative" (`solvers.linear`: a linear bulk on one process is factorised once and Newton
    runs on the Schur complement of the contact dofs; "iterative": CG + GAMG with the
    rigid-body modes, chosen by "auto" for large body-fitted problems). coupling_gap (in
    units of h; with `Factorised` only): the sparsity holds the contact tangent blocks of the
    law points whose gap before the step's deformation is below it, not those of every law
    point of the band: most of those stay open, and their explicit zeros cost MUMPS (100
    grains: 20.9k of 22.7k law points open, a numeric factorisation 0.27 s with them against
    0.14 s with J's nonzeros alone). A closed point outside it adds itself, and every point
    then nearer than it, to the sparsity, and the matrices are built again
    (`ContactProblem.residual`; counted in `coupling_rebuilds`; past two growths in a step,
    every law point of the band). The predictor's touching points (predictor_gap) are in it
    on a pair with no closed point; elsewhere their first tangent is dropped (their pair's
    closed points hold the bodies). 0.01 h: 100 grains x 30 steps, 1.06e9 flops a
    factorisation against 1.45e9 at 0.05 h with the predictor's 0.05 h, no growth, the same
    forces to 5e-13. None: every law point of the band.
    short_lived: the problem serves one load step (an MPM step on its own mesh), so
    `Factorised` has MUMPS order by AMD, whose analysis costs less than METIS's extra fill
    saves over a few Newton iterations (`linear.SHORT_LIVED_ORDERING`; a mat_mumps_icntl_7
    among petsc_options wins)."""

    newton: object = None
    petsc_options: dict | None = None
    linear_solver: str = "auto"
    coupling_gap: float | None = 0.01
    short_lived: bool = False


GROUPS = {"contact": ContactOptions, "fem": FemOptions, "solver": SolverOptions}
_FIELD_GROUP = {f.name: g for g, cls in GROUPS.items() for f in fields(cls)}


def options(**kw):
    """{"contact": ContactOptions, "fem": FemOptions, "solver": SolverOptions} from flat
    keywords (module doc); a TypeError names an unknown one."""
    split = {g: {} for g in GROUPS}
    for name, value in kw.items():
        if name not in _FIELD_GROUP:
            raise TypeError(f"ContactProblem: unknown option {name!r}")
        split[_FIELD_GROUP[name]][name] = value
    return {g: GROUPS[g](**values) for g, values in split.items()}


__all__ = ["ContactOptions", "FemOptions", "SolverOptions", "options"]
