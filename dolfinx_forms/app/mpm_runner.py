"""Run a multi-step description (`method = "mpm"`, mpm_spec.py): the implicit MPM over its
stages, then results, checks and the multi-step result folder.

    result = dolfinx_forms.run("demos/scenes/brazilian_disc.toml", out="results/disc")
    result.metrics["results"]["half_width_rel_error_max"]

The scene: each body's exact shape sampled at the nodes of one uniform grid (its level set)
with material points seeded in its cells on the first step; rigid obstacles placed by their
shapes (`RigidObstacle`); Dirichlet conditions on the grid nodes in a box. Each stage sets the
obstacles' motion and the conditions' increments per step, or finds an obstacle's step motion
that brings its force to a target (secant iterations, each a step from the same state). The
folder is the multi-step demos' (`mpm_run.Steps`): steps.csv (step, stage, newton_iterations,
band, equilibrium_rel, wall_s, with [dynamics] time and kinetic_energy, then <obstacle>_fx,
_fy, _moment per obstacle), contacts.csv,
bodies.csv, the two series, force_chains.png and forces.png, metrics.json.
"""

from __future__ import annotations

import math

import numpy as np

from dolfinx_forms.solvers.newton import ContactSolverError

PROG = "python3 -m dolfinx_forms"
JUDGED = 5  # the Hertz half-width is compared where a > 5 h (a few cells across the zone)


# --------------------------------------------------------------------------- the scene
def make_obstacles(spec):
    """{name: RigidObstacle} of the description (shapes in their frames, standing still)."""
    from dolfinx_forms.geometry.obstacles import RigidObstacle
    from dolfinx_forms.mesh.from_spec import shape_of

    ext = np.asarray(spec["grid"]["extent"], float)[:, :2]
    size = 100 * float(np.max(ext[1] - ext[0]))
    out = {}
    for o in spec["obstacles"]:
        far = ext + np.array([[-1.0], [1.0]]) * float(np.max(ext[1] - ext[0]))
        sd, box = shape_of(o["shape"], far if o["shape"]["type"] == "half_plane" else None, size)
        touch = None
        if o["bodies"] is not None:
            touch = [i + 1 for i, b in enumerate(spec["bodies"]) if b["name"] in o["bodies"]]
        out[o["name"]] = RigidObstacle(
            o["name"], sd, bbox=box, center=tuple(o["centre"][:2]), bodies=touch
        )
    return out


def make_dirichlet(spec):
    """{name: Dirichlet} on the grid nodes in each box (values: the first stage's)."""
    from dolfinx_forms.app.mpm_spec import box_mask
    from dolfinx_forms.fem.boundary import Dirichlet

    comp = {"all": None, "x": 0, "y": 1}
    return {
        d["name"]: Dirichlet(lambda x, b=d["box"]: box_mask(b, x[0], x[1]), comp[d["component"]])
        for d in spec["dirichlet"]
    }


def set_stage(stage, obstacles, dirichlet):
    """The stage's motion per step: obstacles' translation and rotation, conditions' values."""
    for name, ob in obstacles.items():
        m = stage["move"].get(name, {"translation": [0.0, 0.0], "rotation": 0.0})
        ob.translation = np.array(m["translation"], float)
        ob.rotation = math.radians(m["rotation"])
    for name, d in dirichlet.items():
        d.value = float(stage["dirichlet"][name])


