"""Newton's method on R(u) = 0 with load steps and exact cut-back.

`newton` iterates at one load level from the committed state; `load_steps` ramps the load
level in equal steps and halves a step that fails (no convergence in `max_iterations`, a
repeated active set without residual decrease, a linear-solver failure, a non-finite residual),
restoring u and the friction history exactly, at most `max_cutbacks` times. A converged step
whose active contact points reach the edge of the contact band is done again from the
committed state with the band doubled (`ContactProblem.grow_band`).
"""

import time
from dataclasses import dataclass, field, replace

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc


class ContactSolverError(RuntimeError):
    """Newton/linear-solver failure, with the load step and iteration where it happened."""


# NewtonOptions.rise_limit of the quasi-static finite-strain steps: the material-point path's
# (mpm/implicit.py RISE_LIMIT) and the body-fitted updated Lagrangian's (fem/updated.py)
QUASI_STATIC_RISE_LIMIT = 1.0


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
    line_search: bool = True  # halve a Newton step that does not lower the residual
    # a step that jumps back to an active set seen before, without a lower residual (a cycle),
    # is halved too, across the active set's change, before the solve gives up: the 20-disc
    # column (seed 3) ran 278 steps with 34 retried in 160 s instead of 391 with 62 in 190 s,
    # side by side (8.3 Newton iterations per step instead of 5.6)
    damp_cycles: bool = True
    # friction: the first iteration of a step is the elastic predictor (every closed point
    # sticks: residual and tangent of an infinite mu), the return mapping from the next on. A
    # platen moved sideways by a step of a stuck block (tests/mpm/test_mpm.py): 1 Newton
    # iteration, where the slip the step's motion predicts cycled stick/slip through 4
    # cut-backs (16 sub-steps); Hertz-Mindlin, the blocks, the incline, nine discs and four
    # grains take the iterations they took, the Brazilian disc 4.98 per step instead of 4.84,
    # the grain assembly 7.8 instead of 7.9, all with the same answers
    stick_predictor: bool = True
    max_backtracks: int = 5
    # on a nonlinear bulk, a step that changes the active set and raises the residual above
    # rise_limit times the lowest residual of the solve so far is halved like one that keeps it
    # (None: inf, steps across a change taken whole, except on the material-point path's
    # quasi-static steps and the body-fitted updated Lagrangian's (fem/updated.py), which take
    # QUASI_STATIC_RISE_LIMIT = 1). Finite-strain J2 with friction
    # (demos/disc_crush.py, the MPM): whole steps across changes of the contact set on a soft
    # plastic zone raised the residual from 35 to 1e7 in 20 iterations (|du| 8 h an iteration;
    # the tangent is the consistent one, to 1e-9 against differences) and failed perfect
    # plasticity (h = 1, 16 steps, yield 10, H = 0 and 1) at step 8-9 and the default J2 (H =
    # 100, h = 0.4) at step 24; with rise_limit = 1 all three complete (11 Newton iterations
    # instead of 31 with cut-backs at the first step), the neo-Hookean crush and the J2 block
    # give the same forces (2e-12). A linear bulk keeps whole steps: with penalty contact its
    # problem is piecewise linear and they end the semismooth Newton in a few iterations (Hertz
    # under force control: 10-16 iterations instead of <= 6 when halved). The disc crush's
    # body-fitted J2 reference diverged alike from a whole platen move; with rise_limit = 1 it
    # takes whole moves at h = 1 / 0.5 / 0.25 with no cut-back (docs/demos/disc_crush.md)
    rise_limit: float | None = None
    # augmented Lagrangian (Uzawa): stop when no multiplier changes by more than al_rtol of
    # the largest traction *and* no gap by more than al_gtol h (the change of a multiplier is
    # the gap over eps: a soft eps converges slowly, with small changes far from the answer);
    # a step that needs more than max_augmentations solves fails
    al_rtol: float = 1e-7
    al_gtol: float = 1e-6
    max_augmentations: int = 300
    # inexact Uzawa: the step's first solve stops once its residual is below al_first times
    # its first residual r0, a later one below al_eta times the multipliers' last relative
    # change times r0, and the loop ends with a solve to rtol (0, 0: every solve to rtol).
    # Hertz a/20, Newton iterations (Uzawa solves): cut 16 (9) -> 11 (7), body-fitted 21 (11)
    # -> 12 (10), p(x) the same to 6 digits; al_first = 1e-3 or al_eta = 1e-2, 1e-4 cost 1-2
    # iterations more on the cut path
    al_first: float = 1e-2
    al_eta: float = 1e-3
    # a loop whose largest multiplier change makes no new low for al_stall updates (the active
    # set cycling between updates) halves its step and restarts the mixing: a soft disc
    # between stiff blocks (E 200 / 1e5, demos/scenes/disc_squeeze.toml, full steps) cycled at
    # 0.4-6 of the largest traction for 300 updates, 32 cut-backs and 132 s; with this 15 s
    al_stall: int = 15
    # friction: the loop's first leg, at the contact set's eps_t_start, hands over to its
    # eps_t_final once no multiplier changes by more than al_switch of the largest traction
    # (the second leg converges to al_rtol). Mindlin a/20, mu 0.1 / 0.3 / 1, both paths:
    # 19-22 Newton iterations at 1e-3 instead of 23-26 with the first leg converged to al_rtol
    # (18-21 without the continuation), the same answers
    al_switch: float = 1e-3
    # the P1 multiplier nodes realigned with the contact zones' edges at most this often per
    # loop (`ContactSet.align_edges`; 0: the nodes stay at equal spacing along Gamma_c): first
    # once no gap changes by more than al_align_gtol h and no multiplier by more than
    # al_align_rtol of the largest traction (the gaps converged, before the tractions' last
    # digits and the final solve), then at each fixed point where an edge moved by 0.1 node
    # spacing. Hertz a/20, Newton iterations: R 10 at eps0 <= 1 / 1e2 / 1e4: 17 / 32 / 52
    # instead of 20 / 37 / 58 (aligned at fixed points only); R 40 17 instead of 20, both paths;
    # p(x) the same to 4e-8 over eps0. At 1e-5 h: 16 / 30 / 52, but the nodes, and p(x) to
    # 2e-6, then depend on eps0 and on the path to the fixed point
    al_align: int = 3
    al_align_rtol: float = 1e-2
    al_align_gtol: float = 1e-6
    # the later solves of an augmented loop start next to the answer: where the tangent
    # changes with the iterate (a nonlinear bulk, slipping points) they keep the tangent and
    # factorisation of their first iteration while the active set stays and each iteration
    # lowers the residual at least al_frozen_rate times (a modified Newton); slower, the
    # tangent is made afresh for the rest of that solve. block_compression (neo-Hookean, 30 %
    # in 20 steps, h = 0.05): 415 -> 133 factorisations, 8.5 -> 5.6 s, forces to 7e-11
    al_frozen: bool = True
    al_frozen_rate: float = 0.25


