"""Outputs of the multi-step (MPM) runs: step tables, time series, and the run skeleton.

Files (the contract of docs/contract.md, "Multi-step and multi-body outputs"):
`steps.csv` (the demo's columns), `contacts.csv` (step, body_i, body_j, x, y, normal_force,
tangential_force, active_length, stick_fraction), `bodies.csv` (step, body, fx, fy, moment,
area_levelset, volume_points), and XDMF time series that ParaView opens:
`material_points_<body>.xdmf` (the points at their current positions with stress, volume and
displacement since the start; beyond SERIES_PER_BODY_MAX bodies one `material_points.xdmf` with
the body's index) and `levelsets.xdmf` (the background grid with the bodies' combined level set,
the body it belongs to and its extended step displacement, and up to SERIES_PER_BODY_MAX bodies
each body's own). Each series keeps its arrays in one HDF5 file beside the .xdmf (`Series`),
one frame every `series_every` steps.

`Steps` is the step loop of a multi-step demo inside the run skeleton every demo uses
(`demo.Run`): records, warnings, series frames, the metrics blocks and the step files.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from dolfinx_forms.io.output import write_table
from dolfinx_forms.solvers.newton import ContactSolverError

CONTACT_COLUMNS = [
    "step",
    "body_i",
    "body_j",
    "x",
    "y",
    "normal_force",
    "tangential_force",
    "active_length",
    "stick_fraction",
]
BODY_COLUMNS = ["step", "body", "fx", "fy", "moment", "area_levelset", "volume_points"]


class Series:
    """An XDMF temporal collection of frames, each with its own geometry, all its arrays in
    one HDF5 file beside it (<name>.h5, paths relative to the .xdmf); ParaView and meshio's
    TimeSeriesReader open it. A cloud of points is a Polyvertex grid whose every point is a
    cell; each frame also carries its points as the field `position` (meshio's reader keeps
    the first frame's geometry)."""

    def __init__(self, name):
        self.name, self.frames = name, []

    def add(self, time_value, points, point_data, cells=None):
        """points (n, 2); point_data {name: (n,) or (n, c)}; cells (m, 4) quadrilaterals in
        DOLFINx order, or None for a cloud of points."""
        self.frames.append((float(time_value), np.asarray(points, float), point_data, cells))

    def write(self, folder):
        import h5py

        folder = Path(folder)
        grids = []
        with h5py.File(folder / f"{self.name}.h5", "w") as h5:
            for k, (t, x, data, cells) in enumerate(self.frames):
                n = len(x)
                xyz = np.zeros((n, 3))
                xyz[:, : x.shape[1]] = x
                if cells is None:
                    kind, topo = "Polyvertex", np.arange(n, dtype=np.int64)[:, None]
                    data = {"position": xyz, **data}
                else:
                    kind = "Quadrilateral"
                    topo = np.asarray(cells)[:, [0, 1, 3, 2]].astype(np.int64)  # VTK order
                nodes = "" if cells is not None else ' NodesPerElement="1"'
                parts = [
                    f'<Topology TopologyType="{kind}" NumberOfElements="{len(topo)}"{nodes}>'
                    + self._item(h5, f"frame{k}/topology", topo)
                    + "</Topology>",
                    '<Geometry GeometryType="XYZ">'
                    + self._item(h5, f"frame{k}/geometry", xyz)
                    + "</Geometry>",
                ]
                for name, v in data.items():
                    v = np.asarray(v, float)
                    kind_a = "Scalar" if v.ndim == 1 else "Vector" if v.shape[1] <= 3 else "Tensor"
                    if kind_a == "Vector" and v.shape[1] == 2:
                        v = np.hstack([v, np.zeros((n, 1))])
                    parts.append(
                        f'<Attribute Name="{name}" AttributeType="{kind_a}" Center="Node">'
                        + self._item(h5, f"frame{k}/{name}", v)
                        + "</Attribute>"
                    )
                grids.append(
                    f'<Grid Name="frame{k}" GridType="Uniform"><Time Value="{t:.17g}" />'
                    + "".join(parts)
                    + "</Grid>"
                )
        text = (
            '<?xml version="1.0"?>\n<Xdmf Version="3.0"><Domain>'
            f'<Grid Name="{self.name}" GridType="Collection" CollectionType="Temporal">'
            + "\n".join(grids)
            + "</Grid></Domain></Xdmf>\n"
        )
        (folder / f"{self.name}.xdmf").write_text(text)

    def _item(self, h5, key, a):
        a = np.ascontiguousarray(a)
        h5.create_dataset(key, data=a)
        dtype = "Int" if a.dtype.kind == "i" else "Float"
        dims = " ".join(str(d) for d in a.shape)
        return (
            f'<DataItem Dimensions="{dims}" NumberType="{dtype}" Precision="8" '
            f'Format="HDF">{self.name}.h5:/{key}</DataItem>'
        )


# up to this many bodies each has its own point series and level-set fields; beyond, one point
# series and the combined fields only (per-body whole-grid fields grow as bodies x grid)
SERIES_PER_BODY_MAX = 16


def add_frames(sim, points_series, grid_series, step, x0):
    """One frame of both series from the simulation's current state (rank 0 calls it; the
    points and level sets are replicated). x0: {tag: initial point positions}. The grid frame
    has the combined fields `phi`, `body` and `du` (`ImplicitMPM.union_fields`), and with at
    most SERIES_PER_BODY_MAX bodies each body's `phi_<body>` and `du_<body>`; the points are
    `material_points_<body>` per body then, else one `material_points` with a field `body`
    (the body's index in bodies.csv's order)."""
    per_body = len(sim.bodies) <= SERIES_PER_BODY_MAX
    fields = []
    for k, b in enumerate(sim.bodies):
        pts = sim.points[b.tag]
        data = {"stress": pts.stress, "volume": pts.vol, "displacement": pts.x - x0[b.tag]}
        if per_body:
            points_series.setdefault(b.name, Series(f"material_points_{b.name}")).add(
                step, pts.x, data
            )
        else:
            fields.append((pts.x, {**data, "body": np.full(len(pts.x), float(k))}))
    if fields:
        data = {key: np.concatenate([f[1][key] for f in fields]) for key in fields[0][1]}
        x = np.concatenate([f[0] for f in fields])
        points_series.setdefault("all", Series("material_points")).add(step, x, data)
    nx, ny = len(sim.xlines), len(sim.ylines)
    X, Y = np.meshgrid(sim.xlines, sim.ylines)
    v = (np.arange(ny - 1)[:, None] * nx + np.arange(nx - 1)[None, :]).ravel()
    quads = np.stack([v, v + 1, v + nx, v + nx + 1], axis=1)
    phi, body, du = sim.union_fields()
    data = {"phi": phi, "body": body.astype(float), "du": du}
    if per_body:
        data.update({f"phi_{b.name}": sim.levelset_values(b.tag).ravel() for b in sim.bodies})
        for name in getattr(sim, "grid_increments", {}):
            data[f"du_{name}"] = sim.grid_increment(name)
    grid_series.add(step, np.stack([X.ravel(), Y.ravel()], axis=1), data, quads)


# a body's level-set area off its points' volume by more than this is reported: the level set
# has drifted from the material it bounds (a quasi-static demo: 1e-3; an advected grain in a
# deposit: up to 22 %, which then stopped the run)
AREA_DRIFT = 0.02


def levelset_warnings(record):
    """The bodies of a step record whose level-set area is off their points' volume by more
    than AREA_DRIFT (one message per body, the same at every step: the first step is kept)."""
    out = []
    for name, area in record["area_levelset"].items():
        if abs(area / record["volume_points"][name] - 1) > AREA_DRIFT:
            out.append(
                f"{name}: its level set's area is off its points' volume by more than "
                f"{AREA_DRIFT:.0%} (the level set drifted from the material; "
                "--levelset-update reference-map rebuilds it from the points)"
            )
    return out


# a body whose points' volume ratios vol / vol0 (det F) differ by more than this factor is
# reported: a grain's points near a wall of the 100-grain column reached det F 0.005 beside 2.3
# (issue 31) while its neighbours' stayed within 0.8-1.06
VOLUME_SPREAD = 2.0


def point_volume_warnings(record):
    """The bodies of a step record whose points' det F spread by more than VOLUME_SPREAD (one
    message per body, the same at every step: the first step is kept; the ratios are in the
    record's point_volume_ratio)."""
    out = []
    for name, (lo, hi) in record.get("point_volume_ratio", {}).items():
        if not hi <= VOLUME_SPREAD * lo:
            out.append(
                f"{name}: its points' volume ratios (det F) differ by more than a factor "
                f"{VOLUME_SPREAD:g} within the body: its deformation is no longer resolved "
                "(points near a wall, in cut-cell slivers?)"
            )
    return out


# a body whose material points lie deeper than this (in h) inside another body or a rigid
# obstacle is reported: the contact holds the level sets' contours apart, and a point that far
# past the other's surface is material its level set no longer bounds. The neo-Hookean block
# at its defaults: 0.76 h at its corners; with the reference map 1.2 h at 27 %, one step
# before that run failed; the disc and grain demos stay within 0.032 h
# (docs/demos/block_compression.md)
PENETRATION_DEPTH = 0.5


def penetration_warnings(record, h):
    """The bodies of a step record with a material point deeper than PENETRATION_DEPTH h
    inside another body or an obstacle (`records.penetrations`; one message per body and
    other, the same at every step: the first step is kept)."""
    return [
        f"{name}: material points more than {PENETRATION_DEPTH:g} h inside {other!r} (the "
        "contact holds the level sets apart, not the points: its level set no longer bounds "
        "its material there, e.g. at a corner; refine h)"
        for name, (depth, other) in record.get("penetration", {}).items()
        if depth > PENETRATION_DEPTH * h
    ]


class Steps:
    """The step loop of a multi-step demo inside its `demo.Run` block:

        with Run("brazilian", params, discretization="cut", plot=False) as run:
            sim = ImplicitMPM(...)
            steps = Steps(run, sim, COLUMNS, args.steps, args.series_every)
            for _ in range(args.steps):
                rec = steps.step()
                steps.rows.append({...the demo's steps.csv row...})
            steps.measure()
            if run.rank0:
                ...the check...
            run.finish(summary, **steps.outputs(plots))

    `step` runs one ImplicitMPM step, keeps its record, the self-checks' warnings (with the
    first step that saw each) and the series frames (the first step, every `series_every`-th,
    the last). A ContactSolverError or a RuntimeError of the step's geometry becomes a
    ContactSolverError "step k: ..." (the Run ends with one line and status 1). `measure`
    fills the mesh and solver blocks of metrics.json; `outputs` gives `Run.finish` the files:
    steps.csv, contacts.csv, bodies.csv, the series, then the demo's plots."""

    def __init__(self, run, sim, columns, num_steps, series_every=10):
        self.run, self.sim, self.columns = run, sim, columns
        run.sim = sim
        self.num_steps, self.series_every = num_steps, series_every
        self.records = run.records = []  # ImplicitMPM.step records
        self.rows = run.rows = []  # steps.csv rows
        self.points_series, self.grid_series = {}, Series("levelsets")
        # {body name: Series} of the points, or {"all": Series} beyond SERIES_PER_BODY_MAX
        # bodies (rank 0)
        run.data["series"] = self.points_series
        self.checks = {}  # warning -> first step where it was seen
        self.series = True  # False: no time series (no frames kept, none written)
        self._x0 = None
        # the single-step results (reaction, half-width, p(x) errors) mean nothing here: a
        # multi-step record has the keys its demo fills, not nulls
        for block in ("results", "analytic"):
            for k in [k for k, v in run.metrics[block].items() if v is None]:
                del run.metrics[block][k]

    def step(self, advance=None):
        """One step: sim.step(), or advance() (a step found otherwise, e.g. to a force)."""
        from dolfinx_forms.solvers.checks import contact_warnings

        k = len(self.records)
        try:
            rec = self.sim.step() if advance is None else advance()
        except (ContactSolverError, RuntimeError) as e:  # Newton, or the geometry of a step
            raise ContactSolverError(f"step {k + 1}: {e}") from e
        self.records.append(rec)
        warnings = [*levelset_warnings(rec), *point_volume_warnings(rec),
                    *penetration_warnings(rec, self.sim.h)]  # fmt: skip
        for w in [*contact_warnings(self.sim.problem), *warnings]:
            self.checks.setdefault(w, rec["step"])
        if self._x0 is None:  # positions at seeding: the first step's points before it moved
            self._x0 = {
                t: p.x - d for (t, p), d in zip(self.sim.points.items(), self.sim.first_step_du)
            }
        last = k + 1 == self.num_steps
        frame = (k + 1) % self.series_every == 0 or last or k == 0
        if self.series and self.run.rank0 and frame:
            add_frames(self.sim, self.points_series, self.grid_series, rec["step"], self._x0)
        return rec

    def measure(self):
        """The mesh and solver blocks of metrics.json from the steps' records."""
        sim, last, metrics = self.sim, self.records[-1], self.run.metrics
        metrics["mesh"].update(
            h_contact=sim.h, num_cells=last["num_cells"], num_dofs=last["num_dofs"]
        )
        metrics["solver"].update(
            load_steps=len(self.records),
            newton_iterations=[r["newton_iterations"] for r in self.records],
            converged=True,
            residual_history=[r["residuals"] for r in self.records],  # per step
            enforcement=sim.problem.contact.enforcement,
            penalty={"eps_n": sim.problem.eps_n, "eps_t": sim.problem.eps_t},
            linear_solver=sim.problem.linear.name,  # the last step's
            condensed_dofs=int(getattr(sim.problem.linear, "num_dofs", 0)),
            cutbacks=int(sum(r["cutbacks"] for r in self.records)),
            # sub-steps per step: a failed step is done again in halves (ImplicitMPM.step)
            substeps=[r.get("substeps", 1) for r in self.records],
            # sub-steps per step whose Newton started from the last increment (increment.py)
            predicted=[r.get("predicted", 0) for r in self.records],
            factorisations=[r["factorisations"] for r in self.records],  # per step
            coupling_rebuilds=[r["coupling_rebuilds"] for r in self.records],  # per step
            warnings=[f"step {k}: {w}" for w, k in self.checks.items()],
            # the deepest material point inside another body or an obstacle over the run, in h
            # (`records.penetrations`; PENETRATION_DEPTH warns)
            points_inside_max_h=max(
                (d / sim.h for r in self.records for d, _ in r["penetration"].values()),
                default=0.0,
            ),
        )

    def write(self, folder):
        """steps.csv, contacts.csv, bodies.csv and the series into `folder` (rank 0)."""
        contacts = [
            dict(step=r["step"], **{c: p[c] for c in CONTACT_COLUMNS[1:]})
            for r in self.records
            for p in r["pairs"]
        ]
        bodies = [
            dict(
                step=r["step"],
                body=b.name,
                fx=r["body_forces"][b.name][0],
                fy=r["body_forces"][b.name][1],
                moment=r["body_forces"][b.name][2],
                area_levelset=r["area_levelset"][b.name],
                volume_points=r["volume_points"][b.name],
            )
            for r in self.records
            for b in self.sim.bodies
        ]
        write_table(folder / "steps.csv", self.columns, self.rows)
        write_table(folder / "contacts.csv", CONTACT_COLUMNS, contacts)
        write_table(folder / "bodies.csv", BODY_COLUMNS, bodies)
        if self.series:
            for series in list(self.points_series.values()) + [self.grid_series]:
                series.write(folder)

    def outputs(self, plots=None):
        """The keywords of `Run.finish` for a multi-step result folder: no single-step
        solution, tractions or traction plot; the step files, then plots(run, folder)."""

        def files(run, folder):
            self.write(folder)
            if plots is not None:
                plots(run, folder)

        return dict(plot=None, files=files, solution=False, tractions=False)


def binned_mean(x, values, size, max_bins=800):
    """(image, extent) for imshow: the mean of `values` at the points x (n, 2) over square
    pixels of side about `size` (at most max_bins across), NaN (blank) where no point falls."""
    lo, hi = x.min(axis=0), x.max(axis=0)
    n = np.clip(np.ceil((hi - lo) / size).astype(int), 1, max_bins)
    rng = [(lo[0], lo[0] + max(hi[0] - lo[0], 1e-300)), (lo[1], lo[1] + max(hi[1] - lo[1], 1e-300))]
    total, ex, ey = np.histogram2d(x[:, 0], x[:, 1], bins=n, range=rng, weights=values)
    count = np.histogram2d(x[:, 0], x[:, 1], bins=n, range=rng)[0]
    with np.errstate(invalid="ignore", divide="ignore"):
        image = np.where(count > 0, total / count, np.nan).T  # imshow: rows are y
    return image, (ex[0], ex[-1], ey[0], ey[-1])


def plot_force_chains(sim, record, path, title="force chains"):
    """The force network of one step: segments from the centroids of the two bodies of every
    pair with a normal force to the centre of its contact zone (width by normal force; a wall's
    or obstacle's side is left out when its centroid lies far from the contact), over the mean
    stress (s_xx + s_yy) / 2 at the material points (clipped at its 2nd percentile), with the
    bodies' outlines (blue) and the rigid obstacles' (green) on the grid."""
    import contourpy
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    centroid, radius = {}, {}
    for b in sim.bodies:
        p = sim.points[b.tag]
        centroid[b.name] = np.average(p.x, axis=0, weights=p.vol)
        radius[b.name] = np.sqrt(p.vol.sum() / np.pi)
    fig, ax = plt.subplots(figsize=(6, 6))
    x = np.concatenate([p.x for p in sim.points.values()])
    mean = np.concatenate([0.5 * (p.stress[:, 0] + p.stress[:, 1]) for p in sim.points.values()])
    lo = min(np.percentile(mean, 2), -1e-300)
    # the points' mean per pixel of about h (4 points): a scatter of ~1e5 markers took 1-2 s
    image, extent = binned_mean(x, mean, sim.h)
    sc = ax.imshow(image, extent=extent, origin="lower", cmap="Greys_r", vmin=lo, vmax=0)
    # the bodies' outlines (their level sets' zero contours, each on its window) and the rigid
    # obstacles'; outlines and chains as one collection each: an artist per body or segment
    # made matplotlib's autoscaling O(N^2) (21 s of the plot at 700 grains)
    outlines = []
    for b in sim.bodies:
        i0, i1, j0, j1 = sim.windows[b.tag]
        x, y, phi = sim.xlines[i0 : i1 + 1], sim.ylines[j0 : j1 + 1], sim.levelsets[b.tag].values
        outlines += contourpy.contour_generator(x, y, phi, line_type="Separate").lines(0.0)
    ax.add_collection(LineCollection(outlines, colors="tab:blue", linewidths=0.6))
    X, Y = np.meshgrid(sim.xlines, sim.ylines)
    xy = np.c_[X.ravel(), Y.ravel()]
    for ob in getattr(sim, "obstacles", ()):
        phi = np.asarray(ob.values(xy)).reshape(X.shape)
        if phi.min() < 0 < phi.max():
            ax.contour(X, Y, phi, [0.0], colors="tab:green", linewidths=1.2)
    fmax = max([q["normal_force"] for q in record["pairs"]] + [1e-300])
    chains, widths = [], []
    for q in record["pairs"]:
        if q["normal_force"] <= 0:
            continue
        c = np.array([q["x"], q["y"]])
        # centroid -> contact for grain-like sides (a wall's centroid can be far away)
        for name in (q["body_i"], q["body_j"]):
            if name in centroid and np.linalg.norm(centroid[name] - c) < 1.5 * radius[name]:
                chains.append([centroid[name], c])
                widths.append(0.5 + 5 * q["normal_force"] / fmax)
    ax.add_collection(LineCollection(chains, colors="tab:red", linewidths=widths))
    ax.autoscale_view()
    fig.colorbar(sc, ax=ax, label="mean stress (s_xx + s_yy)/2", shrink=0.8)
    ax.set(aspect="equal", title=f"{title}, step {record['step']}")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
