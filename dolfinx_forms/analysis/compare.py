"""Measures of the computed contact and their comparison with the analytic references
(analytic.py): the one evaluation of Hertz / Cattaneo-Mindlin and of the patch test, used by
the demos and by the scene runner.

Every function takes the contact points of `output.gather_points` (sorted by x) and returns
plain floats (None where not defined) for metrics.json.
"""

import numpy as np

from dolfinx_forms.analysis import analytic

__all__ = ["rel_l2", "contact_results", "hertz", "patch", "slip_limit", "extreme", "slip_results"]


def rel_l2(w, a, b):
    """sqrt(sum w (a - b)^2 / sum w b^2), the weighted relative L2 difference (None: b = 0)."""
    den = np.sum(w * b**2)
    return float(np.sqrt(np.sum(w * (a - b) ** 2) / den)) if den > 0 else None


def contact_results(pts, mu):
    """Measures of the contact points, any scene: point counts per state, forces, contact
    length, peak pressure and shear, penetration, and the half-widths of the contact zone
    (active points, ends at the zero of the gap) and, with mu > 0, of the stick zone (active
    points that never slipped since friction was switched on: a point of the slip zone may be
    momentarily `stick` in a small last load increment). The zones are along x: half-widths
    suit interfaces that run along x."""
    from dolfinx_forms.solvers.problem import zone_ends

    x, p, q, w, gap, slip, state = (
        pts[k] for k in ("x", "p_n", "p_t", "w", "gap_n", "slip", "state")
    )
    active = state != 0
    res = {
        "num_points": {n: int(np.sum(state == k)) for k, n in enumerate(("open", "stick", "slip"))},
        "contact_force": float(np.sum(w * p)),
        "tangential_force": float(np.sum(w * q)),
        "contact_length": float(np.sum(w[active])),
        "peak_pressure": float(p.max()) if p.size else None,
        "shear_max": float(np.abs(q).max()) if q.size else None,
        "max_penetration": float(max(0.0, -gap[active].min())) if active.any() else None,
    }
    xl, xr = zone_ends(x, active, gap)
    res["contact_half_width"] = None if xl is None else float(0.5 * (xr - xl))
    res["contact_centre"] = None if xl is None else float(0.5 * (xr + xl))
    if mu > 0:
        # 1e-6 of the largest slip: the penalty's stick points have none at all, the augmented
        # Lagrangian's what its loop tolerance leaves (eps_t al_rtol tau)
        slipped = np.abs(slip) > 1e-6 * max(np.abs(slip).max(initial=0.0), 1e-300)
        sl, sr = zone_ends(x, active & ~slipped)
        res["stick_half_width"] = None if sl is None else float(0.5 * (sr - sl))
    return res


def hertz(pts, P, R, E_star, mu=0.0, Q=None):
    """Hertz line contact at the computed load P (and Cattaneo-Mindlin at the computed
    tangential force Q, if given with mu > 0): (results, analytic, curves).

    results: pressure_rel_l2_error of p(x) against Hertz (and tangential_ratio |Q|/(mu P),
    traction_rel_l2_error of |q(x)| while |Q| < mu P); pressure_rel_l2_error_circle against
    the pressure of the circle itself to order (a/R)^4 (`analytic.circle_pressure`: Hertz's
    parabola is 0.4 % off it at a/R = 0.1, a floor under any converging method's error against
    Hertz; with friction traction_rel_l2_error_circle likewise, `analytic.circle_mindlin`);
    analytic: contact_half_width a, peak_pressure p0 (and stick_half_width c),
    contact_half_width_circle (and stick_half_width_circle); curves: {label: (x, y)} for the
    plot."""
    a, p0 = analytic.hertz_line(P, R, E_star)
    x, w = pts["x"], pts["w"]
    a_c = analytic.circle_line(P, R, E_star)
    res = {
        "pressure_rel_l2_error": rel_l2(w, pts["p_n"], analytic.hertz_pressure(x, a, p0)),
        "pressure_rel_l2_error_circle": rel_l2(
            w, pts["p_n"], analytic.circle_pressure(x, a_c, R, E_star)
        ),
    }
    an = {
        "contact_half_width": float(a),
        "peak_pressure": float(p0),
        "contact_half_width_circle": float(a_c),
    }
    xs = np.linspace(-1.5 * a, 1.5 * a, 400)
    curves = {"Hertz p(x)": (xs, analytic.hertz_pressure(xs, a, p0))}
    if Q is not None and mu > 0:
        res["tangential_ratio"] = float(abs(Q) / (mu * P))
        if abs(Q) < mu * P:  # partial slip
            c = float(analytic.mindlin_stick_half_width(a, Q, mu, P))
            qa = analytic.mindlin_shear(x, a, c, p0, mu)
            res["traction_rel_l2_error"] = rel_l2(w, np.abs(pts["p_t"]), qa)
            an["stick_half_width"] = c
            _, c_c = analytic.circle_mindlin(P, Q, mu, R, E_star)
            qc = analytic.circle_mindlin_shear(x, a_c, c_c, R, E_star, mu)
            res["traction_rel_l2_error_circle"] = rel_l2(w, np.abs(pts["p_t"]), qc)
            an["stick_half_width_circle"] = float(c_c)
            sign = np.sign(np.sum(pts["p_t"])) or 1.0
            curves["Cattaneo-Mindlin q(x)"] = (xs, sign * analytic.mindlin_shear(xs, a, c, p0, mu))
    return res, an, curves