def quasi_static(problem_kw):
    """problem_kw with its NewtonOptions' rise_limit set to QUASI_STATIC_RISE_LIMIT, unless the
    caller set one (the option's comment says why)."""
    newton = problem_kw.get("newton") or NewtonOptions()
    if newton.rise_limit is not None:
        return problem_kw
    return dict(problem_kw, newton=replace(newton, rise_limit=QUASI_STATIC_RISE_LIMIT))


@dataclass
class StepLog:
    lam: float
    iterations: int
    residuals: list = field(default_factory=list)
    cutback: bool = False
    augmentations: int = 0  # augmented Lagrangian: the Newton solves after the first (Uzawa)


def tolerance(problem, r0):
    """The residual a Newton solve must reach: rtol of its first residual r0, with a round-off
    floor relative to the problem's force scale (and the user's absolute atol)."""
    opts = problem.newton
    return max(opts.rtol * r0, opts.ftol * problem.force_scale, opts.atol)


def newton(problem, lam, r_ref=0.0, early=0.0, guess=None):
    """Newton at load level lam from the committed state of `problem` (a ContactProblem).
    r_ref: a residual that the relative test may also refer to (the step's first residual, for
    the later solves of an augmented Lagrangian loop, which start near the answer). early: stop
    once the residual is below early times the first (an inexact solve of the Uzawa loop).
    guess(problem, lam): adds a predicted increment to u (`load_steps`); Newton starts from it
    only if it lowers the first residual (then without the stick predictor, which would read
    the predicted slip as stuck), and the relative test still refers to the residual of the
    committed state. Returns (ok, residuals, why)."""
    opts = problem.newton
    problem.set_bc_values(lam)
    residuals, seen = [], {}
    r0 = None
    r_zero, u_start = None, None  # with a guess: the committed state's residual and u
    if guess is not None and r_ref == 0:  # both residuals as the first iteration's, unstuck
        r_zero = problem.residual(lam, predictor=problem.predictor_gap > 0)
        u_start = problem.u.x.array.copy()
        guess(problem, lam)
        problem.set_bc_values(lam)
    # the later solves of an augmented loop start from a converged state (no predictor) and
    # take at least one iteration: the multipliers' change is below the step's tolerance
    later = r_ref > 0
    r_base, sig_base, backtracks = None, None, 0  # where the last Newton step started
    r_low = np.inf  # the lowest residual a Newton step started from (rise_limit)
    # a later solve keeps its first tangent while it converges where no key says the tangent
    # is the same (a nonlinear bulk, slipping points: al_frozen)
    frozen = later and opts.al_frozen
    for it in range(opts.max_iterations + 1):
        predictor = it == 0 and not later and problem.predictor_gap > 0
        guessed = it == 0 and r_zero is not None
        stick = it == 0 and not later and opts.stick_predictor and problem.contact.mu > 0
        # J is assembled once its key is known unless J holds the last keyed tangent (`_keep`)
        constant = not problem.bulk.nonlinear or frozen  # J depends on the active set only
        lazy = problem.J_key is not None and not (predictor or stick or not constant)
        r = problem.residual(
            lam, with_tangent=not lazy, predictor=predictor, stick=stick and not guessed
        )
        if guessed:
            problem.guess_taken = bool(r < r_zero)
            if not problem.guess_taken:  # no better than the committed state: start there
                problem.u.x.array[:] = u_start
                problem.u.x.scatter_forward()
                r = problem.residual(lam, with_tangent=not lazy, predictor=predictor, stick=stick)
        residuals.append(r)
        if not np.isfinite(r):
            # a step past what the state allows (finite strain: det F <= 0 beyond it) is
            # halved like one that does not lower the residual, before the solve gives up
            step = opts.line_search and r_base is not None and it < opts.max_iterations
            if step and backtracks < opts.max_backtracks:
                residuals.pop()
                backtracks += 1
                _backtrack(problem, 0.5**backtracks)
                continue
            where = problem.nonfinite()
            why = (
                where
                if where
                else "a singular system? every body needs its rigid motions held by Dirichlet "
                "conditions or by contact; a frictionless body can slide along the contact"
            )
            return False, residuals, f"non-finite residual at iteration {it} ({why})"

        if r0 is None:
            r0 = max(r, r_ref, r_zero or 0.0)
        # relative to the step's first residual, with a round-off floor relative to the
        # problem's force scale: no absolute floor that would accept the initial guess of a
        # problem with small forces (E = 1e-12 converges like E = 1)
        if (it > 0 or not later) and r <= max(tolerance(problem, r0), early * r0):
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
        # Line search: a step that keeps the active set but does not lower the residual (the
        # slip law's curvature) is halved, u = u_base + alpha du. A step that changes the active
        # set is taken whole: the semismooth Newton's residual need not fall monotonically;
        # unless, on a nonlinear bulk, it raises the residual above rise_limit times the solve's
        # lowest (a divergence through ever-changing active sets: a plastic zone's soft tangent),
        # or it jumped back to an active set seen before (a cycle, damp_cycles): halved too,
        # across the change, before giving up
        rise_limit = np.inf if opts.rise_limit is None else opts.rise_limit
        rise = sig == sig_base or (problem.bulk.nonlinear and r > rise_limit * r_low)
        worse = opts.line_search and r_base is not None and r > r_base and rise
        if worse or (cycling and opts.damp_cycles and r_base is not None):
            if backtracks < opts.max_backtracks and it < opts.max_iterations:
                backtracks += 1
                _backtrack(problem, 0.5**backtracks)
                continue
        if cycling:
            return False, residuals, f"active set cycles (iteration {it})"
        seen[sig] = min(r, seen.get(sig, np.inf))
        if it == opts.max_iterations:
            break
        # J is the same matrix (its factorisation reused) for a linear bulk, the same active
        # set, mu and a constant contact tangent (frictionless or no slipping point), no predictor
        if frozen and r_base is not None and r > opts.al_frozen_rate * r_base:
            frozen = constant = lazy = False  # too slow on the kept tangent: a fresh one
            problem.residual(lam, with_tangent=True)  # the same state: R is unchanged
        key = None
        if constant and not predictor and not stick:
            slip = problem.contact.mu > 0 and problem.comm.allreduce(
                int(problem.contact.state_counts()[2]), MPI.SUM
            )
            same = (sig, problem.contact.mu, problem.contact.eps_t)
            if not (slip or problem.bulk.nonlinear):
                key = same  # exactly the same J
            elif frozen:
                key = ("kept", *same)  # the first tangent of this active set, kept
        _keep(problem, key, lazy, lam)
        r_base, sig_base, backtracks = r, sig, 0
        r_low = min(r_low, r)
        # the residual Newton must reach: what an iterative linear solver has to resolve
        problem.linear.newton_target = max(opts.rtol * r0, opts.ftol * problem.force_scale)
        with problem.phase("solve"):
            problem.R.scale(-1.0)
            try:  # linear.py: a full factorisation, or the condensed bulk
                problem.linear.setup(problem.J, key)
                problem.linear.solve(problem.R, problem.du.vector)
                if problem.control is not None:  # force control: the bordered step
                    problem.control.border(problem.linear, problem.du.vector, lam)
            except PETSc.Error as e:
                return False, residuals, f"linear solver error {e.ierr} at iteration {it}"
            except RuntimeError as e:  # LinearSolverError, or PETSc's through the C++ glue
                return False, residuals, f"{e} at iteration {it}"
        problem.du.x.scatter_forward()
        problem.u.x.array[:] += problem.du.x.array
    return False, residuals, f"no convergence in {opts.max_iterations} iterations"


