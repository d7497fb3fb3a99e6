"""Rigid level-set obstacles (seed 002): bodies with no dofs, moved by a prescribed rigid motion.

An obstacle is a shape in its own frame (an analytic `_cpp.Shape`, a polygon/polyline as a
`_cpp.Polygon`, or a grid `_cpp.LevelSet`) placed by a pose: rotation `angle` about `center`,
then translation `offset`. Its signed distance at x is the shape's at the pulled-back point
R^T (x - center - offset) + center (rigid motions keep distances). It meets a deformable body
through the same intermediate surface as a body pair (eqs 21-25); its side of the contact
quadrature has no dofs and its displacement at the closest points P_j enters the jump of eq 26 as
a prescribed value (`ContactQuadrature.u_j_prescribed`). A step's motion (translation and
rotation per step) is scaled by the load level lam inside the step, so load-step cut-back also
cuts the obstacle's motion; `advance()` moves the pose once the step is accepted.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from dolfinx_forms import _cpp


def _rotation(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


@dataclass
class RigidObstacle:
    """A rigid obstacle (see the module docstring).

    name: for output; shape: `_cpp.Shape` or `_cpp.LevelSet` (phi < 0 inside) in the obstacle's
    frame (a LevelSet's grid must contain the obstacle with a margin: beyond it the value is
    extended by the distance to the grid); bbox: (2, 2) bounding box in that frame (None: the
    LevelSet's grid box; required for a Shape); center: the point the rotation turns about
    (and the moment is taken about); translation, rotation: the prescribed motion per step (a
    (2,) vector and an angle in radians, counter-clockwise); bodies: tags of the deformable
    bodies it may touch (None: all)."""

    name: str
    shape: object
    bbox: object = None
    center: object = (0.0, 0.0)
    translation: object = (0.0, 0.0)
    rotation: float = 0.0
    bodies: object = None
    offset: np.ndarray = field(default_factory=lambda: np.zeros(2))
    angle: float = 0.0

    def __post_init__(self):
        if not isinstance(self.shape, (_cpp.Shape, _cpp.LevelSet)):
            raise TypeError(
                f"RigidObstacle {self.name!r}: shape must be a _cpp.Shape or _cpp.LevelSet, "
                f"got {type(self.shape).__name__}"
            )
        if self.bbox is None:
            if not isinstance(self.shape, _cpp.LevelSet):
                raise ValueError(f"RigidObstacle {self.name!r}: bbox is required for a Shape")
            g = self.shape.grid
            self.bbox = np.array([[g.x[0], g.y[0]], [g.x[-1], g.y[-1]]])
        self.bbox0 = np.asarray(self.bbox, float).reshape(2, 2)
        self.center = np.asarray(self.center, float)
        self.translation = np.asarray(self.translation, float)
        self.rotation = float(self.rotation)
        self.offset = np.asarray(self.offset, float).copy()
        for what, v in (("translation", self.translation), ("rotation", self.rotation)):
            if not np.all(np.isfinite(v)):
                raise ValueError(f"RigidObstacle {self.name!r}: {what} must be finite")

    # ------------------------------------------------------------------ pose
    def pull_back(self, x):
        """Points x (n, 2) in the obstacle's frame."""
        R = _rotation(self.angle)
        return (np.asarray(x, float)[:, :2] - self.center - self.offset) @ R + self.center

    def push_forward(self, X):
        R = _rotation(self.angle)
        return (np.asarray(X, float) - self.center) @ R.T + self.center + self.offset

    @property
    def current_center(self):
        return self.center + self.offset

    @property
    def current_bbox(self):
        """Axis-aligned box of the current pose (the frame box's corners moved)."""
        lo, hi = self.bbox0
        corners = self.push_forward(
            np.array([[lo[0], lo[1]], [hi[0], lo[1]], [lo[0], hi[1]], [hi[0], hi[1]]])
        )
        return np.array([corners.min(axis=0), corners.max(axis=0)])

    def step_displacement(self, x, lam=1.0):
        """Displacement of the obstacle's material points now at x (n, 2) for the fraction
        lam of one step's motion: rotation lam * rotation about the current centre, then
        translation lam * translation."""
        x = np.asarray(x, float)[:, :2]
        c = self.current_center
        R = _rotation(lam * self.rotation)
        return (x - c) @ R.T + c + lam * self.translation - x

    def advance(self, lam=1.0):
        """Move the pose by the fraction lam of one step's motion (after an accepted step)."""
        c = self.current_center
        self.offset = self.offset + lam * self.translation
        # rotating about the current centre keeps the centre; the frame turns by lam * rotation
        self.angle += lam * self.rotation
        assert np.allclose(self.current_center, c + lam * self.translation)

    def state(self):
        return (self.offset.copy(), float(self.angle))

    def set_state(self, s):
        self.offset, self.angle = s[0].copy(), float(s[1])

    # ------------------------------------------------------------------ geometry
    def values(self, x):
        """Signed distance (n,) at points x (n, 2) of the current pose."""
        X = np.ascontiguousarray(self.pull_back(x))
        if isinstance(self.shape, _cpp.Shape):
            return np.asarray(self.shape(X))
        # beyond its grid (which must hold the whole obstacle): the value at the nearest grid
        # point plus the distance to the grid, continuous and positive there
        g = self.shape.grid
        lo, hi = np.array([g.x[0], g.y[0]]), np.array([g.x[-1], g.y[-1]])
        Xc = np.minimum(np.maximum(X, lo), hi)  # np.clip: ~10 us of overhead a call
        return self.shape.evaluate(np.ascontiguousarray(Xc))[0] + np.linalg.norm(X - Xc, axis=1)

    def levelset(self, grid):
        """The obstacle's level set on a `_cpp.StructuredGrid` (node values of the current
        pose; exact for an analytic shape, the C1 interpolant's for a grid level set)."""
        return _cpp.LevelSet(grid, self.values(grid.nodes()))

    def closest_points(self, points, length_scale, phi_on_grid):
        """Closest points on the current boundary (eq 25): exact for an analytic shape (in the
        obstacle's frame, moved back), the iteration of eq 25 on `phi_on_grid` otherwise."""
        if isinstance(self.shape, _cpp.Shape):
            r = _cpp.closest_point_projection(
                self.shape, np.ascontiguousarray(self.pull_back(points)), length_scale
            )
            r["points"] = self.push_forward(r["points"])
            return r
        return _cpp.closest_point_projection(phi_on_grid, np.ascontiguousarray(points))
