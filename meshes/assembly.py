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


def held_rows(n, cols):
    """True if n grains in rows of `cols` (row j shifted by half a spacing when odd, the last
    row partial) leave every grain of the last full row a lattice neighbour above it: the last
    row is full, or odd with cols - 1 grains (it then covers both ends of the even row below).
    A grain with neighbours below and beside only is pushed out of the row by the compression
    and, once its contacts slip, turns almost freely: 7 grains (3 + 3 + 1), 700 (27 per row,
    25 in the last) and 1000 (32 per row, 8 in the last) failed at their first step with
    ceil(sqrt(n)) grains per row."""
    full, rest = divmod(int(n), int(cols))
    return rest == 0 or (full % 2 == 1 and rest == cols - 1)


def lattice_columns(n):
    """Grains per row of the assembly: ceil(sqrt(n)) if `held_rows`, else the count nearest
    sqrt(n) (in ratio, the smaller of a tie) that is; one always is (n per row)."""
    cols = int(np.ceil(np.sqrt(n)))
    if held_rows(n, cols):
        return cols
    good = [c for c in range(1, int(n) + 1) if held_rows(n, c)]
    return min(good, key=lambda c: (abs(np.log(c / np.sqrt(n))), c))


def grain_assembly(comm, n=15, radius=5.0, h=0.5, aspect=1.25, overlap=None, margin=None):
    """n elliptic grains (semi-axes a = radius sqrt(aspect), b = radius / sqrt(aspect), long axis
    along x) on a hexagonal lattice of `lattice_columns(n)` per row (ceil(sqrt(n)) unless its
    last row would leave a grain unheld from above, `held_rows`): the image under y -> y b/a
    of the densest packing of discs of radius a (an affine map keeps tangency), brought closer
    by `overlap` (default 0.2 h) so that every lattice neighbour overlaps, inside four rigid
    plates that overlap the outermost grains by `overlap`. A hexagonal assembly is stable under
    compression (a square lattice of round grains would shear). Returns (grid lines,
    [(name, tag, shape)], plates {name: RigidObstacle}, build_scene, box (2, 2) of the plates'
    inner faces, centres (n, 2))."""
    overlap = 0.2 * h if overlap is None else float(overlap)
    a, b = radius * np.sqrt(aspect), radius / np.sqrt(aspect)
    cols = lattice_columns(n)
    s = 2 * a - overlap  # centre spacing of the disc packing (radius a) before the map
    k = np.arange(n)
    i, j = k % cols, k // cols
    centres = np.stack([s * (i + 0.5 * (j % 2)), s * np.sqrt(3) / 2 * j * (b / a)], axis=1)
    lo = np.array([(centres[:, 0] - a).min() + overlap, (centres[:, 1] - b).min() + overlap])
    hi = np.array([(centres[:, 0] + a).max() - overlap, (centres[:, 1] + b).max() - overlap])
    c = 0.5 * (lo + hi)
    centres, lo, hi = centres - c, lo - c, hi - c
    plates = box_plates(lo, hi)
    margin = 4 * h + 0.1 * radius if margin is None else margin
    ax = [uniform_lines(lo[d] - margin, hi[d] + margin, h) for d in range(2)]
    bodies = [(f"grain{k}", k + 1, df.Ellipse(tuple(x), a, b, 0.0)) for k, x in enumerate(centres)]
    build = grid_scene(comm, ax[0], ax[1], [(q[0], q[1]) for q in bodies], contact_box=False)
    return (ax[0], ax[1]), bodies, plates, build, np.array([lo, hi]), centres