def _backtrack(problem, fraction):
    """Take `fraction` of the last Newton step back (u and the force control's load)."""
    problem.u.x.array[:] -= fraction * problem.du.x.array
    if problem.control is not None:
        problem.control.backtrack(fraction)


def _keep(problem, key, lazy, lam):
    """Make problem.J the tangent of this iteration, of `key` (None: no key). A residual
    evaluated without it (lazy) keeps the J of an earlier iteration, which is this one's when
    the keys agree: the key says the same J (a linear bulk, the same active set and mu, no
    slip), the contract the factorisations' reuse rests on. The force control's k = J^T 1_b
    belongs to its control, hence the control in the key. Otherwise the evaluation is repeated
    with the tangent (the same state: R is unchanged). Skips the tangent's copy of K, contact
    entries and assembly (1.6 of 1.8 ms per evaluation on cut Hertz a/20, 8.5k dofs) in the
    iterations of a settled active set: most of an augmented Lagrangian loop."""
    keyed = None if key is None else (key, id(problem.control))
    if lazy and (keyed is None or keyed != problem.J_key):
        problem.residual(lam, with_tangent=True)
    problem.J_key = keyed


def _dot(comm, a, b):
    return comm.allreduce(float(np.dot(a, b)), MPI.SUM)


def augmented_loop(problem, lam, residuals, depth=20):
    """`_augmented_loop`; the hybrid projection's rows, frozen where it cycled, are free again
    after it (the next load step chooses them afresh)."""
    try:
        return _augmented_loop(problem, lam, residuals, depth)
    finally:
        problem.contact.freeze_rows(False)