# --------------------------------------------------------------------------- force control
def reach_force(sim, ob, target, goal, log):
    """One step whose obstacle force component reaches `goal`: secant iterations on the
    obstacle's step translation along the component, each a full step from the same state
    (the state is restored between them). Returns the accepted step's record."""
    c = "xy".index(target["component"])
    key = f"f{target['component']}"
    tol = target["tol"] * max(abs(target["force"]), 1e-300)
    limit = 0.5 * sim.h  # the band and the advection follow h / 2 per step
    snap = sim.snapshot()
    tried = []  # (d, F)
    d = float(ob.translation[c])
    for k in range(target["max_iter"]):
        ob.translation[c] = d
        rec = sim.step()
        F = rec["obstacles"][ob.name][key]
        tried.append((d, F))
        if abs(F - goal) <= tol:
            return rec
        sim.restore(snap)
        if len(tried) == 1:  # no slope yet: the force grows with the motion about linearly
            d1 = 2 * d if F == 0 else d * goal / F
        else:
            (da, Fa), (db, Fb) = tried[-2], tried[-1]
            d1 = db - (Fb - goal) * (db - da) / (Fb - Fa) if Fb != Fa else 2 * db
        d = float(np.clip(d1, -limit, limit))
        if len(tried) > 1 and d == tried[-1][0]:
            break
    raise ContactSolverError(
        f"obstacle {ob.name!r}: force {key} = {goal:.6g} not reached within "
        f"{target['tol']:g} relative in {len(tried)} steps from the same state (last: "
        f"{tried[-1][1]:.6g} at a step motion of {tried[-1][0]:.4g}; at most h/2 = {limit:g})"
    )


# --------------------------------------------------------------------------- results
def hertz_half_width(F, R, E, nu):
    """Cylinder on a rigid flat (plane strain): a = 2 sqrt(F R (1 - nu^2) / (pi E))."""
    return 2 * np.sqrt(np.maximum(F, 0) * R * (1 - nu**2) / (np.pi * E))


def evaluate(run, spec):
    """Results of every multi-step scene (rank 0): equilibrium, area against points, mass,
    Newton, contacts, obstacle forces; with [analytic] the Hertz half-width; warnings."""
    from dolfinx_forms.mpm.implicit import equilibrium_error

    recs, res, warn = run.records, run.results, run.metrics["solver"]["warnings"]
    names = [b["name"] for b in spec["bodies"]]
    area = np.array([[r["area_levelset"][n] / r["volume_points"][n] - 1 for n in names]
                     for r in recs])  # fmt: skip
    mass = np.array([[r["mass"][n] / recs[0]["mass"][n] - 1 for n in names] for r in recs])
    # with inertia a body's contact forces balance its mass times acceleration and its
    # weight, not zero: the static equilibrium check does not apply
    eq = None if spec["dynamics"] else max(equilibrium_error(r) for r in recs)
    res.update(
        steps=len(recs),
        equilibrium_rel_max=None if eq is None else float(eq),
        area_vs_points_rel_max=float(np.abs(area).max()),
        mass_rel_change_max=float(np.abs(mass).max()),
        newton_iterations_mean=float(np.mean([r["newton_iterations"] for r in recs])),
        contacts_final=len([q for q in recs[-1]["pairs"] if q["normal_force"] > 0]),
        obstacle_forces={
            n: [o["fx"], o["fy"], o["moment"]] for n, o in recs[-1]["obstacles"].items()
        },
        band_final=float(recs[-1]["band"]),
    )
    if spec["dynamics"]:
        ek = float(sum(recs[-1]["kinetic_energy"].values()))
        res.update(time_final=float(recs[-1]["time"]), kinetic_energy_final=ek)
    elif eq > 1e-6:
        warn.append(f"a body is out of equilibrium by {eq:.1e} of the largest contact force")
    if res["area_vs_points_rel_max"] > 0.01:
        av = res["area_vs_points_rel_max"]
        warn.append(f"level-set area and point volume differ by {av:.1%}")
    an = spec["analytic"]
    if an is not None:
        law = next(b["law"] for b in spec["bodies"] if b["name"] == an["body"])
        F = np.array([np.hypot(r["obstacles"][an["obstacle"]]["fx"],
                               r["obstacles"][an["obstacle"]]["fy"]) for r in recs])  # fmt: skip
        a = np.array([next((q["half_width"] for q in r["pairs"]
                            if {q["body_i"], q["body_j"]} == {an["body"], an["obstacle"]}), 0.0)
                      for r in recs])  # fmt: skip
        a_h = hertz_half_width(F, an["R"], law["E"], law["nu"])
        judged = a > JUDGED * spec["grid"]["h"]
        err = np.abs(a / np.where(a_h > 0, a_h, np.inf) - 1)
        res.update(
            half_width=a.tolist(),
            steps_judged=int(judged.sum()),
            half_width_rel_error_max=float(err[judged].max()) if judged.any() else None,
        )
        run.analytic.update(half_width=a_h.tolist())


