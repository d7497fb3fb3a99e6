"""Load protocols: the stages that drive a ContactProblem (displacement ramps, force control,
friction switched on between stages).

A *load* is a Dirichlet condition (its `value`) or a traction / body force (its `scale`). A
stage moves some loads from their current values to targets on straight paths
start + lam (target - start) while every other load is held at its current value; the problem's
load parameter runs lam: 0 -> 1 within the stage, so Newton's step cut-back works inside it and
the friction history is committed step by step. Each stage prints one line with the load
reached (rank 0, through problem.log) and returns a :class:`StageRecord` for metrics.json.

    ramp(problem, top_y, -0.01, steps=4)                    # a displacement ramp
    ramp(problem, [top_y, side], [-0.02, 1.0])              # and a traction's load factor
    ramp(problem, top_x, lambda x: 1e-3 * x[0])             # a value per dof: f(coordinates)
    reach_force(problem, top_y, "block_bottom", 1, 430.0, first_guess=-0.1)  # P = 430
    friction_on(problem, 0.3)
    reach_force(problem, top_x, "cylinder_top", 0, 64.5, first_guess=5e-5, monotone=True)
"""

from dataclasses import asdict, dataclass, field

import numpy as np

from dolfinx_forms.solvers.newton import ContactSolverError

__all__ = [
    "Path",
    "StageRecord",
    "current_value",
    "dof_coordinates",
    "ramp",
    "reach_force",
    "friction_on",
]


@dataclass
class Path:
    """Value of a load along a stage: start + lam (target - start) (floats or per-dof arrays)."""

    start: object
    target: object

    def __call__(self, lam):
        return self.start + lam * (self.target - self.start)


@dataclass
class StageRecord:
    """What a stage did: its accepted load steps, Newton iterations, the values reached by the
    loads it moved, the reaction at its boundary and (force control) the secant iterations."""

    kind: str
    label: str
    load_steps: int = 0
    newton_iterations: int = 0
    values: dict = field(default_factory=dict)
    boundary: str | None = None
    force: list | None = None
    target: float | None = None
    secant_iterations: int | None = None
    method: str | None = None  # force control: "newton" (value solved for) or "secant"

    def as_dict(self):
        return asdict(self)


def _attr(load):
    """The attribute a stage moves: `scale` for tractions and body forces, `value` otherwise."""
    return "scale" if hasattr(load, "scale") else "value"


def current_value(problem, load):
    """The value (Dirichlet) or load factor (traction, body force) applied at problem.lam."""
    v = getattr(load, _attr(load))
    if v is not None and not callable(v):  # a constant, possibly an array per dof
        return np.array(v, float) if np.ndim(v) else float(v)
    v = load.at(problem.lam)
    return np.array(v, float) if np.ndim(v) else float(v)


