"""Library helpers the demos share: the uniform state of the inclined interface
(analytic.inclined_uniaxial_state), the nearest-vertex marker (boundary.nearest_vertex_marker)
and the slip measures of a frictional interface (compare.slip_results, slip_limit)."""

import numpy as np
import pytest
from mpi4py import MPI

from dolfinx_forms.analysis import analytic, compare
from dolfinx_forms.fem.boundary import nearest_vertex_marker


def test_inclined_state_without_penalty():
    """Bonded (eps = 0): s = E' d / H and the traction ratio is tan theta."""
    E, nu, d, H, slope = 1000.0, 0.3, 1.0, 1000.0, 0.2
    r = analytic.inclined_uniaxial_state(E, nu, d, H, slope)
    s = E / (1 - nu**2) * d / H
    cos2 = 1 / (1 + slope**2)
    assert r["s"] == pytest.approx(s, rel=1e-14)
    assert r["exx"] == pytest.approx(nu * (1 + nu) * s / E, rel=1e-14)
    assert r["p_n"] == pytest.approx(s * cos2, rel=1e-14)
    assert abs(r["tau_t"]) / r["p_n"] == pytest.approx(slope, rel=1e-14)
    assert r["gx"] == 0.0


def test_inclined_state_with_penalty_is_compatible():
    """With penalty springs the top displacement is the bodies' shortening plus the vertical
    component of the interface jump g = eps_n p_n-part n + eps_t tau_t t: both give -d."""
    E, nu, d, H, slope, en, et = 1000.0, 0.3, 1.0, 1000.0, 0.2, 0.025, 0.025
    r = analytic.inclined_uniaxial_state(E, nu, d, H, slope, en, et)
    n = np.array([-slope, 1.0]) / np.hypot(1.0, slope)
    t = np.array([-n[1], n[0]])
    traction = r["s"] * np.array([0.0, -n[1]])  # on the lower body's face, from the upper
    jump = en * (traction @ n) * n + et * (traction @ t) * t
    shortening = r["s"] * (1 - nu**2) * H / E
    assert -shortening + jump[1] == pytest.approx(-d, rel=1e-14)
    assert r["gx"] == pytest.approx(jump[0], rel=1e-14)
    assert r["p_n"] == pytest.approx(-(traction @ n), rel=1e-14)
    assert r["tau_t"] == pytest.approx(traction @ t, rel=1e-14)
    assert r["s"] < E / (1 - nu**2) * d / H  # the springs soften the column


def test_nearest_vertex_marker():
    from dolfinx import mesh

    m = mesh.create_rectangle(MPI.COMM_WORLD, [[0.0, 0.0], [1.0, 1.0]], [4, 4])
    marker = nearest_vertex_marker(m, (0.6, 0.0), on=lambda x: np.isclose(x[1], 0.0))
    x = np.array([[0.5, 0.75, 0.5, 0.5], [0.0, 0.0, 0.25, 1e-12], [0.0, 0.0, 0.0, 0.0]])
    assert marker(x).tolist() == [True, False, False, True]
    corner = nearest_vertex_marker(m, (2.0, 2.0))  # every vertex qualifies
    assert corner(np.array([[1.0, 0.75], [1.0, 1.0], [0.0, 0.0]])).tolist() == [True, False]
    with pytest.raises(ValueError, match="no vertex"):
        nearest_vertex_marker(m, (0.5, 0.0), on=lambda x: x[1] > 2.0)


def test_slip_results_and_limit():
    pts = dict(
        x=np.array([0.0, 1.0, 2.0, 3.0, 4.0]),
        state=np.array([2, 1, 2, 1, 0]),
        slip=np.array([1e-3, 0.0, 2e-3, 0.0, 0.0]),
        p_n=np.array([1.0, 2.0, 2.0, 1.0, 0.0]),
        p_t=np.array([0.2, -0.3, 0.4, 0.1, 0.0]),
    )
    interior = np.array([False, True, True, True, False])
    r = compare.slip_results(pts, interior, tol=1e-6)
    assert r["slips"] and r["max_plastic_slip"] == 2e-3 and r["max_plastic_slip_interior"] == 2e-3
    assert r["slip_fraction"] == 0.5 and r["slip_fraction_interior"] == pytest.approx(1 / 3)
    assert r["end_slip_points"] == 1 and r["num_points"] == dict(open=1, stick=2, slip=2)
    assert (r["traction_ratio_min"], r["traction_ratio_max"]) == (0.1, 0.2)
    assert (r["traction_ratio_min_all"], r["traction_ratio_max_all"]) == (0.1, 0.2)
    assert not compare.slip_results(pts, interior, tol=1e-2)["slips"]
    none = compare.slip_results(pts, np.zeros(5, bool), tol=1e-6)
    assert not none["slips"] and none["traction_ratio_min"] is None
    ((label, (x, y)),) = compare.slip_limit(pts, 0.5).items()
    assert "slip limit" in label and np.isnan(x[5]) and y[:5].tolist() == [0.5, 1, 1, 0.5, 0]
    assert y[6:].tolist() == [-0.5, -1, -1, -0.5, 0]
