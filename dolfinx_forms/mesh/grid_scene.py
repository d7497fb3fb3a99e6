"""The background grid of the implicit MPM and the cut scene of its level sets on it.

`grid_scene(comm, xlines, ylines, bodies, ...)` returns the `build_scene(levelsets)` callback of
`dolfinx_forms.mpm.implicit.ImplicitMPM`: every step it makes the cut scene of the current level
sets (each body's window is the sub-grid of its active cells, `fem.cut.material_window`: only
its level set decides them, and a body's share of the build costs its size, not the grid's).
"""

from __future__ import annotations

import numpy as np

from dolfinx_forms import _cpp
from dolfinx_forms.fem.cut import material_window
from dolfinx_forms.mesh.cut_scene import CutBody, cut_scene


def uniform_lines(lo, hi, h):
    """Uniform grid lines k h covering [lo, hi] (lo, hi rounded outwards to multiples of h)."""
    k0, k1 = int(np.floor(lo / h + 1e-9)), int(np.ceil(hi / h - 1e-9))
    return h * np.arange(k0, k1 + 1, dtype=float)


def grid_scene(comm, xlines, ylines, bodies, pairs=(), boundary_markers=None, contact_box=None):
    """build_scene(levelsets {tag: _cpp.LevelSet}, pairs=None, boxes=None) -> Scene for `bodies`
    [(name, tag)] on the grid; pairs: body-body contact pairs (indices into bodies; the
    simulation passes its broad phase's each step, else these); boxes: the simulation's contact
    boxes with their ranks ({"boxes", "owners"}, dolfinx_forms.mesh.scene.contact_partitioner), else
    contact_box; boundary_markers: as in
    meshes.cut.cut_scene (default none); contact_box: the cells kept on rank 0 where contact is
    computed ((2, 2) or (k, 2, 2); None: from the pairs; required with obstacles in parallel)."""
    xlines, ylines = np.asarray(xlines, float), np.asarray(ylines, float)
    window = np.array([[xlines[0], ylines[0]], [xlines[-1], ylines[-1]]])
    h = float(max(np.diff(xlines).max(), np.diff(ylines).max()))
    fixed = list(pairs)

    def body_window(levelset):
        """The grid-line window of a grid level set's active cells (`cut.material_window`)."""
        if not isinstance(levelset, _cpp.LevelSet):
            return window
        i0, i1, j0, j1 = material_window(levelset.values)
        x, y = np.asarray(levelset.grid.x), np.asarray(levelset.grid.y)  # lines of this grid
        return np.array([[x[i0], y[j0]], [x[i1], y[j1]]])

    def build(levelsets, pairs=None, boxes=None):
        cbodies = [
            CutBody(name, tag, body_window(levelsets[tag]), levelsets[tag]) for name, tag in bodies
        ]
        use = fixed if pairs is None else [tuple(p) for p in pairs]
        box = contact_box if boxes is None else boxes
        return cut_scene(comm, xlines, ylines, cbodies, boundary_markers or {}, use, h, box)

    return build