def _augmented_loop(problem, lam, residuals, depth=20):
    """The augmented Lagrangian's outer loop at load level lam, after a converged Newton solve:
    the fixed point lambda = T(lambda), T(lambda) = the tractions of the solution with
    multipliers lambda (Uzawa's update, seed 003), accelerated by Anderson mixing of the last
    `depth` iterates (Walker & Ni 2011; restarted when the update grows), its steps relaxed by
    the contact set's `relaxation`. Stops when no
    multiplier changes by more than al_rtol of the largest traction and no gap by more than
    al_gtol h, after a solve to rtol; the solves before stop early (NewtonOptions.al_eta).
    With friction the loop is a continuation in the tangential regularisation: it nearly
    converges (al_switch) at the contact set's eps_t_start first, then goes on from there at
    its eps_t_final (the fixed point wanted; started from the committed tractions it can
    cycle, `solver`).
    Appends the inner Newton residuals to `residuals`.
    Returns (ok, augmentations: the Newton solves after the first, why)."""
    cs, comm, opts = problem.contact, problem.comm, problem.newton
    rho = cs.relaxation  # the mixing parameter of Anderson's update
    # lambda - tau = gap / eps at an active law point: the gap tolerance in traction units
    h_eps = problem.scene.h_contact / max(cs.eps_n, cs.eps_t)  # a gap of h in traction units
    X, F = [], []
    x = cs.multipliers()
    u_good = problem.u.x.array.copy()  # the last converged solve and its tractions
    t_good = cs.tractions()
    fallbacks = solves = aligned = 0
    near_tried = False  # the alignment near the fixed point (al_align_rtol) was tried
    best, stalled = np.inf, 0  # the smallest change yet, updates since
    for k in range(opts.max_augmentations + 1):
        t = cs.tractions()
        f = t - x
        change = comm.allreduce(float(np.abs(f).max()) if f.size else 0.0, MPI.MAX)
        scale = comm.allreduce(float(np.abs(t).max()) if f.size else 0.0, MPI.MAX)
        best, stalled = (change, 0) if change < (1 - 1e-3) * best else (best, stalled + 1)
        if stalled >= opts.al_stall:  # cycling: a shorter step, the mixing restarted
            rho, X, F, best, stalled = 0.5 * rho, [], [], change, 0
            cs.halvings += 1
            cs.freeze_rows()  # the hybrid projection's rows stay as they are
            problem.log(
                f"augmented Lagrangian: no progress in {opts.al_stall} updates, step {rho:.3g}"
            )
        first_leg = cs.mu > 0 and cs.eps_t != cs.eps_t_final
        switch = first_leg and change <= max(
            opts.al_switch * scale, min(opts.al_rtol * scale, opts.al_gtol * h_eps)
        )
        if switch:  # continuation: from near this fixed point on to the one at the final eps_t
            cs.eps_t = cs.eps_t_final
            h_eps = problem.scene.h_contact / max(cs.eps_n, cs.eps_t)
            X, F, best, stalled = [], [], np.inf, 0
        done = change <= min(opts.al_rtol * scale, opts.al_gtol * h_eps)
        at_fixed_point = done and not switch and residuals[-1] <= tolerance(problem, residuals[0])
        # near the fixed point first, then at it (so whatever eps0): the P1 nodes aligned with
        # the contact edges, and the loop on to the new nodes' fixed point
        near = not (first_leg or near_tried) and change <= min(
            opts.al_align_rtol * scale, opts.al_align_gtol * h_eps
        )
        if (near or at_fixed_point) and aligned < opts.al_align:
            near_tried = True
            if comm.allreduce(cs.align_edges(), MPI.LOR):
                aligned += 1
                cs.alignments += 1
                problem.log(f"augmented Lagrangian: multiplier nodes aligned with the "
                            f"contact edges ({aligned}), after {solves} solves")  # fmt: skip
                X, F, best, stalled = [], [], np.inf, 0
                continue
        if switch or done:
            if at_fixed_point:
                return True, solves, ""
            # after a switch an inexact solve; else the last solve, which stopped early
            early = opts.al_eta * change / max(scale, 1e-300) if switch else 0.0
            ok, more, why = newton(problem, lam, residuals[0], early)
            residuals += more
            solves += 1
            if not ok:
                return False, solves, f"augmented Lagrangian, update {k}: {why}"
            u_good[:], t_good = problem.u.x.array, cs.tractions()
            continue
        if k == opts.max_augmentations:
            break
        if F and _dot(comm, f, f) > 4.0 * _dot(comm, F[-1], F[-1]):
            X, F = [], []  # the mixing made it worse: restart from a plain Uzawa step
        X.append(x.copy())
        F.append(f.copy())
        X, F = X[-(depth + 1) :], F[-(depth + 1) :]
        x = x + rho * f  # Uzawa: lambda <- tau (relaxed)
        if len(F) > 1:
            dF = np.array([F[i + 1] - F[i] for i in range(len(F) - 1)])
            dX = np.array([X[i + 1] - X[i] for i in range(len(X) - 1)])
            G = comm.allreduce(dF @ dF.T, MPI.SUM)
            rhs = comm.allreduce(dF @ f, MPI.SUM)
            gamma = np.linalg.lstsq(G + 1e-14 * np.trace(G) * np.eye(len(G)), rhs, rcond=None)[0]
            x = cs.admissible(x - (dX + rho * dF).T @ gamma)
        cs.set_multipliers(x)
        early = opts.al_eta * change / max(scale, 1e-300)
        ok, more, why = newton(problem, lam, residuals[0], early)
        residuals += more
        solves += 1
        if ok:
            u_good[:], t_good = problem.u.x.array, cs.tractions()
            continue
        if len(F) <= 1 or fallbacks == 3:
            return False, solves, f"augmented Lagrangian, update {k + 1}: {why}"
        # a mixed update too far for Newton: back to the last solve, a plain Uzawa step
        fallbacks += 1
        X, F = [], []
        problem.u.x.array[:] = u_good
        x = t_good.copy()
        cs.set_multipliers(x)
        ok, more, why = newton(problem, lam, residuals[0])
        residuals += more
        solves += 1
        if not ok:
            return False, solves, f"augmented Lagrangian, update {k + 1}: {why}"
        u_good[:], t_good = problem.u.x.array, cs.tractions()
    return (
        False,
        solves,
        f"augmented Lagrangian: multipliers still change by {change / scale:.2e} of the "
        f"largest traction after {opts.max_augmentations} updates",
    )


