"""Multi-step scene descriptions (`method = "mpm"`): deformable level-set bodies carrying
material points, rigid obstacles moved step by step or to a force, run by the implicit MPM
(`dolfinx_forms.mpm.implicit.ImplicitMPM`, `mpm_runner.run`). Read and checked here, like the
single-step descriptions (scene_spec.py: `extends`, `--set`; the value rules, shapes, laws,
`[solver.petsc]`, `[solver.newton]` and `[[checks]]` of both: spec_values.py). Keys (defaults
in brackets; lengths and forces in the scene's units, angles in degrees):

  method = "mpm", name ["scene"; the file's stem], description [""]
  [units]  length [""], force [""]: the labels of the plots ("mm", "N")
  [grid]  extent = [[x_min, y_min], [x_max, y_max]] (rounded outwards to multiples of h), h
      (the uniform background grid of the level sets and the cut cells)
  [solver]  enforcement ["penalty"] or "augmented", mu [0], eps0 [1.0; augmented 1e-2] (eq 51:
      the penalty in [1e-4, 1], cli.MPM_EPS0; augmented: the loop's speed, [1e-4, 1e4]), band
      [2 h; doubled while active points reach its edge], ghost_penalty [0.01], grid_refine
      [4], num_gauss [2], linear_solver ["auto"], petsc {KEY = VALUE}, newton {rtol, ftol,
      atol, stol, max_iterations, max_cutbacks}, predictor_gap [0], levelset_update
      ["advection"], "flow" or "reference-map" (mpm/evolution.py), reinit_drift [0.2],
      extrapolate [true, false where a law carries a history] (a quasi-static step's Newton
      starts from the last step's increment where that lowers its first residual:
      mpm/increment.py)
  [dynamics]  (optional: inertia, each stage step a time step; mpm/dynamics.py PointNewmark)
      dt, integrator ["dissipative"] or "trapezoidal", gravity [[0, 0]] (per unit mass),
      viscosity [0] (Kelvin-Voigt eta: spares rigid motions), mass_damping [0] (Rayleigh's
      alpha: a drag alpha rho v)
  [[bodies]]  name, rho [1] (the density, with [dynamics]), shape (circle, ellipse, box,
      polygon: as scene_spec), law = {type =
      "linear", E, nu} | {type = "orthotropic", ...} (small strain per step) | {type =
      "neo-hookean", E, nu} | {type = "j2", E, nu, yield_stress, hardening [0]} | {type =
      "drucker-prager", E, nu, cohesion, friction_angle, dilatancy_angle [friction_angle],
      hardening [0]} (finite strain: F and the history at the points, mpm/finite_strain.py)
  [[obstacles]]  name, shape (any shape of scene_spec, half_plane included: normal outward
      from the obstacle), centre [the shape's centre; a half-plane's point; a polygon's
      vertex mean] (the point it turns about and its moment is taken about), bodies [every
      body] (the bodies it may touch)
  [[dirichlet]]  name, box = {x_min, x_max, y_min, y_max} (the grid nodes inside, of any
      body), component ["all" | "x" | "y"], value [0] (the prescribed increment per step)
  [[stages]]  label [stage-i], steps, move = {obstacle = {translation = [dx, dy] per step,
      rotation [0] degrees per step, counter-clockwise about its current centre}} (obstacles
      not named stand still), dirichlet = {name = increment per step} [each its value],
      target = {obstacle, component = "x" | "y", force (the bodies' force on the obstacle at
      the stage's end, reached linearly over its steps), tol [1e-3, relative to |force|],
      max_iter [12]}
      (the obstacle's step translation along the component is found by secant iterations, each
      a full step from the same state; its `move` translation is the first guess)
  [outputs]  series [true], series_every [10], plots [true]
  [analytic]  type = "hertz": body (a circle), obstacle (a half-plane): the contact
      half-width against a = 2 sqrt(F R (1 - nu^2) / (pi E)) at every step with a > 5 h
  [[checks]]  as scene_spec; quantities under results: steps, equilibrium_rel_max,
      area_vs_points_rel_max, mass_rel_change_max, newton_iterations_mean, contacts_final,
      obstacle_forces.<name> = [fx, fy, moment] (last step), band_final, and with [analytic]
      half_width_rel_error_max, steps_judged
"""