def step_row(rec, stage, obstacles):
    from dolfinx_forms.mpm.implicit import equilibrium_error

    row = dict(step=rec["step"], stage=stage, newton_iterations=rec["newton_iterations"],
               band=rec["band"], equilibrium_rel=equilibrium_error(rec),
               wall_s=rec["wall_s"])  # fmt: skip
    if "time" in rec:  # [dynamics]
        row.update(time=rec["time"], kinetic_energy=sum(rec["kinetic_energy"].values()))
    for name in obstacles:
        o = rec["obstacles"][name]
        row.update({f"{name}_fx": o["fx"], f"{name}_fy": o["fy"], f"{name}_moment": o["moment"]})
    return row


def plots(spec):
    """force_chains.png (the last step) and forces.png (every obstacle's force per step), with
    the scene's units on the axes."""
    u = spec["units"]
    force = f"force ({u['force']}/{u['length']})" if u["force"] and u["length"] else "force"

    def draw(run, folder):
        if not spec["outputs"]["plots"]:
            return
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from dolfinx_forms.app.mpm_run import plot_force_chains

        plot_force_chains(run.sim, run.records[-1], folder / "force_chains.png", spec["name"])
        if not spec["obstacles"]:
            return
        fig, ax = plt.subplots(figsize=(6, 4))
        steps = [r["step"] for r in run.rows]
        for o in spec["obstacles"]:
            for c, ls in (("fx", "--"), ("fy", "-")):
                y = [r[f"{o['name']}_{c}"] for r in run.rows]
                ax.plot(steps, y, ls, label=f"{o['name']} {c}")
        ax.set(xlabel="step", ylabel=force, title=f"{spec['name']}: obstacle forces")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(folder / "forces.png", dpi=120)
        plt.close(fig)

    return draw


def summary(run):
    r = run.results
    balance = (f"t = {r['time_final']:.4g}, kinetic energy {r['kinetic_energy_final']:.3e}"
               if r["equilibrium_rel_max"] is None
               else f"equilibrium {r['equilibrium_rel_max']:.1e}")  # fmt: skip
    text = (
        f"{run.name}: {r['steps']} steps, {r['contacts_final']} contacts at the end, "
        f"{balance}, area vs points "
        f"{r['area_vs_points_rel_max']:.1e}, Newton {r['newton_iterations_mean']:.1f} per step"
    )
    if r.get("half_width_rel_error_max") is not None:
        text += f", half-width vs Hertz {r['half_width_rel_error_max']:.2%} (a > {JUDGED} h)"
    return text


# --------------------------------------------------------------------------- run
def make_simulation(spec, comm, timer=None, log=print):
    """(ImplicitMPM, obstacles {name: RigidObstacle}, dirichlet {name: Dirichlet})."""
    from dolfinx_forms.app.spec_values import make_law
    from dolfinx_forms.mesh.from_spec import shape_of
    from dolfinx_forms.mesh.grid_scene import grid_scene
    from dolfinx_forms.mpm.implicit import ImplicitMPM, MPMBody
    from dolfinx_forms.solvers.newton import NewtonOptions

    g, s = spec["grid"], spec["solver"]
    bodies = [
        MPMBody(b["name"], i + 1, make_law(b["law"]), shape_of(b["shape"])[0])
        for i, b in enumerate(spec["bodies"])
    ]
    tags = [(b.name, b.tag) for b in bodies]
    dyn = spec["dynamics"]
    if dyn is not None:
        from dolfinx_forms.mpm.dynamics import PointNewmark

        rho = {b.tag: d["rho"] for b, d in zip(bodies, spec["bodies"])}
        dyn = PointNewmark(rho, dyn["dt"], dyn["integrator"], dyn["gravity"],
                           viscosity=dyn["viscosity"],
                           mass_damping=dyn["mass_damping"])  # fmt: skip
    build = grid_scene(comm, g["xlines"], g["ylines"], tags, contact_box=False)
    obstacles, dirichlet = make_obstacles(spec), make_dirichlet(spec)
    named = "enforcement mu eps0 ghost_penalty grid_refine num_gauss predictor_gap linear_solver"
    kw = {k: s[k] for k in named.split()}
    if s["band"] is not None:
        kw["band"] = s["band"]
    sim = ImplicitMPM(
        comm,
        (g["xlines"], g["ylines"]),
        bodies,
        build,
        obstacles=list(obstacles.values()),
        dirichlet=list(dirichlet.values()),
        reinit_drift=s["reinit_drift"],
        levelset_update=s["levelset_update"],
        extrapolate=s["extrapolate"],
        dynamics=dyn,
        timer=timer,
        log=log,
        petsc_options=s["petsc"],
        newton=NewtonOptions(**s["newton"]),
        **kw,
    )
    return sim, obstacles, dirichlet


