"""Granular columns (issue 31): a random polydisperse sample in four rigid walls and MELODY's
protocol (seed 004, example 2): deposition under gravity, uniaxial compression by the top wall,
then biaxial shear at constant area by the lateral walls. demos/granular_column.py (the material
point method) and benchmarks/dem_peer.py (LAMMPS, rigid discs) both take the sample, the wall
motion and the statistics from here, so that the two codes run the same test. numpy only.

Conventions (both codes):
- walls: inner faces x = left, x = right, y = bottom, y = top; wall forces are normal forces
  per unit thickness, positive in compression;
- the sample's stresses from the wall forces, sigma_xx = (F_left + F_right) / (2 H) and
  sigma_yy = (F_bottom + F_top) / (2 W) (the mean over the column: gravity makes sigma_yy grow
  with depth), W = right - left, H = top - bottom; stress ratio sigma_yy / sigma_xx;
- the shear strain gamma = eps_yy - eps_xx with logarithmic strains of the walls' box from the
  end of compression: W = W_c exp(gamma / 2), H = H_c exp(-gamma / 2), the area W H constant;
- a contact is a grain pair pressed together (normal force > 0); the coordination number is
  2 contacts / grains (all grains, rattlers included; wall contacts are not counted); the force
  distribution is that of the contacts' normal forces: its mean and coefficient of variation;
- the force mean in units of the sample's own stress, force_mean / (p d), p = (sigma_xx +
  sigma_yy) / 2 and d the sample's mean diameter: a displacement-driven compression gives forces
  that grow with the contact stiffness (LAMMPS's own force mean at the end of compression: 7, 18,
  32 for E = 1e4, 1e5, 1e6), while f / (p d) has a rigid limit, about pi / (phi z) for packing
  fraction phi and coordination z (p = sum over contacts of f l / (2 A), branch lengths l ~ d),
  so it is the mean the two codes' contact laws (plane-strain continuum, 3D Hertz) can share.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import grains as gr

PHASES = ("deposition", "compression", "shear")


@dataclass(frozen=True)
class Sample:
    """A packed random sample: outlines[i] (k, 2) counter-clockwise vertices at their places,
    radius[i] = sqrt(area / pi) (the disc's radius for discs), centre[i] the centroid, box
    (2, 2) the walls' inner faces [[left, bottom], [right, top]]; discs: exact circles."""

    outlines: list
    radius: np.ndarray
    centre: np.ndarray
    box: np.ndarray
    discs: bool


def random_sample(n, radius=1.0, polydispersity=0.2, elongation=0.0, roughness=0.0,
                  fraction=0.35, gap=None, seed=1):  # fmt: skip
    """n grains with radii uniform in radius (1 -+ polydispersity), Fourier outlines
    (meshes.grains.fourier_grain: elongation, roughness; both 0: discs), placed without contact
    (gap between grains and from the walls, default 0.1 radius) by random sequential addition
    in a square box of area fraction `fraction` (MELODY: a square domain, no contact at the
    start). Reproducible from the seed."""
    if not (int(n) >= 1 and 0 <= polydispersity < 1 and 0 < fraction <= 0.5):
        raise ValueError(
            f"random_sample: need n >= 1, 0 <= polydispersity < 1 and 0 < fraction <= 0.5, "
            f"got {n}, {polydispersity}, {fraction}"
        )
    rng = np.random.default_rng(seed)
    r = radius * rng.uniform(1 - polydispersity, 1 + polydispersity, int(n))
    discs = elongation == 0 and roughness == 0
    shapes = [
        gr.disc_outline((0.0, 0.0), q) if discs else gr.fourier_grain(rng, q, elongation, roughness)
        for q in r
    ]
    area = np.array([abs(gr.polygon_area(v)) for v in shapes])
    side = np.sqrt(area.sum() / fraction)
    box = np.array([[0.0, 0.0], [side, side]])
    gap = 0.1 * radius if gap is None else float(gap)
    placed = gr.pack_grains(shapes, box, gap=gap, rng=rng, max_tries=5000)
    centre = np.array([gr.polygon_centroid(v) for v in placed])
    if discs:  # the disc's exact radius (its 64-gon has a little less area)
        equivalent = r
    else:
        equivalent = np.sqrt(area / np.pi)
    return Sample(placed, equivalent, centre, box, discs)


def shape(sample, i):
    """The exact level-set shape of grain i (`_cpp.Circle` for discs, else `_cpp.Polygon`)."""
    if sample.discs:
        return gr.disc(sample.centre[i], sample.radius[i])
    return gr.polygon(sample.outlines[i])


@dataclass(frozen=True)
class Protocol:
    """The walls' motion in time (module docstring). box: the walls at t = 0; phases of
    t_deposit (walls fixed, gravity), t_compress (the top wall, put on the sample's top at
    the end of deposition, moves at constant speed to (1 - compression) times the settled
    height above the bottom), t_shear (the
    lateral walls move apart symmetrically and the top wall down, gamma growing linearly to
    shear_strain at constant area)."""

    box: np.ndarray
    t_deposit: float
    t_compress: float
    t_shear: float
    compression: float
    shear_strain: float

    @property
    def t_end(self):
        return self.t_deposit + self.t_compress + self.t_shear

    def phase(self, t):
        """The phase of time t: the one the step ending at t belongs to (times within 1e-9 of
        the run's length of a phase's end belong to it: steps sum to it only to round-off)."""
        eps = 1e-9 * max(1.0, self.t_end)
        if t <= self.t_deposit + eps:
            return PHASES[0]
        return PHASES[1] if t <= self.t_deposit + self.t_compress + eps else PHASES[2]

    def walls(self, t, settled_height):
        """{left, right, bottom, top}: the walls' inner faces at time t; settled_height: the
        sample's height above the bottom at the end of deposition (each code measures its own;
        unused before)."""
        (x0, y0), (x1, y1) = self.box
        left, right, top = x0, x1, y1
        phase = self.phase(t)
        if phase != PHASES[0]:  # the top wall drops onto the settled sample, then compresses
            s = min(1.0, (t - self.t_deposit) / self.t_compress)
            top = y0 + settled_height * (1 - s * self.compression)
        if phase == PHASES[2]:
            gamma = self.shear_strain * min(1.0, (t - self.t_deposit - self.t_compress)
                                            / self.t_shear)  # fmt: skip
            w, xc = (x1 - x0) * np.exp(gamma / 2), 0.5 * (x0 + x1)
            left, right = xc - w / 2, xc + w / 2
            top = y0 + (top - y0) * np.exp(-gamma / 2)
        return dict(left=float(left), right=float(right), bottom=float(y0), top=float(top))

    def shear(self, t):
        """gamma at time t (0 before the shear phase)."""
        t_s = t - self.t_deposit - self.t_compress
        return float(self.shear_strain * min(1.0, max(0.0, t_s) / self.t_shear))


def stresses(walls, forces):
    """(sigma_xx, sigma_yy, sigma_yy / sigma_xx) of the walls' box from their normal forces
    {left, right, bottom, top} (compression positive; module docstring); the ratio is None
    (an empty CSV cell) while the lateral walls carry nothing."""
    w, h = walls["right"] - walls["left"], walls["top"] - walls["bottom"]
    sxx = (forces["left"] + forces["right"]) / (2 * h)
    syy = (forces["bottom"] + forces["top"]) / (2 * w)
    return float(sxx), float(syy), float(syy / sxx) if sxx > 0 else None


def contact_statistics(normal_forces, n_grains):
    """{contacts, coordination, force_mean, force_cv} of the grain-grain contacts' normal forces
    (those <= 0 are open and not counted)."""
    f = np.asarray(normal_forces, float)
    f = f[f > 0]
    mean = float(f.mean()) if f.size else 0.0
    cv = float(f.std() / mean) if f.size else 0.0
    return dict(contacts=int(f.size), coordination=2.0 * f.size / n_grains, force_mean=mean,
                force_cv=cv)  # fmt: skip


def scaled_force_mean(force_mean, sxx, syy, mean_diameter):
    """force_mean / (p d), p = (sigma_xx + sigma_yy) / 2 (module docstring); None (an empty
    CSV cell) while the walls carry nothing."""
    p = 0.5 * (sxx + syy)
    return float(force_mean / (p * mean_diameter)) if p > 0 else None


#: the columns of steps.csv of both codes (demos/granular_column.py, benchmarks/dem_peer.py)
COLUMNS = [
    "t", "phase", "shear_strain", "left", "right", "top",
    "force_left", "force_right", "force_bottom", "force_top",
    "stress_xx", "stress_yy", "stress_ratio",
    "contacts", "coordination", "force_mean", "force_cv", "kinetic_energy", "force_mean_pd",
]  # fmt: skip


def row(protocol, t, walls, forces, normal_forces, sample, kinetic_energy):
    """One steps.csv row (COLUMNS) from a code's state at time t (`sample`: its grain count
    and mean diameter)."""
    sxx, syy, ratio = stresses(walls, forces)
    out = dict(t=float(t), phase=protocol.phase(t), shear_strain=protocol.shear(t),
               left=walls["left"], right=walls["right"], top=walls["top"],
               stress_xx=sxx, stress_yy=syy, stress_ratio=ratio,
               kinetic_energy=float(kinetic_energy))  # fmt: skip
    out.update({f"force_{k}": float(forces[k]) for k in ("left", "right", "bottom", "top")})
    out.update(contact_statistics(normal_forces, len(sample.radius)))
    d = 2.0 * float(np.mean(sample.radius))
    out["force_mean_pd"] = scaled_force_mean(out["force_mean"], sxx, syy, d)
    return out