from __future__ import annotations

import copy

import numpy as np

from dolfinx_forms.mpm.evolution import LEVELSET_UPDATES
from dolfinx_forms.app.spec_values import (
    SpecError,
    Table,
    name_ref,
    newton_table,
    parse_check,
    parse_component,
    parse_law,
    parse_shape,
    petsc_table,
    plain_name,
)

MAX_GRID_CELLS = 16_000_000  # 4000 x 4000
MPM_LAWS = ("linear", "orthotropic", "neo-hookean", "j2", "drucker-prager")
MAX_STEPS = 100_000


def _grid(t):
    from dolfinx_forms.mesh.grid_scene import uniform_lines

    g = {"extent": t.box("extent"), "h": t.number("h", lo=0, lo_open=True)}
    t.done()
    (x0, y0), (x1, y1) = (p[:2] for p in g["extent"])
    cells = (x1 - x0) / g["h"] * (y1 - y0) / g["h"]
    if not cells <= MAX_GRID_CELLS:
        raise SpecError(
            "grid.h",
            f"gives {cells:.3g} grid cells over the extent (at most {MAX_GRID_CELLS:.3g}), "
            f"got h = {g['h']:g}",
        )
    g["xlines"] = uniform_lines(x0, x1, g["h"]).tolist()
    g["ylines"] = uniform_lines(y0, y1, g["h"]).tolist()
    return g


def _eps0(t, enforcement):
    """solver.eps0 in the range the MPM demos' --eps0 accept: cli.MPM_EPS0 with the penalty
    (measured), cli.MPM_EPS0_AUGMENTED with the augmented Lagrangian (the loop's speed)."""
    from dolfinx_forms.app.cli import MPM_EPS0, MPM_EPS0_AUGMENTED

    lo, hi = MPM_EPS0 if enforcement == "penalty" else MPM_EPS0_AUGMENTED
    eps0 = t.number("eps0", 1.0 if enforcement == "penalty" else 1e-2, lo=0, lo_open=True)
    if not lo <= eps0 <= hi:
        why = (
            "above 1 the bodies pass through each other: forces 1e5x too small at 1e6; below "
            "1e-4 Newton fails; the augmented Lagrangian takes up to 1e4"
            if enforcement == "penalty"
            else "it sets the Uzawa loop's speed only"
        )
        raise SpecError(
            t.path("eps0"),
            f"must be in {'[1e-4, 1]' if enforcement == 'penalty' else '[1e-4, 1e4]'} on the "
            f"multi-step path with {enforcement} ({why}), "
            f"got {eps0:g}",
        )
    return eps0


def _solver(t):
    enforcement = t.string("enforcement", "penalty", choices=["penalty", "augmented"])
    s = dict(
        enforcement=enforcement,
        mu=t.number("mu", 0.0, lo=0),
        eps0=_eps0(t, enforcement),
        band=t.number("band", None, lo=0, lo_open=True),
        ghost_penalty=t.number("ghost_penalty", 0.01, lo=0),
        grid_refine=t.integer("grid_refine", 4, lo=1, hi=16),
        num_gauss=t.integer("num_gauss", 2, lo=1, hi=5),
        predictor_gap=t.number("predictor_gap", 0.0, lo=0),
        levelset_update=t.string(
            "levelset_update", LEVELSET_UPDATES[0], choices=list(LEVELSET_UPDATES)
        ),
        reinit_drift=t.number("reinit_drift", 0.2, lo=0, lo_open=True),
        extrapolate=t.boolean("extrapolate", None),  # None: ImplicitMPM's choice
        linear_solver=t.string(
            "linear_solver", "auto", choices=["auto", "condensed", "factorised", "iterative"]
        ),
    )
    s["petsc"] = petsc_table(t, s["linear_solver"])
    s["newton"] = newton_table(t)
    t.done()
    return s


