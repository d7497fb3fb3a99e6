"""Newton's method on R(u) = 0 with load steps and exact cut-back.

`newton` iterates at one load level from the committed state; `load_steps` ramps the load
level in equal steps and halves a step that fails (no convergence in `max_iterations`, a
repeated active set without residual decrease, a linear-solver failure, a non-finite residual),
restoring u and the friction history exactly, at most `max_cutbacks` times.
"""

import time
from dataclasses import dataclass, field

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc


class ContactSolverError(RuntimeError):
    """Newton/linear-solver failure, with the load step and iteration where it happened."""


@dataclass
class NewtonOptions:
    rtol: float = 1e-10  # residual relative to the first residual of the step
    ftol: float = 1e-13  # round-off floor, relative to the force scale (internal, external)
    atol: float = 0.0  # absolute residual floor (force units); 0: none, the test is scale-free
    stol: float = 1e-12  # increment relative to |u|
    max_iterations: int = 25
    max_cutbacks: int = 6
    fd_tangent: bool = False  # verification only: central differences of the contact residual
    fd_step: float = 1e-9


@dataclass
class StepLog:
    lam: float
    iterations: int
    residuals: list = field(default_factory=list)
    cutback: bool = False


def newton(problem, lam):
    """Newton at load level lam from the committed state of `problem` (a ContactProblem).
    Returns (ok, residuals, why)."""
    opts = problem.newton
    problem.set_bc_values(lam)
    residuals, seen = [], {}
    r0 = None
    for it in range(opts.max_iterations + 1):
        r = problem.residual(lam, with_tangent=True, predictor=it == 0)
        residuals.append(r)
        if not np.isfinite(r):
            return (
                False,
                residuals,
                (
                    f"non-finite residual at iteration {it} (a singular system? every body needs "
                    "its rigid motions held by Dirichlet conditions or by contact; a frictionless "
                    "body can slide along the contact)"
                ),
            )
        if r0 is None:
            r0 = r
        # relative to the step's first residual, with a round-off floor relative to the
        # problem's force scale: no absolute floor that would accept the initial guess of a
        # problem with small forces (E = 1e-12 converges like E = 1)
        if r <= max(opts.rtol * r0, opts.ftol * problem.force_scale, opts.atol):
            return True, residuals, ""
        if it > 0:
            dnorm, unorm = problem.du.vector.norm(), problem.u.vector.norm()
            if dnorm <= opts.stol * max(unorm, 1e-300) and r <= np.sqrt(opts.rtol) * r0:
                return True, residuals, ""
            # stalled at round-off (e.g. the cancelling terms of a finite-strain stress at small
            # strain): no decrease, already within 1e3 rtol of the target, negligible update
            stalled = it >= 2 and r > 0.5 * residuals[-2]
            if stalled and r <= 1e3 * opts.rtol * r0 and dnorm <= 1e-8 * max(unorm, 1e-300):
                return True, residuals, ""
        # An active set seen before without a lower residual: Newton is cycling. The states
        # live on the ranks that hold the pairs: the set compared is the union over the ranks
        # (one rank's part can repeat while another's changes).
        sig = tuple(problem.comm.allgather(problem.contact.signature()))
        cycling = any(sig) and sig in seen and r >= 0.999 * seen[sig]
        if cycling:
            return False, residuals, f"active set cycles (iteration {it})"
        seen[sig] = min(r, seen.get(sig, np.inf))
        if it == opts.max_iterations:
            break
        with problem.phase("solve"):
            problem.R.scale(-1.0)
            try:
                problem.ksp.setOperators(problem.J)
                problem.ksp.solve(problem.R, problem.du.vector)
            except PETSc.Error as e:
                return False, residuals, f"linear solver error {e.ierr} at iteration {it}"
            reason = problem.ksp.getConvergedReason()
            if reason < 0:
                return (
                    False,
                    residuals,
                    f"linear solver diverged (reason {reason}) at iteration {it}",
                )
        problem.du.x.scatter_forward()
        problem.u.x.array[:] += problem.du.x.array
    return False, residuals, f"no convergence in {opts.max_iterations} iterations"


def load_steps(problem, num_steps=1, lam_end=1.0, label="step", initial_guess=None):
    """Ramp the load level of `problem` from its committed value to lam_end in num_steps
    equal steps, with cut-back; one progress line per accepted step. initial_guess(problem,
    lam) may set u before the first Newton iteration of a step. Raises ContactSolverError."""
    dlam = (lam_end - problem.lam) / num_steps
    cuts = 0
    while problem.lam < lam_end - 1e-14 * max(1.0, abs(lam_end)):
        target = min(problem.lam + dlam, lam_end)
        if initial_guess is not None:
            initial_guess(problem, target)
        t0 = time.perf_counter()
        ok, residuals, why = newton(problem, target)
        if ok:
            problem.commit(target)
            problem.steps.append(StepLog(target, len(residuals) - 1, residuals, cuts > 0))
            nst = problem.comm.allreduce(problem.contact.state_counts(), MPI.SUM)
            problem.log(
                f"{label} lam={target:.4f}: {len(residuals) - 1} Newton iterations, "
                f"|R| {residuals[0]:.2e} -> {residuals[-1]:.2e}, "
                f"open/stick/slip {nst[0]}/{nst[1]}/{nst[2]} "
                f"({time.perf_counter() - t0:.2f} s)"
            )
            continue
        problem.restore()
        cuts += 1
        if cuts > problem.newton.max_cutbacks:
            raise ContactSolverError(
                f"{label}: Newton failed at load level {target:.6g} ({why}); residuals "
                + ", ".join(f"{r:.3e}" for r in residuals[-5:])
                + f"; gave up after {problem.newton.max_cutbacks} step cut-backs"
            )
        dlam /= 2
        problem.log(f"{label} lam={target:.4f}: {why}; cutting the step to {dlam:.4g}")