def dof_coordinates(problem, bc):
    """Coordinates (n, 3) of the dofs that the Dirichlet condition `bc` prescribes, in the
    order of its per-dof values."""
    k = next(i for i, d in enumerate(problem.dirichlet) if d is bc)
    return problem.V.tabulate_dof_coordinates()[problem.bc_dofs[k] // problem.bs]


def _loads(problem):
    """Every load of the problem: Dirichlet conditions, then tractions and body forces."""
    return [*problem.dirichlet, *(load for load, _ in problem.bulk.rhs)]


def describe(load):
    """A short name of a load for progress lines: 'cylinder_top.u_y', 'traction lower_left'."""
    if _attr(load) == "scale":
        return f"{type(load).__name__.lower()} {getattr(load, 'boundary', None) or ''}".strip()
    b = load.boundary if isinstance(load.boundary, str) else "point"
    return f"{b}.u_{'all' if load.component is None else 'xyz'[load.component]}"


def _global(problem, v):
    """A float, or (min, max) of a per-dof array over every rank (collective; a rank may hold
    none of the condition's dofs)."""
    if np.ndim(v) == 0:
        return float(v)
    from mpi4py import MPI

    lo = problem.comm.allreduce(float(np.min(v, initial=np.inf)), op=MPI.MIN)
    return lo, problem.comm.allreduce(float(np.max(v, initial=-np.inf)), op=MPI.MAX)


def _fmt(v):
    return f"{v:.6g}" if np.ndim(v) == 0 else f"[{v[0]:.4g} .. {v[1]:.4g}]"


def _record(v):
    """A value for metrics.json: the float, or the range (min, max) of a per-dof array."""
    return float(v) if np.ndim(v) == 0 else {"min": v[0], "max": v[1]}


def _move(problem, moves, steps, label):
    """One stage: every load held at its current value except `moves` [(load, target)], which
    follow straight paths; lam 0 -> 1 in `steps` load steps. Returns (load steps, iterations)."""
    moving = {id(load): target for load, target in moves}
    for load in _loads(problem):
        start = current_value(problem, load)
        target = moving.get(id(load), start)
        if callable(target):  # a function of the coordinates x (3, n) of the condition's dofs
            X = dof_coordinates(problem, load)
            target = np.broadcast_to(target(X.T), (len(X),))
        target = np.asarray(target, float) if np.ndim(target) else float(target)
        setattr(load, _attr(load), Path(start, target))
    n0 = len(problem.steps)
    problem.lam = 0.0
    problem.solve(int(steps), label=label)
    return len(problem.steps) - n0, sum(s.iterations for s in problem.steps[n0:])


def _as_moves(loads, targets):
    if isinstance(loads, (list, tuple)):
        targets = targets if isinstance(targets, (list, tuple)) else [targets] * len(loads)
        if len(targets) != len(loads):
            raise ValueError(f"ramp: {len(loads)} loads but {len(targets)} targets")
        return list(zip(loads, targets))
    return [(loads, targets)]


def ramp(problem, bc, target, steps=1, label="ramp", boundary=None, names=None):
    """Move one load (or a list of loads) from its current value to `target` (a float, a per-dof
    array, a function f(x) of the coordinates x (3, n) of a Dirichlet condition's dofs, or a
    list of these aligned with the loads) in `steps` equal load steps, the others held.
    The reaction reported is the one at `boundary` (default: the boundary of the first moved
    Dirichlet condition on a named boundary; none if there is no such condition). names: the
    loads' names in the progress line and the record (default: `describe`).
    Raises ContactSolverError when Newton fails after its cut-backs."""
    moves = _as_moves(bc, target)
    names = [describe(ld) for ld, _ in moves] if names is None else list(names)
    if boundary is None:
        named = [
            ld.boundary for ld, _ in moves if _attr(ld) == "value" and isinstance(ld.boundary, str)
        ]
        boundary = named[0] if named else None
    nsteps, its = _move(problem, moves, steps, label)
    now = [_global(problem, current_value(problem, ld)) for ld, _ in moves]
    values = {n: _record(v) for n, v in zip(names, now)}
    rec = StageRecord("ramp", label, nsteps, its, values=values, boundary=boundary)
    reached = ", ".join(f"{n} = {_fmt(v)}" for n, v in zip(names, now))
    if boundary is not None:
        rec.force = [float(f) for f in problem.reaction(boundary)]
        reached += f"; reaction on {boundary} = [{', '.join(f'{f:.6g}' for f in rec.force)}]"
    problem.log(f"{label}: {reached} ({nsteps} load steps, {its} Newton iterations)")
    return rec


def reach_force(
    problem,
    bc,
    boundary,
    component,
    target,
    first_guess,
    tol=1e-3,
    max_iter=12,
    monotone=False,
    steps=1,
    label="force",
    name=None,
    method="newton",
):
    """Force control: the value of the Dirichlet condition `bc` that makes the reaction
    component `component` at `boundary` equal to `target` (name: the condition's name in
    progress lines and the record, default `describe`).

    method="newton" (a constant condition): the value is an unknown of Newton and the reaction
    an equation (`force_control`); the reaction is ramped from its current value to the target
    in `steps` load steps (monotonic loading whatever `monotone`), each one Newton solve, and
    reached to Newton's tolerance; `first_guess` starts the first step.

    method="secant" (or a condition with a value per dof): secant iterations until the
    reaction is within tol |target| of the target.

    Each iterate is a stage from the last one (the first in `steps` load steps, the others in
    one), starting from the current value and reaction; `first_guess` is the first value of
    the condition tried. Frictionless loading is path independent, so the secant may step
    back. monotone=True keeps the loading monotonic (friction: Cattaneo-Mindlin assumes it):
    the secant aims at the near end of the tolerance band, which it reaches from below for a
    reaction concave in the displacement (slip softens it), and a step that would reverse
    the direction of loading raises. Raises ContactSolverError when the force is not reached
    in `max_iter` stages."""
    if method not in ("newton", "secant"):
        raise ValueError(f"method: 'newton' or 'secant', not {method!r}")
    target = float(target)
    name = describe(bc) if name is None else name
    if method == "newton" and np.ndim(current_value(problem, bc)) == 0:
        return _reach_in_newton(
            problem, bc, boundary, component, target, first_guess, tol, steps, label, name
        )
    history = [(current_value(problem, bc), float(problem.reaction(boundary)[component]))]
    value = float(first_guess)
    nsteps = its = 0
    for k in range(int(max_iter)):
        n, i = _move(problem, [(bc, value)], steps if k == 0 else 1, f"{label} {name}={value:.6g}")
        nsteps, its = nsteps + n, its + i
        force = problem.reaction(boundary)
        history.append((value, float(force[component])))
        (v0, f0), (v1, f1) = history[-2], history[-1]
        if abs(f1 - target) <= tol * abs(target):
            rec = StageRecord("force", label, nsteps, its, values={name: float(v1)})
            rec.boundary, rec.force = boundary, [float(f) for f in force]
            rec.target, rec.secant_iterations, rec.method = target, k + 1, "secant"
            problem.log(
                f"{label}: reaction {'xyz'[component]} on {boundary} = {f1:.6g} "
                f"(target {target:.6g}) at {name} = {v1:.6g} after {k + 1} secant steps "
                f"({nsteps} load steps, {its} Newton iterations)"
            )
            return rec
        if f1 == f0:
            raise ContactSolverError(
                f"{label}: the reaction on {boundary} did not change between "
                f"{name} = {v0:.6g} and {v1:.6g} (no contact?)"
            )
        aim = target
        if monotone:  # the near end of the band, so that a small overshoot stays inside it
            aim = target - 0.5 * tol * abs(target) * np.sign(target - f1)
        value = v1 + (aim - f1) * (v1 - v0) / (f1 - f0)
        if monotone and (value - v1) * (v1 - v0) < 0:
            raise ContactSolverError(
                f"{label}: monotonic loading would reverse at {name} = "
                f"{v1:.6g} (reaction {f1:.6g}, target {target:.6g})"
            )
    raise ContactSolverError(
        f"{label}: reaction {'xyz'[component]} on {boundary} = {f1:.6g} did "
        f"not reach {target:.6g} (tol {tol:g}) in {max_iter} secant steps"
    )


def _reach_in_newton(
    problem, bc, boundary, component, target, first_guess, tol, steps, label, name
):
    """reach_force's method="newton": the condition's value solved for with the reaction."""
    from dolfinx_forms.solvers.force_control import ForceControl

    for load in _loads(problem):  # every load held at its current value
        v = current_value(problem, load)
        setattr(load, _attr(load), Path(v, v))
    index = next(i for i, d in enumerate(problem.dirichlet) if d is bc)
    control = ForceControl(problem, index, boundary, component, target, first_guess)
    bc.value, problem.control = control, None
    n0 = len(problem.steps)
    problem.lam, problem.control = 0.0, control
    try:
        problem.solve(int(steps), label=f"{label} {name}")
    finally:
        problem.control = None
        bc.value = Path(control.s, control.s)
        control.destroy()
    nsteps = len(problem.steps) - n0
    its = sum(s.iterations for s in problem.steps[n0:])
    force = problem.reaction(boundary)
    f1 = float(force[component])
    if not abs(f1 - target) <= tol * abs(target):  # Newton's tolerance is far tighter
        raise ContactSolverError(
            f"{label}: reaction {'xyz'[component]} on {boundary} = {f1:.6g} is not the target "
            f"{target:.6g} (tol {tol:g}) after Newton converged"
        )
    rec = StageRecord("force", label, nsteps, its, values={name: float(control.s)})
    rec.boundary, rec.force, rec.target, rec.method = (
        boundary,
        [float(f) for f in force],
        target,
        "newton",
    )
    problem.log(
        f"{label}: reaction {'xyz'[component]} on {boundary} = {f1:.6g} (target {target:.6g}) "
        f"at {name} = {control.s:.6g}, solved for in Newton ({nsteps} load steps, {its} Newton "
        "iterations)"
    )
    return rec


def friction_on(problem, mu, label="friction"):
    """Switch friction to mu between stages. Going from mu = 0 to mu > 0 starts from zero
    tangential traction: the committed plastic slip becomes the current tangential gap."""
    old = problem.mu
    problem.set_friction(mu)
    problem.log(
        f"{label}: mu = {problem.mu:g} (was {old:g})"
        + ("; tangential traction starts from zero" if old == 0 < problem.mu else "")
    )
    return StageRecord("friction", label, values={"mu": problem.mu})