def patch(pts, E, nu, displacement, height, eps_n):
    """The frictionless patch test: uniform pressure, exact E' d / H and penalised
    E' d / (H + E' eps_n) (eq 51 compliance), E' = E / (1 - nu^2): (results, analytic, curves).

    results: pressure_mean, pressure_max_rel_deviation (from the penalised value),
    pressure_rel_error_vs_exact, pressure_rel_l2_error (against the penalised value); empty
    without contact points."""
    Ep, d, H = E / (1 - nu**2), displacement, height
    exact = float(analytic.patch_pressure(E, nu, d / H))
    penalised = float(Ep * d / (H + Ep * eps_n))
    an = {"pressure": exact, "pressure_penalised": penalised}
    p, w = pts["p_n"], pts["w"]
    if not p.size:
        return {}, an, {}
    res = {
        "pressure_mean": float(np.sum(w * p) / np.sum(w)),
        "pressure_max_rel_deviation": float(np.max(np.abs(p - penalised)) / penalised),
        "pressure_rel_error_vs_exact": float(np.max(np.abs(p - exact)) / exact),
        "pressure_rel_l2_error": rel_l2(w, p, np.full_like(p, penalised)),
    }
    xs = np.array([pts["x"].min(), pts["x"].max()])
    return res, an, {"exact": (xs, [exact] * 2), "penalised": (xs, [penalised] * 2)}


def slip_limit(pts, mu):
    """The Coulomb limit +- mu p_n at the contact points, as a plot curve {label: (x, y)} (the
    two branches separated by a NaN)."""
    x, mp = pts["x"], mu * pts["p_n"]
    return {"+- mu p_n (slip limit)": (np.r_[x, np.nan, x], np.r_[mp, np.nan, -mp])}


def extreme(a, f=np.max):
    """float(f(a)), None for an empty array (a metrics.json value)."""
    return float(f(a)) if a.size else None


def slip_results(pts, interior, tol):
    """Slip measures of a frictional interface: the verdict `slips` (the committed plastic
    slip exceeds `tol` at an `interior` point, a mask of the contact points that leaves out
    the ends, where the geometry is less accurate), the largest plastic slip and the fraction
    of slipping points (all active points and interior ones), the slipping points outside
    the interior (end_slip_points), the points per state, and the range of the traction
    ratio |p_t|/p_n (interior, and _all: every active point)."""
    state, slip, pn, q = (pts[k] for k in ("state", "slip", "p_n", "p_t"))
    active = state != 0
    ratio, ratio_i = (np.abs(q[m]) / pn[m] for m in (active, interior))
    gi = np.abs(slip[interior])
    return dict(
        slips=bool(gi.size and gi.max() > tol),
        max_plastic_slip=extreme(np.abs(slip)),
        max_plastic_slip_interior=extreme(gi),
        slip_fraction=extreme(state[active] == 2, np.mean),
        slip_fraction_interior=extreme(state[interior] == 2, np.mean),
        end_slip_points=int(np.sum((state == 2) & ~interior)),
        num_points={n: int(np.sum(state == k)) for k, n in enumerate(("open", "stick", "slip"))},
        traction_ratio_min=extreme(ratio_i, np.min),
        traction_ratio_max=extreme(ratio_i),
        traction_ratio_min_all=extreme(ratio, np.min),
        traction_ratio_max_all=extreme(ratio),
        slip_threshold_mm=tol,
    )