def load_steps(problem, num_steps=1, lam_end=1.0, label="step", initial_guess=None):
    """Ramp the load level of `problem` from its committed value to lam_end in num_steps
    equal steps, with cut-back; one progress line per accepted step. initial_guess(problem,
    lam) may add a predicted increment to u before the first Newton iteration of a step, taken
    where it lowers the first residual (`newton`). Raises ContactSolverError."""
    dlam = (lam_end - problem.lam) / num_steps
    cuts = 0
    while problem.lam < lam_end - 1e-14 * max(1.0, abs(lam_end)):
        target = min(problem.lam + dlam, lam_end)
        if problem.control is not None:
            problem.control.predict(target)
        t0 = time.perf_counter()
        problem.contact.start_step()
        early = problem.newton.al_first if problem.contact.augmented else 0.0
        ok, residuals, why = newton(problem, target, early=early, guess=initial_guess)
        augmentations = 0
        if ok and problem.contact.augmented:
            ok, augmentations, why = augmented_loop(problem, target, residuals)
        # active points at the band's edge: the step again from the committed state, with
        # the band doubled (no cut-back: the step converged)
        if ok and getattr(problem, "band_growth", 0) and problem.band_reached():
            if problem.grow_band(target):
                continue
            # the growth bound spent: the zone is cut off, the answer wrong (never exit 0)
            raise ContactSolverError(problem.band_errors[0])
        if ok:
            problem.commit(target)
            problem.steps.append(
                StepLog(target, len(residuals) - 1 - augmentations, residuals, cuts > 0)
            )
            problem.steps[-1].augmentations = augmentations
            nst = problem.comm.allreduce(problem.contact.state_counts(), MPI.SUM)
            aug = f" in {augmentations + 1} augmented solves" if problem.contact.augmented else ""
            states = (
                f"open/active {nst[0]}/{nst[1] + nst[2]}"  # frictionless: no stick, no slip
                if problem.contact.mu == 0
                else f"open/stick/slip {nst[0]}/{nst[1]}/{nst[2]}"
            )
            problem.log(
                f"{label} lam={target:.4f}: {len(residuals) - 1 - augmentations} Newton "
                f"iterations{aug}, |R| {residuals[0]:.2e} -> {residuals[-1]:.2e}, {states} "
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
