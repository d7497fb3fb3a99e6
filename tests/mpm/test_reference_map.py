"""The level set rebuilt from the material points (mpm/evolution.py): phi(x) = phi_0(X(x)), X the
MLS fit of the points' reference positions. The linear MLS basis reproduces affine maps, so
for any affine motion of a body the rebuilt contour is the moved initial shape to round-off,
after any number of steps."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

import dolfinx_forms as df
from dolfinx_forms import _cpp
from dolfinx_forms.mpm import evolution
from dolfinx_forms.mpm.material_points import MaterialPoints

R, H = 1.0, 0.1


def disc_points(spacing=H / 3):
    """Material points filling the unit disc at the Gauss-point spacing (h / 3)."""
    s = np.arange(-R, R + spacing, spacing)
    X = np.stack(np.meshgrid(s, s), -1).reshape(-1, 2)
    X = X[np.linalg.norm(X, axis=1) < R - 0.2 * spacing]
    return MaterialPoints(1, X.copy(), np.ones(len(X)), np.ones(len(X)), np.zeros((len(X), 3)))


def grid_around(centre, half=2.0):
    n = int(round(2 * half / H))
    lo = np.asarray(centre) - half
    return _cpp.StructuredGrid.uniform(list(lo), list(lo + n * H), [n, n])


@pytest.mark.parametrize(
    "A",
    [
        np.eye(2),
        np.array([[np.cos(2.0), -np.sin(2.0)], [np.sin(2.0), np.cos(2.0)]]),  # 115 degrees
        np.array([[1.3, 0.2], [-0.1, 0.8]]),  # a finite affine strain
    ],
    ids=["translation", "rotation", "affine"],
)
def test_affine_motion_is_reproduced_to_round_off(A):
    """Points moved by x = A X + c: every grid node within 3 h of the points gets
    phi_0(A^-1 (x - c)) to 1e-12 (the MLS fit of X is exact), so the zero contour is the image
    of the initial circle: an ellipse for a strain, at any position the body has reached. A
    node more than h from every point is outside."""
    pts, c = disc_points(), np.array([3.7, -1.3])
    pts.x = pts.X @ A.T + c
    grid = grid_around(c)
    phi = evolution.reference_map(grid, df.Circle((0.0, 0.0), R), pts, H)
    nodes = grid.nodes()
    exact = np.linalg.norm(np.linalg.solve(A, (nodes - c).T).T, axis=1) - R
    near = cKDTree(pts.x).query(nodes)[0] < 3 * H  # the fitted band around the body
    assert near[exact < 2 * H].all()
    assert np.abs(phi.values.ravel()[near] - exact[near]).max() < 1e-12
    assert np.all(phi.values.ravel()[~near] > 0)


def test_a_badly_supported_fit_does_not_grow_the_body():
    """Points of a thin strip (three rows, as at a grain's flattened contact): a node 2 h off
    the strip's side sees only a few nearly collinear points within the plain MLS support, and
    the plain fit mapped such a node into a grain's reference shape (a deposit's failure). The
    well-conditioned fit (rcond >= 1e-3) keeps every node beyond h / 2 of the points outside
    (the box's sides are h / 6 from the outer rows), with the fit alone up to h and the safety
    net beyond."""
    s = np.arange(-1.0, 1.0, H / 3)
    X = np.stack(np.meshgrid(s, [-H / 3, 0.0, H / 3]), -1).reshape(-1, 2)
    pts = MaterialPoints(1, X.copy(), np.ones(len(X)), np.ones(len(X)), np.zeros((len(X), 3)))
    shape = df.Box((-1.05, -0.05), (1.05, 0.05))
    grid = grid_around((0.0, 0.0))
    phi = evolution.reference_map(grid, shape, pts, H)
    d = cKDTree(pts.x).query(grid.nodes())[0]
    assert np.all(phi.values.ravel()[d > H / 2] > 0)


def test_a_drifted_level_set_is_reported():
    """mpm_run.levelset_warnings: a body whose level-set area is off its points' volume by more
    than 2 % is named (the advected grain of a deposit reached +22 %); within it, nothing."""
    from dolfinx_forms.app.mpm_run import levelset_warnings

    rec = dict(
        area_levelset={"a": 1.0, "b": 1.03, "c": 0.97}, volume_points=dict(a=1.001, b=1, c=1)
    )
    warnings = levelset_warnings(rec)
    assert len(warnings) == 2 and warnings[0].startswith("b: ") and warnings[1].startswith("c: ")


def test_a_spread_of_point_volumes_is_reported():
    """mpm_run.point_volume_warnings: a body whose points' det F (vol / vol0, the record's
    `point_volume_ratio` from the points) differ by more than a factor 2 is named, with the same
    text at every step; a body compressed uniformly by 40 % is not."""
    from dolfinx_forms.app.mpm_run import point_volume_warnings
    from dolfinx_forms.mpm.implicit import _ratio_range

    pts = disc_points()
    pts.vol = 0.6 * pts.vol0
    uniform = _ratio_range(pts)
    assert uniform == pytest.approx([0.6, 0.6], rel=1e-12)
    pts.vol[:2] = pts.vol0[:2] * np.array([0.005, 2.3])  # the column's grain near its wall
    broken = _ratio_range(pts)
    assert broken == pytest.approx([0.005, 2.3], rel=1e-12)
    rec = dict(point_volume_ratio={"a": uniform, "b": broken, "c": [0.5, 0.99]})
    warnings = point_volume_warnings(rec)
    assert len(warnings) == 1 and warnings[0].startswith("b: ")
    rec["point_volume_ratio"]["b"] = [0.01, 2.2]
    assert point_volume_warnings(rec) == warnings


def test_a_grid_levelset_shape_is_mapped_too():
    """A body whose initial shape is a grid level set (a grain's sampled outline): phi_0 is its
    C1 interpolant, evaluated at X clamped to its grid (positive beyond). A rotated disc comes
    out within 1e-4 of the exact distance near its contour (the interpolant's own error on a
    grid of h / 2) and positive wherever its reference lies beyond that grid."""
    pts, c = disc_points(), np.array([3.7, -1.3])
    A = np.array([[np.cos(1.0), -np.sin(1.0)], [np.sin(1.0), np.cos(1.0)]])
    pts.x = pts.X @ A.T + c
    fine = _cpp.StructuredGrid.uniform([-1.3, -1.3], [1.3, 1.3], [52, 52])
    shape = _cpp.LevelSet(fine, np.linalg.norm(fine.nodes(), axis=1) - R)
    grid = grid_around(c)
    phi = evolution.reference_map(grid, shape, pts, H).values.ravel()
    nodes = grid.nodes()
    exact = np.linalg.norm(nodes - c, axis=1) - R
    band = np.abs(exact) < 2 * H
    assert np.abs(phi[band] - exact[band]).max() < 1e-4
    assert np.all(phi[exact > 0.4] > 0)


def test_material_points_inside_an_obstacle_or_another_body_are_reported():
    """records.penetrations: the deepest point of each body inside a rigid obstacle it meets
    or inside another body's level set (the broad phase's pairs), to round-off of the exact
    signed distances; mpm_run.penetration_warnings names the bodies deeper than 0.5 h, with
    the same text at every step."""
    from types import SimpleNamespace

    from dolfinx_forms.app.mpm_run import penetration_warnings
    from dolfinx_forms.geometry.obstacles import RigidObstacle
    from dolfinx_forms.mesh.cut_scene import half_plane
    from dolfinx_forms.mpm import records

    a, b = disc_points(), disc_points()  # unit discs centred at (0, 0) and (1.9, 0)
    b.x = b.x + [1.9, 0.0]
    wall = RigidObstacle("wall", half_plane((0.0, 0.85), (0.0, -1.0), 100.0),
                         bbox=[[-5.0, 0.85], [5.0, 3.0]], center=(0.0, 0.85), bodies=[1])  # a only
    bodies = [SimpleNamespace(name="a", tag=1), SimpleNamespace(name="b", tag=2)]
    grids = [grid_around((0.0, 0.0)), grid_around((1.9, 0.0))]
    levelsets = {t: _cpp.LevelSet(g, np.asarray(df.Circle(c, R)(g.nodes())))
                 for t, g, c in zip((1, 2), grids, ((0.0, 0.0), (1.9, 0.0)))}  # fmt: skip
    boxes = np.array([[[-1.1, -1.1], [1.1, 1.1]], [[0.8, -1.1], [3.0, 1.1]]])
    sim = SimpleNamespace(
        bodies=bodies, obstacles=[wall], points={1: a, 2: b}, levelsets=levelsets,
        body_boxes=lambda: boxes, candidate_pairs=lambda boxes=None: [(0, 1)],
    )  # fmt: skip
    depth = records.penetrations(sim)
    # a: its top points up to 1 - 0.85 inside the wall (less their inset from the circle);
    # b: its leftmost points ~0.1 inside a (the discs overlap by 0.1), a's into b alike
    top = a.x[:, 1].max() - 0.85
    assert depth["a"] == (pytest.approx(top, abs=1e-12), "wall")
    inside_a = R - np.linalg.norm(b.x, axis=1).min()
    assert depth["b"][1] == "a" and depth["b"][0] == pytest.approx(inside_a, abs=1e-3)
    assert 0 < inside_a < top
    warnings = penetration_warnings({"penetration": depth}, h=0.1)
    assert len(warnings) == 2 and warnings[0].startswith("a: ") and "'wall'" in warnings[0]
    assert penetration_warnings({"penetration": depth}, h=0.2) == warnings[:1]
    wall.offset = np.array([0.0, 1.0])  # the wall moved up past the disc: only b is left
    assert records.penetrations(sim)["a"] == (pytest.approx(inside_a, abs=1e-3), "b")
