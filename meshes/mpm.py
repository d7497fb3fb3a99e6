"""Scenes of the implicit MPM: cut scenes of grid level sets on one uniform background grid.

`grid_scene(comm, xlines, ylines, bodies, ...)` returns the `build_scene(levelsets)` callback of
`dolfinx_forms.mpm.ImplicitMPM`: every step it makes the cut scene of the current level sets
(each body's window is the whole grid: only its level set decides its active cells). Also the
Brazilian-disc set-up (paper 5.3.1): a disc between two rigid half-plane platens.
"""

from __future__ import annotations

import numpy as np

import dolfinx_forms as df
from dolfinx_forms.obstacles import RigidObstacle

from .cut import CutBody, cut_scene, half_plane


def uniform_lines(lo, hi, h):
    """Uniform grid lines k h covering [lo, hi] (lo, hi rounded outwards to multiples of h)."""
    k0, k1 = int(np.floor(lo / h + 1e-9)), int(np.ceil(hi / h - 1e-9))
    return h * np.arange(k0, k1 + 1, dtype=float)


def grid_scene(comm, xlines, ylines, bodies, pairs=(), boundary_markers=None, contact_box=None):
    """build_scene(levelsets {tag: _cpp.LevelSet}) -> Scene for `bodies` [(name, tag)] on the
    grid; pairs: body-body contact pairs (indices into bodies); boundary_markers: as in
    meshes.cut.cut_scene (default none); contact_box: the cells kept on rank 0 where contact is
    computed ((2, 2) or (k, 2, 2); None: from the pairs; required with obstacles in parallel)."""
    xlines, ylines = np.asarray(xlines, float), np.asarray(ylines, float)
    window = np.array([[xlines[0], ylines[0]], [xlines[-1], ylines[-1]]])
    h = float(max(np.diff(xlines).max(), np.diff(ylines).max()))

    def build(levelsets):
        cbodies = [CutBody(name, tag, window, levelsets[tag]) for name, tag in bodies]
        return cut_scene(
            comm, xlines, ylines, cbodies, boundary_markers or {}, list(pairs), h, contact_box
        )

    return build


def brazilian_disc(comm, R=10.0, h=0.2, step_displacement=0.02, steps=50, margin=None):
    """The Brazilian disc of the paper (5.3.1): a disc of radius R centred at the origin between
    a fixed lower platen (y < -R) and an upper one (y > R) moved down by step_displacement per
    step. Returns (grid lines, [MPMBody args], obstacles, build_scene). The grid covers the
    disc with `margin` (default 3 h + the total platen travel) and has a line at x = 0 (the
    symmetry line of the u_x = 0 condition)."""
    margin = 3 * h + step_displacement * steps if margin is None else margin
    xl = uniform_lines(-R - margin, R + margin, h)
    yl = uniform_lines(-R - margin, R + margin, h)
    ext = 100 * R
    top = RigidObstacle(
        "platen_top",
        half_plane((0.0, R), (0.0, -1.0), ext),
        bbox=[[-2 * R, R], [2 * R, 2 * R]],
        center=(0.0, R),
        translation=(0.0, -step_displacement),
    )
    bottom = RigidObstacle(
        "platen_bottom",
        half_plane((0.0, -R), (0.0, 1.0), ext),
        bbox=[[-2 * R, -2 * R], [2 * R, -R]],
        center=(0.0, -R),
    )
    zone = 0.25 * R + 4 * h  # where the contact zones can be: kept on rank 0
    box = np.array(
        [[[-zone, R - zone], [zone, R + margin]], [[-zone, -R - margin], [zone, -R + zone]]]
    )
    build = grid_scene(comm, xl, yl, [("disc", 1)], contact_box=box)
    return (xl, yl), ("disc", 1, df.Circle((0.0, 0.0), R)), [top, bottom], build
