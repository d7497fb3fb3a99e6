"""Grain assemblies in rigid plates (paper 5.3.2): non-circular grains on a hexagonal lattice,
every lattice neighbour overlapping, inside four rigid half-plane plates.

Why overlaps: a grain whose contacts are all open at the first Newton iteration has no
stiffness and the implicit step is singular (the paper enlarges its grains by 0.5 h for the
same reason). Why a hexagonal lattice: it is stable under compression; random sequential
packings (meshes.grains.pack_grains) leave grains without contacts, and square lattices of
round grains shear as soon as a contact slips.
"""

from __future__ import annotations

import numpy as np

import dolfinx_forms as df
from dolfinx_forms.geometry.obstacles import RigidObstacle

from dolfinx_forms.mesh.cut_scene import half_plane
from .mpm import grid_scene, uniform_lines


def grain_assembly(comm, n=15, radius=5.0, h=0.5, aspect=1.25, overlap=None, margin=None):
    """n elliptic grains (semi-axes a = radius sqrt(aspect), b = radius / sqrt(aspect), long axis
    along x) on a hexagonal lattice of cols = ceil(sqrt(n)) per row: the image under y -> y b/a
    of the densest packing of discs of radius a (an affine map keeps tangency), brought closer
    by `overlap` (default 0.2 h) so that every lattice neighbour overlaps, inside four rigid
    plates that overlap the outermost grains by `overlap`. A hexagonal assembly is stable under
    compression (a square lattice of round grains would shear). Returns (grid lines,
    [(name, tag, shape)], plates {name: RigidObstacle}, build_scene, box (2, 2) of the plates'
    inner faces, centres (n, 2))."""
    overlap = 0.2 * h if overlap is None else float(overlap)
    a, b = radius * np.sqrt(aspect), radius / np.sqrt(aspect)
    cols = int(np.ceil(np.sqrt(n)))
    s = 2 * a - overlap  # centre spacing of the disc packing (radius a) before the map
    k = np.arange(n)
    i, j = k % cols, k // cols
    centres = np.stack([s * (i + 0.5 * (j % 2)), s * np.sqrt(3) / 2 * j * (b / a)], axis=1)
    lo = np.array([(centres[:, 0] - a).min() + overlap, (centres[:, 1] - b).min() + overlap])
    hi = np.array([(centres[:, 0] + a).max() - overlap, (centres[:, 1] + b).max() - overlap])
    c = 0.5 * (lo + hi)
    centres, lo, hi = centres - c, lo - c, hi - c
    ext = 100 * (hi - lo).max()
    far = 2 * (hi - lo).max()

    def plate(name, point, normal, box, center):
        return RigidObstacle(name, half_plane(point, normal, ext), bbox=box, center=center)

    plates = {
        "plate_left": plate(
            "plate_left", (lo[0], 0), (1, 0), [[lo[0] - far, -far], [lo[0], far]], (lo[0], lo[1])
        ),
        "plate_right": plate(
            "plate_right", (hi[0], 0), (-1, 0), [[hi[0], -far], [hi[0] + far, far]], (hi[0], lo[1])
        ),
        "plate_bottom": plate(
            "plate_bottom", (0, lo[1]), (0, 1), [[-far, lo[1] - far], [far, lo[1]]], (0, lo[1])
        ),
        "plate_top": plate(
            "plate_top", (0, hi[1]), (0, -1), [[-far, hi[1]], [far, hi[1] + far]], (0, hi[1])
        ),
    }
    margin = 4 * h + 0.1 * radius if margin is None else margin
    ax = [uniform_lines(lo[d] - margin, hi[d] + margin, h) for d in range(2)]
    bodies = [(f"grain{k}", k + 1, df.Ellipse(tuple(x), a, b, 0.0)) for k, x in enumerate(centres)]
    build = grid_scene(comm, ax[0], ax[1], [(q[0], q[1]) for q in bodies], contact_box=False)
    return (ax[0], ax[1]), bodies, plates, build, np.array([lo, hi]), centres


#: the plates of grain_assembly and their inward normals before any rotation
INWARD = {
    "plate_left": (1, 0), "plate_right": (-1, 0), "plate_bottom": (0, 1), "plate_top": (0, -1)
}


def plate_frame_forces(record, plates):
    """The plates' forces of an ImplicitMPM step record in each plate's current frame (rotated
    by its angle): {name_normal (compression positive), name_tangential}."""
    out = {}
    for name, inward in INWARD.items():
        a = plates[name].angle
        m = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]) @ inward
        f = np.array([record["obstacles"][name]["fx"], record["obstacles"][name]["fy"]])
        out[f"{name}_normal"] = float(-f @ m)
        out[f"{name}_tangential"] = float(f @ np.array([-m[1], m[0]]))
    return out
