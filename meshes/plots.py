"""The demos' figures beyond the shared traction plot (dolfinx_forms.io.output): each function
writes the PNG files of one demo into its result folder. matplotlib is imported on first use
(Agg backend), so importing this module costs nothing."""

from __future__ import annotations

import numpy as np

from dolfinx_forms.app.mpm_run import binned_mean, plot_force_chains


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(plt, fig, path, tight=True):
    if tight:
        fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def brazilian_disc_plots(run, folder, half_width):
    """demos/brazilian_disc.py: half_width.png (the platens' contact half-widths against
    half_width(F, R, E, nu), Hertz) and sigma_yy.png (sigma_yy at the material points, four
    frames of the time series)."""
    plt = _pyplot()
    p, rows = run.params, run.rows
    F = np.array([r["force_top"] for r in rows])
    Fs = np.linspace(0, F.max(), 200)
    fig, ax = plt.subplots(figsize=(5, 4))
    ax.plot(Fs, half_width(Fs, p["R"], p["E"], p["nu"]), "k-", label="Hertz")
    ax.plot(F, [r["half_width_top"] for r in rows], "o", ms=3, label="top platen")
    ax.plot(F, [r["half_width_bottom"] for r in rows], "x", ms=3, label="bottom platen")
    ax.axhline(5 * p["h"], color="0.6", ls=":", label="5 h")
    ax.set(xlabel="F (N/mm)", ylabel="a (mm)", title="Brazilian disc: contact half-width")
    ax.legend()
    _save(plt, fig, folder / "half_width.png")
    frames = run.data["series"]["disc"].frames  # (step, x, {stress, ...}, cells)
    frames = [
        frames[k] for k in sorted({0, len(frames) // 3, 2 * len(frames) // 3, len(frames) - 1})
    ]
    fig, axes = plt.subplots(1, len(frames), figsize=(3.2 * len(frames), 3.4), squeeze=False)
    lo = min(f[2]["stress"][:, 1].min() for f in frames)
    for ax, (step, x, data, _) in zip(axes[0], frames):
        image, extent = binned_mean(x, data["stress"][:, 1], p["h"])
        sc = ax.imshow(image, extent=extent, origin="lower", cmap="viridis", vmin=lo, vmax=0)
        ax.set(aspect="equal", title=f"step {step:g}", xticks=[], yticks=[])
    fig.colorbar(sc, ax=axes[0].tolist(), label="sigma_yy at the material points (N/mm^2)")
    _save(plt, fig, folder / "sigma_yy.png", tight=False)


def block_plots(run, folder, reference):
    """demos/block_compression.py: force.png (force per unit thickness against compression,
    with the homogeneous solution reference(params, l_y) -> (force, l_x)) and F_yy.png (F_yy at
    the material points at the end: uniform in the exact solution)."""
    plt = _pyplot()
    p, rows = run.params, run.rows
    c = np.array([r["compression"] for r in rows])
    cs = np.linspace(0, c.max(), 100)[1:]
    fig, ax = plt.subplots(figsize=(5, 4))
    ax.plot(cs, reference(p, 1 - cs)[0] if p["law"] != "linear" else np.interp(
        cs, c, reference(p, 1 - c)[0]), "k-", label="homogeneous")  # fmt: skip
    ax.plot(c, [r["force"] for r in rows], "o", ms=3, label="MPM, top platen")
    ax.set(xlabel="compression", ylabel="F (N/mm)", title=f"Block ({p['law']})")
    ax.legend()
    _save(plt, fig, folder / "force.png")
    pts = run.sim.points[1]
    fig, ax = plt.subplots(figsize=(5, 4))
    image, extent = binned_mean(pts.x, pts.F[:, 1, 1], p["h"])
    sc = ax.imshow(image, extent=extent, origin="lower", cmap="viridis")
    ax.set(aspect="equal", title=f"F_yy at the points, step {len(rows)}")
    fig.colorbar(sc, ax=ax)
    _save(plt, fig, folder / "F_yy.png")


def disc_crush_outputs(run, folder, reference):
    """demos/disc_crush.py: reference.csv (every level of the body-fitted reference,
    meshes.disc.REFERENCE_COLUMNS), force.png (the top platen's force against compression, MPM and
    the body-fitted reference at each mesh size, and each against the finest) and plastic_zone.png (the plastic area
    fraction of both over the steps; alpha at the material points at the last step)."""
    from dolfinx_forms.io.output import write_table
    from meshes.disc import REFERENCE_COLUMNS

    write_table(folder / "reference.csv", REFERENCE_COLUMNS, reference)
    plt = _pyplot()
    p, rows = run.params, run.rows
    c = np.array([r["compression"] for r in rows])
    sizes = sorted({r["h"] for r in reference}, reverse=True)
    finest = np.array([r["force"] for r in reference if r["h"] == sizes[-1]])
    fig, (ax, dx) = plt.subplots(1, 2, figsize=(10, 4))
    for h in sizes:
        F = np.array([r["force"] for r in reference if r["h"] == h])
        ax.plot(c, F, "-", lw=1, label=f"body-fitted, h = {h:g}")
        dx.plot(c, 100 * (F / finest - 1), "-", lw=1, label=f"body-fitted, h = {h:g}")
    F = np.array([r["force"] for r in rows])
    ax.plot(c, F, "o", ms=3, label=f"MPM, h = {p['h']:g}")
    dx.plot(c, 100 * (F / finest - 1), "o", ms=3, label=f"MPM, h = {p['h']:g}")
    ax.set(xlabel="platen closure / diameter", ylabel="F (N/mm)", title=f"Disc crush ({p['law']})")
    dx.set(xlabel="platen closure / diameter", ylabel="F / F_finest - 1 (%)",
           title="against the finest body-fitted run")  # fmt: skip
    ax.legend()
    dx.legend()
    _save(plt, fig, folder / "force.png")
    if p["law"] != "j2":
        return
    fig, axes = plt.subplots(1, 2, figsize=(9, 4))
    axes[0].plot(c, [r["plastic_fraction"] for r in rows], "o", ms=3, label="MPM")
    axes[0].plot(c, [r["plastic_fraction_reference"] for r in rows], "k-", label="body-fitted")
    axes[0].set(xlabel="platen closure / diameter", ylabel="plastic area fraction",
                title="plastic zone (alpha > 0)")  # fmt: skip
    axes[0].legend()
    pts = run.sim.points[1]
    image, extent = binned_mean(pts.x, pts.history[:, -1], p["h"])
    sc = axes[1].imshow(image, extent=extent, origin="lower", cmap="magma")
    axes[1].set(aspect="equal", title=f"alpha at the points, step {len(rows)}")
    fig.colorbar(sc, ax=axes[1])
    _save(plt, fig, folder / "plastic_zone.png")


def flat_punch_plot(run, folder, tab, johnson):
    """demos/flat_punch.py: tractions.png, p_n and p_t at the contact points against
    johnson(x, a, P, nu, adhesive) -> (p, q)."""
    plt = _pyplot()
    p = run.params
    adhesive = p["adhesive"]
    xs = np.linspace(-0.98, 0.98, 400) * p["a"]
    pj, qj = johnson(xs, p["a"], p["P"], p["nu"], adhesive)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(xs, pj, "k-", label="Johnson p")
    ax.plot(tab[:, 0], tab[:, 1], ".", ms=3, label="MPM p_n")
    if adhesive:
        ax.plot(xs, qj, "k--", label="Johnson q")
        ax.plot(tab[:, 0], tab[:, 2], ".", ms=3, label="MPM p_t")
    ax.set(xlabel="x (mm)", ylabel="traction (N/mm^2)", ylim=(min(0, qj.min()) * 1.5, 4 * pj.min()),
           title="Flat punch: contact tractions")  # fmt: skip
    ax.legend()
    _save(plt, fig, folder / "tractions.png")


def max_principal(s):
    """Largest principal stress of [s_xx, s_yy, s_xy] rows."""
    return 0.5 * (s[:, 0] + s[:, 1]) + np.hypot(0.5 * (s[:, 0] - s[:, 1]), s[:, 2])


def four_grains_plots(run, folder):
    """demos/four_grains.py: force_chains.png and max_principal_stress.png (the largest
    principal stress at the material points, the active contacts' centres marked)."""
    plt = _pyplot()
    sim, rec = run.sim, run.records[-1]
    plot_force_chains(sim, rec, folder / "force_chains.png", "four grains")
    x = np.concatenate([p.x for p in sim.points.values()])
    s1 = max_principal(np.concatenate([p.stress for p in sim.points.values()]))
    lim = np.percentile(np.abs(s1), 99.5)  # the contact peaks would wash out the rest
    fig, ax = plt.subplots(figsize=(6, 6))
    image, extent = binned_mean(x, s1, sim.h)
    sc = ax.imshow(image, extent=extent, origin="lower", cmap="RdBu_r", vmin=-lim, vmax=lim)
    for q in rec["pairs"]:
        if q["normal_force"] > 0:
            ax.plot(q["x"], q["y"], "k+", ms=6)
    fig.colorbar(sc, ax=ax, label="largest principal stress (N/mm^2)", shrink=0.8)
    ax.set(aspect="equal", title=f"four grains: largest principal stress, step {rec['step']}")
    _save(plt, fig, folder / "max_principal_stress.png")


def grain_assembly_plots(run, folder):
    """demos/grain_assembly.py: force_chains.png and plate_forces.png (normal and tangential
    forces on the top and left plates per step; dotted: the end of compression)."""
    plt = _pyplot()
    plot_force_chains(run.sim, run.records[-1], folder / "force_chains.png", "grain assembly")
    fig, ax = plt.subplots(figsize=(6, 4))
    steps = [r["step"] for r in run.rows]
    for name in ("plate_top", "plate_left"):
        ax.plot(steps, [r[f"{name}_normal"] for r in run.rows], "-", label=f"{name} normal")
        ax.plot(
            steps, [r[f"{name}_tangential"] for r in run.rows], "--", label=f"{name} tangential"
        )
    ax.axvline(run.params["steps"] + 0.5, color="0.6", ls=":")
    ax.set(xlabel="step", ylabel="force (N/mm)", title="plate forces (compression | shear)")
    ax.legend(fontsize=8)
    _save(plt, fig, folder / "plate_forces.png")


def granular_column_plots(run, folder):
    """demos/granular_column.py: force_chains.png (the last step) and column.png (the walls'
    forces, the stress ratio and the coordination number against time; dotted: the ends of
    deposition and compression)."""
    plt = _pyplot()
    plot_force_chains(run.sim, run.records[-1], folder / "force_chains.png", "granular column")
    rows, p = run.rows, run.params
    t = [r["t"] for r in rows]
    fig, ax = plt.subplots(3, 1, figsize=(6, 8), sharex=True)
    for k in ("left", "right", "bottom", "top"):
        ax[0].plot(t, [r[f"force_{k}"] for r in rows], label=k)
    ax[0].set(ylabel="wall force (normal)")
    ax[0].legend(fontsize=8, ncol=4)
    ax[1].plot(t, [np.nan if r["stress_ratio"] is None else r["stress_ratio"] for r in rows])
    ax[1].set(ylabel="stress ratio $\\sigma_{yy} / \\sigma_{xx}$")
    ax[2].plot(t, [r["coordination"] for r in rows])
    ax[2].set(xlabel="time", ylabel="coordination number")
    for a in ax:
        for end in (p["t_deposit"], p["t_deposit"] + p["t_compress"]):
            a.axvline(end, color="0.6", ls=":")
    ax[0].set_title("granular column: deposition | compression | shear")
    _save(plt, fig, folder / "column.png")


def contact_geometry_plot(run, path):
    """demos/contact_geometry.py: the bodies' zero contours and Gamma_c's segments (left), the
    computed initial gaps g_n0 against the exact ones (right)."""
    plt = _pyplot()
    d, sc = run.data, run.scene
    s, x = d["s"], d["s"]["points"]
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    X = sc.grid.nodes().reshape(sc.grid.shape + (2,))
    ax[0].contour(X[..., 0], X[..., 1], sc.block.values, [0], colors="k")
    ax[0].contour(X[..., 0], X[..., 1], sc.cyl.values, [0], colors="b")
    for seg in s["segments"]:
        ax[0].plot(seg[:, 0], seg[:, 1], "g-")
    ax[0].set_aspect("equal")
    ax[0].set_title("bodies (black, blue) and $\\Gamma_c$ (green)")
    ax[1].plot(x[:, 0], d["g_n0"], "g.", label="computed $g_{n0}$")
    order = np.argsort(x[:, 0])
    ax[1].plot(x[order, 0], d["exact"][order], "k-", lw=0.8, label="exact")
    ax[1].set(xlabel="x (mm)", ylabel="initial normal gap $g_{n0}$ (mm), eq 28")
    ax[1].legend()
    _save(plt, fig, path)


def slip_plot(run, folder):
    """demos/inclined_interface.py: slip.png, the plastic slip g_t^p and the total tangential
    jump g_t along the interface (dotted: the end margins h from the sides x = 0, size)."""
    from dolfinx_forms.io.output import plot_lines

    (gt_x, gt), h, pts, size = run.data["g_t"], run.params["h"], run.pts, run.params["size"]
    o = np.argsort(gt_x)
    lines = {"total jump g_t": (gt_x[o], gt[o], "-")}
    lines["plastic slip g_t^p"] = (pts["x"], pts["slip"], ".")
    title, margins = f"{run.data['verdict']}; dotted: end margin h", (h, size - h)
    plot_lines(folder / "slip.png", lines, title, ylabel="tangential jump (mm)", vlines=margins)