def _centre(shape):
    """The default centre of an obstacle: the point its rotation turns about."""
    kind = shape["type"]
    if kind in ("circle", "ellipse"):
        return list(shape["centre"][:2])
    if kind == "box":
        return [0.5 * (a + b) for a, b in zip(shape["min"][:2], shape["max"][:2])]
    if kind == "polygon":
        return np.mean(np.asarray(shape["points"], float)[:, :2], axis=0).tolist()
    return list(shape["point"][:2])


def _bodies(top, base_dir):
    bodies = {}
    for b in top.tables("bodies"):
        name = b.string("name")
        if not name.strip():
            raise SpecError(b.path("name"), "must not be empty")
        if name in bodies:
            raise SpecError(b.path("name"), f"duplicate body name {name!r}")
        shape = parse_shape(b.table("shape"), base_dir)
        if shape["type"] == "half_plane":
            raise SpecError(
                b.path("shape.type"),
                "a deformable body must be bounded (a half-plane can be "
                "a rigid obstacle: [[obstacles]])",
            )
        law = parse_law(b.table("law"))
        if law["type"] not in MPM_LAWS:
            raise SpecError(
                b.path("law.type"),
                f"the multi-step path takes the laws {', '.join(MPM_LAWS)}, got {law['type']!r}",
            )
        rho = b.number("rho", 1.0, lo=0, lo_open=True)
        bodies[name] = {"name": name, "shape": shape, "law": law, "rho": rho}
        b.done()
    if not bodies:
        raise SpecError("bodies", "missing (at least one [[bodies]] table)")
    return list(bodies.values())


def _obstacles(top, base_dir, body_names):
    out = {}
    for o in top.tables("obstacles"):
        name = o.string("name")
        if not name.strip():
            raise SpecError(o.path("name"), "must not be empty")
        if name in out or name in body_names:
            raise SpecError(o.path("name"), f"duplicate name {name!r} (bodies and obstacles)")
        shape = parse_shape(o.table("shape"), base_dir)
        touch = o.raw("bodies", None)
        if touch is not None and (
            not isinstance(touch, list) or not touch or any(n not in body_names for n in touch)
        ):
            raise SpecError(o.path("bodies"), f"must be a list of body names, got {touch!r}")
        out[name] = {
            "name": name,
            "shape": shape,
            "centre": o.point("centre", None) or _centre(shape),
            "bodies": touch,
        }
        o.done()
    return list(out.values())


def _dirichlet(top, grid):
    out = {}
    X, Y = np.meshgrid(grid["xlines"], grid["ylines"])
    for t in top.tables("dirichlet"):
        box = t.table("box")
        b = {k: box.number(k, None) for k in ("x_min", "x_max", "y_min", "y_max")}
        box.done()
        d = {"box": b, "component": parse_component(t, "component", "all")}
        if d["component"] == "z":
            raise SpecError(t.path("component"), "must be 'x', 'y' or 'all' (scenes are 2D)")
        d["value"] = t.number("value", 0.0)
        d["name"] = t.string("name", f"dirichlet-{len(out) + 1}")
        if d["name"] in out:
            raise SpecError(t.path("name"), f"duplicate name {d['name']!r}")
        if not np.any(box_mask(b, X.ravel(), Y.ravel())):
            raise SpecError(t.path("box"), f"holds no node of the grid ({b})")
        out[d["name"]] = d
        t.done()
    return out


def box_mask(b, x, y):
    """The points (x, y) inside the box {x_min, x_max, y_min, y_max} (None: unbounded)."""
    m = np.ones(np.shape(x), bool)
    for v, lo, hi in ((x, b["x_min"], b["x_max"]), (y, b["y_min"], b["y_max"])):
        if lo is not None:
            m &= v >= lo
        if hi is not None:
            m &= v <= hi
    return m