def box_plates(lo, hi):
    """{plate_left, plate_right, plate_bottom, plate_top}: four rigid half-plane plates whose
    inner faces bound the box [lo, hi] (each turns about its face's lower or left end)."""
    ext = 100 * (hi - lo).max()
    far = 2 * (hi - lo).max()

    def plate(name, point, normal, box, center):
        return RigidObstacle(name, half_plane(point, normal, ext), bbox=box, center=center)

    return {
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


#: the plates of box_plates and their inward normals before any rotation
INWARD = {
    "plate_left": (1, 0),
    "plate_right": (-1, 0),
    "plate_bottom": (0, 1),
    "plate_top": (0, -1),
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


def column_scene(comm, sample, h, shear_strain=0.0):
    """The material-point scene of a `meshes.column.Sample`: grid lines covering the walls' box
    widened about its centre by exp(shear_strain / 2) (the walls at the end of the shear of
    meshes.column.Protocol) plus 4 h,
    the grains [(grain<i>, i + 1, exact shape)], the four plates on the box (box_plates) and
    build_scene (body pairs from the simulation's broad phase)."""
    from .column import shape

    lo, hi = sample.box
    c, half = 0.5 * (lo + hi), 0.5 * (hi - lo) * np.array([np.exp(shear_strain / 2), 1.0])
    ax = [uniform_lines(c[d] - half[d] - 4 * h, c[d] + half[d] + 4 * h, h) for d in range(2)]
    bodies = [(f"grain{i}", i + 1, shape(sample, i)) for i in range(len(sample.radius))]
    build = grid_scene(comm, ax[0], ax[1], [(q[0], q[1]) for q in bodies], contact_box=False)
    return (ax[0], ax[1]), bodies, box_plates(lo, hi), build


def bodies_top(sim):
    """The highest point of the bodies' zero contours in an ImplicitMPM: per grid column of each
    body's level-set window, the top node inside and the crossing above it, interpolated."""
    top = -np.inf
    for b in sim.bodies:
        i0, i1, j0, j1 = sim.windows[b.tag]
        v = sim.levelsets[b.tag].values  # (j1 - j0 + 1, i1 - i0 + 1)
        rows = np.flatnonzero((v <= 0).any(axis=1))
        if not len(rows):
            continue
        j = rows[-1]
        if j + 1 >= v.shape[0]:
            return float(sim.ylines[j0 + j])  # the window ends inside: cannot happen (margin)
        a, b_ = v[j], v[j + 1]
        inside = a <= 0
        t = a[inside] / (a[inside] - b_[inside])  # the crossing between rows j and j + 1
        top = max(top, float(sim.ylines[j0 + j] + sim.h * t.max()))
    return top


class ColumnWalls:
    """The four plates of column_scene moved as a `meshes.column.Protocol` says: `prepare(t,
    dt)` gives each plate its translation over [t, t + dt] (PointNewmark.advance's prepare);
    `settle(sim)` measures the settled height at the end of deposition and puts the top plate
    on the sample; `positions`, `forces(record)` (normal, compression positive) and
    `vertical(record)` (the plates' total upward force on the grains) in meshes.column's
    terms."""

    NAMES = {"left": "plate_left", "right": "plate_right", "bottom": "plate_bottom",
             "top": "plate_top"}  # fmt: skip

    def __init__(self, plates, protocol):
        self.plates, self.protocol, self.settled = plates, protocol, None

    def positions(self):
        return {k: float(self.plates[p].current_center[0 if k in ("left", "right") else 1])
                for k, p in self.NAMES.items()}  # fmt: skip

    def prepare(self, t, dt):
        now, then = self.positions(), self.protocol.walls(t + dt, self.settled)
        for k, p in self.NAMES.items():
            d = then[k] - now[k]
            self.plates[p].translation = np.array([d, 0.0] if k in ("left", "right") else [0, d])

    def settle(self, sim):
        bottom = self.protocol.box[0, 1]
        self.settled = bodies_top(sim) - bottom
        top = self.plates["plate_top"]
        top.offset = top.offset + [0.0, bottom + self.settled - top.current_center[1]]
        return self.settled

    def forces(self, record):
        f = plate_frame_forces(record, self.plates)
        return {k: f[f"{p}_normal"] for k, p in self.NAMES.items()}

    def vertical(self, record):
        return 0.0 - sum(record["obstacles"][p]["fy"] for p in self.NAMES.values())  # not -0.0

    def row(self, record, sample):
        """The meshes.column.row of an ImplicitMPM step record (grain pairs: not a plate's)."""
        from .column import row

        normal = [q["normal_force"] for q in record["pairs"] if q["body_j"] not in self.plates]
        energy = sum(record["kinetic_energy"].values())
        return row(self.protocol, record["time"], self.positions(), self.forces(record), normal,
                   sample, energy)  # fmt: skip