def run_stages(steps, spec, obstacles, dirichlet, log=print):
    """Every stage's steps through `steps` (mpm_run.Steps), with its steps.csv rows."""
    sim = steps.sim
    for st in spec["stages"]:
        set_stage(st, obstacles, dirichlet)
        tg, start = st["target"], None
        for k in range(st["steps"]):
            if tg is None:
                rec = steps.step()
            else:
                ob = obstacles[tg["obstacle"]]
                if start is None:  # the force at the stage's start
                    prev = steps.records[-1]["obstacles"][ob.name] if steps.records else None
                    start = prev[f"f{tg['component']}"] if prev else 0.0
                goal = start + (k + 1) / st["steps"] * (tg["force"] - start)
                rec = steps.step(lambda: reach_force(sim, ob, tg, goal, log))
            steps.rows.append(step_row(rec, st["label"], obstacles))


def run(spec, out, *, comm, force=False, write=True, log=print):
    """Run a checked multi-step description (runner.run dispatches here). Returns a
    checks.RunResult. Raises ContactSolverError (nothing written) on a failed step; on
    several ranks a failure on one ends every rank (demo.Run)."""
    from pathlib import Path

    from dolfinx_forms.app.demo import Run
    from dolfinx_forms.app.demo import write as write_folder
    from dolfinx_forms.app.mpm_run import Steps
    from dolfinx_forms.app.checks import RunResult, console_warnings, evaluate_checks

    params = dict(spec, out=str(out), force=force)
    with Run(spec["name"], params, discretization="cut", comm=comm, plot=False, prog=PROG,
             reraise=True) as r:  # fmt: skip
        with r.phase("mesh"):
            sim, obstacles, dirichlet = make_simulation(spec, comm, r.timer, log)
        total = sum(st["steps"] for st in spec["stages"])
        columns = ["step", "stage", "newton_iterations", "band", "equilibrium_rel", "wall_s"]
        columns += ["time", "kinetic_energy"] if spec["dynamics"] else []
        columns += [f"{n}_{c}" for n in obstacles for c in ("fx", "fy", "moment")]
        steps = Steps(r, sim, columns, total, spec["outputs"]["series_every"])
        steps.series = spec["outputs"]["series"]
        run_stages(steps, spec, obstacles, dirichlet, log)
        steps.measure()
        if r.rank0:
            evaluate(r, spec)
            r.metrics["checks"] = evaluate_checks(r.metrics, spec["checks"])
            r.metrics["checks_passed"] = all(c["passed"] for c in r.metrics["checks"])
            for line in console_warnings(r.metrics["solver"]["warnings"]):
                log(line)
            for c in r.metrics["checks"]:
                log(f"check {c['label']}: {'ok' if c['passed'] else 'FAILED'} "
                    f"({c['reason'] or c['criterion']})")  # fmt: skip
            log(summary(r))
        r.close()
        folder = None
        if write:
            kw = steps.outputs(plots(spec))
            kw.pop("plot")
            folder = write_folder(r, out, force, **kw, plot=None, program=PROG)
    m = r.metrics
    failures = [
        f"check {c['label']!r} failed: {c['reason']}" for c in m["checks"] if not c["passed"]
    ]
    folder = None if folder is None else Path(folder)
    return RunResult(m, not failures, failures, folder, sim.problem)