def _stage(t, i, obstacles, dirichlet, h):
    st = {"label": t.string("label", f"stage-{i}"), "steps": t.integer("steps", lo=1, hi=MAX_STEPS)}
    move = t.table("move", {})
    st["move"] = {}
    for name in list(move.data):
        if name not in obstacles:
            raise SpecError(move.path(name), f"unknown obstacle (known: {', '.join(obstacles)})")
        m = move.table(name)
        tr = m.point("translation", [0.0, 0.0])
        if len(tr) != 2:
            raise SpecError(m.path("translation"), "must be [dx, dy]")
        st["move"][name] = {"translation": tr, "rotation": m.number("rotation", 0.0)}
        m.done()
    move.done()
    inc = t.table("dirichlet", {})
    st["dirichlet"] = {n: d["value"] for n, d in dirichlet.items()}
    for name in list(inc.data):
        if name not in dirichlet:
            known = ", ".join(dirichlet) or "none"
            raise SpecError(inc.path(name), f"unknown Dirichlet condition (known: {known})")
        st["dirichlet"][name] = inc.number(name)
    inc.done()
    tg = t.table("target", None)
    st["target"] = None
    if tg is not None:
        ob = name_ref(tg, "obstacle", list(obstacles), "obstacle")
        comp = parse_component(tg, "component", "all")
        if comp not in ("x", "y"):
            raise SpecError(tg.path("component"), f"must be 'x' or 'y', got {comp!r}")
        st["target"] = dict(
            obstacle=ob,
            component=comp,
            force=tg.number("force"),
            tol=tg.number("tol", 1e-3, lo=0, lo_open=True, hi=0.5),
            max_iter=tg.integer("max_iter", 12, lo=2, hi=100),
        )
        guess = st["move"].get(ob, {"translation": [0.0, 0.0]})["translation"]["xy".index(comp)]
        if guess == 0:
            raise SpecError(
                t.path("move"),
                f"{ob!r} needs a nonzero translation along {comp} (the force target's first "
                "guess of its step motion)",
            )
    for name, m in st["move"].items():  # the band and the level-set advection follow h / 2
        travel = float(np.hypot(*m["translation"]))
        if travel > 0.5 * h:
            raise SpecError(
                f"{t.path('move')}.{name}.translation",
                f"must be at most h/2 = {0.5 * h:g} per step, got {travel:g}",
            )
    for name, v in st["dirichlet"].items():
        if abs(v) > 0.5 * h:
            raise SpecError(
                t.path("dirichlet"), f"{name!r}: at most h/2 = {0.5 * h:g} per step, got {v:g}"
            )
    t.done()
    return st


def _dynamics(t):
    from dolfinx_forms.solvers.dynamics import INTEGRATORS

    d = dict(dt=t.number("dt", lo=0, lo_open=True),
             integrator=t.string("integrator", "dissipative", choices=tuple(INTEGRATORS)),
             gravity=t.point("gravity", [0.0, 0.0]), viscosity=t.number("viscosity", 0.0, lo=0),
             mass_damping=t.number("mass_damping", 0.0, lo=0))  # fmt: skip
    if len(d["gravity"]) != 2:
        raise SpecError(t.path("gravity"), f"must be [gx, gy], got {d['gravity']}")
    t.done()
    return d


def _analytic(t, bodies, obstacles):
    kind = t.string("type", choices=("hertz",))
    body = name_ref(t, "body", [b["name"] for b in bodies], "body")
    ob = name_ref(t, "obstacle", [o["name"] for o in obstacles], "obstacle")
    b = next(x for x in bodies if x["name"] == body)
    if b["shape"]["type"] != "circle" or b["law"]["type"] != "linear":
        raise SpecError(t.path("body"), "the hertz reference needs a circle with a linear law")
    if next(o for o in obstacles if o["name"] == ob)["shape"]["type"] != "half_plane":
        raise SpecError(t.path("obstacle"), "the hertz reference needs a half-plane obstacle")
    t.done()
    return {"type": kind, "body": body, "obstacle": ob, "R": b["shape"]["radius"]}


RESULTS = ("steps", "equilibrium_rel_max", "area_vs_points_rel_max", "mass_rel_change_max",
           "newton_iterations_mean", "contacts_final", "obstacle_forces", "band_final",
           "time_final", "kinetic_energy_final")  # fmt: skip
HERTZ_RESULTS = ("half_width", "steps_judged", "half_width_rel_error_max")


def _check_path(path, key, spec):
    """A check's metrics path under results or analytic names what a multi-step run writes
    (mpm_runner.evaluate): refused here, not at the end of the run."""
    import re

    parts = re.findall(r"[^.\[\]]+", path)
    known = {"results": RESULTS + (HERTZ_RESULTS if spec["analytic"] else ()),
             "analytic": ("half_width",) if spec["analytic"] else ()}  # fmt: skip
    if parts[0] not in known:
        return  # solver, mesh, timing_s: the contract's blocks
    if len(parts) < 2 or parts[1] not in known[parts[0]]:
        names = ", ".join(known[parts[0]]) or "none (no [analytic])"
        raise SpecError(key, f"{path!r}: a multi-step run writes {parts[0]}.{{{names}}}")
    if parts[1] == "obstacle_forces":
        obstacles = [o["name"] for o in spec["obstacles"]]
        if len(parts) < 3 or parts[2] not in obstacles:
            raise SpecError(key, f"{path!r}: obstacle_forces.<one of {', '.join(obstacles)}>")


def validate(data, base_dir=None, default_name="scene"):
    """Check a multi-step description (a dict, as read from TOML) and return a new dict with
    every default filled in. Raises SpecError naming the first bad key."""
    top = Table(copy.deepcopy(data), "")
    name = plain_name(top, default_name)
    top.string("method", choices=("mpm",))
    spec = {"method": "mpm", "name": name, "description": top.string("description", "")}
    units = top.table("units", {})
    spec["units"] = {k: units.string(k, "") for k in ("length", "force")}
    units.done()
    spec["grid"] = grid = _grid(top.table("grid"))
    spec["solver"] = _solver(top.table("solver", {}))
    dyn = top.table("dynamics", None)
    spec["dynamics"] = None if dyn is None else _dynamics(dyn)
    spec["bodies"] = _bodies(top, base_dir)
    names = [b["name"] for b in spec["bodies"]]
    spec["obstacles"] = _obstacles(top, base_dir, names)
    dirichlet = _dirichlet(top, grid)
    spec["dirichlet"] = list(dirichlet.values())
    obstacles = {o["name"]: o for o in spec["obstacles"]}
    stages = top.tables("stages")
    if not stages:
        raise SpecError("stages", "missing (at least one [[stages]] table with its steps)")
    spec["stages"] = [
        _stage(s, i, obstacles, dirichlet, grid["h"]) for i, s in enumerate(stages, start=1)
    ]
    out = top.table("outputs", {})
    spec["outputs"] = dict(
        series=out.boolean("series", True),
        series_every=out.integer("series_every", 10, lo=1, hi=MAX_STEPS),
        plots=out.boolean("plots", True),
    )
    out.done()
    an = top.table("analytic", None)
    spec["analytic"] = None if an is None else _analytic(an, spec["bodies"], spec["obstacles"])
    spec["checks"] = [parse_check(c) for c in top.tables("checks")]
    for i, c in enumerate(spec["checks"]):
        for k in ("quantity", "close_to", "below", "above"):
            if isinstance(c[k], str):
                _check_path(c[k], f"checks[{i}].{k}", spec)
    top.done()
    from dolfinx_forms.app import scene_geometry

    scene_geometry.check_mpm(spec)
    return spec
