"""Scene descriptions: read, check and complete a TOML (or dict) description of a contact run.

A description names the bodies (shape, law), the discretization, boundaries, conditions,
load stages, outputs and checks; `runner.run` executes it (the value rules shared with the
multi-step descriptions: spec_values.py). This module is pure Python: it
reads and checks (one `SpecError` naming the key, e.g. ``bodies[1].shape.radius: must be > 0,
got -1``) and returns the description with every default filled in, which metrics.json
records as its parameters. Keys (defaults in brackets; "box" is [[x_min, y_min], [x_max, y_max]],
an "expression" is a number or a string in x, y, z with + - * / **, pi and sqrt, sin, cos,
tan, exp, log, abs):

  name ["scene"; the file's stem], description [""], extends [none] (a description this one
      changes: its tables merged key by key, anything else replaced), method ["single-step";
      "mpm": a multi-step scene of the implicit MPM, whose keys mpm_spec.py lists]
  [units]  length [""], force [""]: the axis labels of the plots ("mm", "N": x (mm),
      traction (N/mm^2)); the numbers are the user's, in any consistent units
  [discretization]  kind = "cut" | "fitted", h (mesh size at the contact),
      cut:    extent (box of the background grid), fine [none: uniform grid] (box where the
              spacing is h, widened to the multiples of h), growth [1.2], h_far [no cap];
              uniform grids: cells [extent / h, rounded] = [n_x, n_y]
      fitted: cell ["triangle" | "quadrilateral"], degree [1], fine [the contact box], h_far
              [8 h], slope [0.25] (gmsh size growth per unit distance from `fine`),
              structured [false] (boxes without a window: transfinite grids of about h)
      both:   contact_box [the pairs' overlaps] (cells owned by MPI rank 0)
  [solver]  enforcement ["penalty" | "augmented"], multiplier_mass ["hybrid" | "consistent" |
      "lumped": augmented only, see ContactProblem], eps0 [1.0; augmented 1e-2: the loop's
      speed only], band [2 h], band_growth [4] (doublings of the band while active points
      reach its edge; spent: an error), mu [0.0], ghost_penalty [0.01], grid_refine [4],
      num_gauss [2], steps [1], quadrature_degree, cut_degree [4], linear_solver ["auto"]
      ("condensed", "factorised", "iterative": dolfinx_forms/solvers/linear.py), petsc {KEY =
      VALUE}, newton {rtol, ftol, atol, stol, max_iterations, max_cutbacks}
  [[bodies]]  name, shape = {type = "circle", centre, radius} | {type = "ellipse", centre,
      axes = [a, b], angle [0, degrees]} | {type = "box", min, max} | {type = "polygon",
      points | file (x, y per line)} | {type = "half_plane", point, normal (outward)},
      law = {type = "linear", E, nu} | {type = "orthotropic", E1, E2, E3, nu12, nu13, nu23,
      G12, angle [0, degrees]} | {type = "neo-hookean", E, nu}, window [cut: the shape's box
      on grid lines] (the body is shape ∩ window; cut: window sides are grid lines)
  [[pairs]]  bodies = [name_i, name_j]       [every pair of bodies]
  [[boundaries]]  name, and side = "bottom" | [sides] of `body`'s window (cut) or bounding
      box (fitted), or box = {x_min, x_max, y_min, y_max} (facets inside, of `body` if given)
  [[dirichlet]]  name [boundary.component], boundary | point = [x, y], component ["all" |
      "x" | "y" | "z"], value [0] (expression: a value per dof)
  [[tractions]]  name [boundary], boundary, value = [expressions], scale [1]
  [[body_forces]]  name, body [every body], value = [expressions], scale [1]
  [[stages]]  label [kind-i], kind = "ramp": to = {load name = target} [every load to its
      value / scale], steps [solver.steps] | kind = "force": dirichlet, boundary [its],
      component [its], target, first_guess, tol [1e-3], max_iter [12], monotone [false],
      steps [1] | kind = "friction": mu.          [one ramp of every load]
      Every load starts at 0 (tractions: scale 0) and moves only in the stages.
  [outputs]  tractions [true], solution [true], plot [true], reaction [the first Dirichlet
      boundary] (results.reaction)
  [analytic]  type = "hertz": R, bodies [the first pair], normal_force = {boundary,
      component}, tangential_force [none] | type = "patch": displacement, height, body
  [[checks]]  quantity (a metrics path, e.g. "results.reaction[1]"), and close_to (number or
      path) with rtol / atol, below, above; label [quantity]
"""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

from dolfinx_forms.app.spec_values import (  # noqa: F401  (parse_expression: API)
    REQUIRED,
    SIDES,
    Table,
    as_number,
    name_ref,
    newton_table,
    parse_check,
    parse_component,
    parse_expression,
    parse_law,
    parse_shape,
    petsc_table,
    plain_name,
)
from dolfinx_forms.common import SpecError  # noqa: F401  (raised here; its home is common)

__all__ = ["SpecError", "load", "validate", "apply_overrides", "parse_expression", "SIDES"]

# --------------------------------------------------------------------------- sections
def _discretization(t):
    kind = t.string("kind", choices=("cut", "fitted"))
    d = {"kind": kind, "h": t.number("h", lo=0, lo_open=True)}
    if kind == "cut":
        d["extent"] = t.box("extent")
        d["fine"] = t.box("fine", None)
        d["growth"] = t.number("growth", 1.2, lo=1)
        d["h_far"] = t.number("h_far", None, lo=0, lo_open=True)
        cells = t.raw("cells", None)
        if cells is not None:
            if not isinstance(cells, list) or len(cells) != len(d["extent"][0]):
                raise SpecError(t.path("cells"), f"must be [n_x, n_y], got {cells!r}")
            cells = [as_number(n, f"{t.path('cells')}[{i}]", lo=1, integer=True)
                     for i, n in enumerate(cells)]  # fmt: skip
            if d["fine"] is not None:
                raise SpecError(t.path("cells"), "is for uniform grids (no `fine`)")
        d["cells"] = cells
        if t.string("cell", "quadrilateral") != "quadrilateral":
            raise SpecError(t.path("cell"), "the cut grid is made of quadrilaterals")
        if t.integer("degree", 1) != 1:
            raise SpecError(t.path("degree"), "the cut discretization supports degree 1 only")
        other = ("slope", "structured")
    else:
        d["cell"] = t.string("cell", "triangle", choices=("triangle", "quadrilateral"))
        d["degree"] = t.integer("degree", 1, lo=1, hi=2)
        d["fine"] = t.box("fine", None)
        d["h_far"] = t.number("h_far", 8 * d["h"], lo=0, lo_open=True)
        d["slope"] = t.number("slope", 0.25, lo=0, lo_open=True)
        d["structured"] = t.boolean("structured", False)
        other = ("extent", "growth")
    d["contact_box"] = t.box("contact_box", None)
    for k in other:
        if t.has(k):
            raise SpecError(t.path(k), f"not used by kind = {kind!r}")
    t.done()
    return d


def _solver(t):
    from dolfinx_forms import defaults

    enforcement = t.string("enforcement", "penalty", choices=["penalty", "augmented"])
    from dolfinx_forms.geometry.pairs import DEFAULT_MULTIPLIER_MASS, MULTIPLIER_MASSES

    mass = t.string("multiplier_mass", None, choices=list(MULTIPLIER_MASSES))
    if mass is not None and enforcement != "augmented":
        raise SpecError(
            t.path("multiplier_mass"), 'needs enforcement = "augmented" (the penalty has none)'
        )
    # augmented: eps0 sets only the Uzawa loop's speed (the demos' --eps0 default likewise)
    eps0 = 1.0 if enforcement == "penalty" else defaults.TUNING.augmented_eps0
    s = dict(
        enforcement=enforcement,
        multiplier_mass=mass or (DEFAULT_MULTIPLIER_MASS if enforcement == "augmented" else None),
        eps0=t.number("eps0", eps0, lo=0, lo_open=True),
        band=t.number("band", None, lo=0, lo_open=True),
        band_growth=t.integer("band_growth", 4, lo=0, hi=10),
        mu=t.number("mu", 0.0, lo=0),
        ghost_penalty=t.number("ghost_penalty", 0.01, lo=0),
        grid_refine=t.integer("grid_refine", 4, lo=1, hi=16),
        num_gauss=t.integer("num_gauss", 2, lo=1, hi=5),
        steps=t.integer("steps", 1, lo=1, hi=1000),
        quadrature_degree=t.integer("quadrature_degree", None, lo=1, hi=20),
        cut_degree=t.integer("cut_degree", 4, lo=1, hi=20),
        linear_solver=t.string(
            "linear_solver", "auto", choices=["auto", "condensed", "factorised", "iterative"]
        ),
    )
    s["petsc"] = petsc_table(t, s["linear_solver"])
    s["newton"] = newton_table(t)
    t.done()
    return s



def _stage(t, i, loads, dirichlet, boundaries, default_steps):
    kind = t.string("kind", choices=("ramp", "force", "friction"))
    st = {"kind": kind, "label": t.string("label", f"{kind}-{i}")}
    if kind == "ramp":
        to = t.table("to", None)
        if to is not None:
            st["to"] = {}
            for k, v in to.data.items():
                if k not in loads:
                    raise SpecError(to.path(k), f"unknown load (known: {', '.join(loads)})")
                if loads[k] != "dirichlet" and isinstance(v, str):
                    raise SpecError(
                        to.path(k), "a traction or body force target is a number (its scale)"
                    )
                st["to"][k] = parse_expression(v, to.path(k))
        else:
            st["to"] = None
        st["steps"] = t.integer("steps", default_steps, lo=1, hi=1000)
    elif kind == "force":
        name = name_ref(t, "dirichlet", list(dirichlet), "Dirichlet condition")
        bc = dirichlet[name]
        st.update(
            dirichlet=name,
            boundary=name_ref(t, "boundary", boundaries, "boundary", bc.get("boundary")),
        )
        if st["boundary"] is None:
            raise SpecError(t.path("boundary"), "missing (the condition is on a point)")
        st["component"] = parse_component(t, "component", bc["component"])
        if st["component"] == "all" or bc["component"] not in ("all", st["component"]):
            raise SpecError(
                t.path("component"), f"must be the component the condition {name!r} prescribes"
            )
        if isinstance(bc["value"], str):
            raise SpecError(
                t.path("dirichlet"),
                f"{name!r} has a per-dof value: force control moves one value",
            )
        st.update(
            target=t.number("target"),
            first_guess=t.number("first_guess"),
            tol=t.number("tol", 1e-3, lo=0, lo_open=True),
            max_iter=t.integer("max_iter", 12, lo=1, hi=1000),
            monotone=t.boolean("monotone", False),
            steps=t.integer("steps", 1, lo=1, hi=1000),
        )
        if st["target"] == 0:
            raise SpecError(t.path("target"), "must not be 0 (the tolerance is relative)")
    else:
        st["mu"] = t.number("mu", lo=0)
    t.done()
    return st


def _force_ref(t, k, boundaries, default=REQUIRED):
    r = t.table(k, default)
    if r is None:
        return None
    out = {
        "boundary": name_ref(r, "boundary", boundaries, "boundary"),
        "component": parse_component(r, "component", REQUIRED),
    }
    if out["component"] == "all":
        raise SpecError(r.path("component"), "must be 'x', 'y' or 'z'")
    r.done()
    return out


def _analytic(t, bodies, pairs, boundaries):
    kind = t.string("type", choices=("hertz", "patch"))
    a = {"type": kind}
    if kind == "hertz":
        a["R"] = t.number("R", lo=0, lo_open=True)
        names = t.raw("bodies", list(pairs[0]) if pairs else None)
        if not isinstance(names, list) or len(names) != 2 or any(n not in bodies for n in names):
            raise SpecError(t.path("bodies"), f"must be two body names, got {names!r}")
        a["bodies"] = names
        a["normal_force"] = _force_ref(t, "normal_force", boundaries)
        a["tangential_force"] = _force_ref(t, "tangential_force", boundaries, None)
    else:
        a.update(
            displacement=t.number("displacement", lo=0, lo_open=True),
            height=t.number("height", lo=0, lo_open=True),
            body=name_ref(t, "body", list(bodies), "body", next(iter(bodies))),
        )
    for name in a.get("bodies", [a.get("body")]):
        if bodies[name]["law"]["type"] != "linear":
            raise SpecError(t.path("type"), f"the {kind} reference needs linear laws ({name!r})")
    t.done()
    return a


# --------------------------------------------------------------------------- the description
def _bodies(top, base_dir):
    """{name: body} of the [[bodies]] tables: shape, law, window."""
    bodies = {}
    for b in top.tables("bodies"):
        name = b.string("name")
        if name in bodies:
            raise SpecError(b.path("name"), f"duplicate body name {name!r}")
        bodies[name] = {
            "name": name,
            "shape": parse_shape(b.table("shape"), base_dir),
            "law": parse_law(b.table("law")),
            "window": b.box("window", None),
        }
        if bodies[name]["law"]["type"] in ("j2", "drucker-prager"):
            raise SpecError(
                b.path("law.type"),
                f"{bodies[name]['law']['type']} carries a history the single-step runner does "
                "not commit between its load steps: use it in a method = \"mpm\" description",
            )
        if bodies[name]["shape"]["type"] == "half_plane" and bodies[name]["window"] is None:
            raise SpecError(b.path("window"), "a half_plane body needs a window")
        b.done()
    if not bodies:
        raise SpecError("bodies", "missing (at least one [[bodies]] table)")
    return bodies


def _pairs(top, bodies):
    """The [[pairs]] in contact (default: every two bodies)."""
    names = list(bodies)
    pairs = []
    for p in top.tables("pairs"):
        v = p.raw("bodies")
        if (
            not isinstance(v, list)
            or len(v) != 2
            or v[0] == v[1]
            or any(n not in bodies for n in v)
        ):
            raise SpecError(p.path("bodies"), f"must be two different body names, got {v!r}")
        pairs.append(list(v))
        p.done()
    if not top.has("pairs"):
        pairs = [[a, b] for i, a in enumerate(names) for b in names[i + 1 :]]
    return pairs


def _boundaries(top, names):
    """{name: boundary} of the [[boundaries]]: a side of a body, or a box."""
    boundaries = {}
    for b in top.tables("boundaries"):
        name = b.string("name")
        if name in boundaries:
            raise SpecError(b.path("name"), f"duplicate boundary name {name!r}")
        bd = {"name": name, "body": name_ref(b, "body", names, "body", None)}
        if b.has("side") == b.has("box"):
            raise SpecError(b.path("side"), "give exactly one of side and box")
        if b.has("side"):
            sides = b.raw("side")
            sides = [sides] if isinstance(sides, str) else sides
            if not isinstance(sides, list) or not sides or any(s not in SIDES for s in sides):
                raise SpecError(
                    b.path("side"),
                    f"must be one or more of {', '.join(SIDES)}, got {b.raw('side')!r}",
                )
            if bd["body"] is None:
                raise SpecError(b.path("body"), "missing (side is a side of a body)")
            bd["side"] = sides
        else:
            box = b.table("box")
            bd["box"] = {
                k: box.number(k, None)
                for k in ("x_min", "x_max", "y_min", "y_max", "z_min", "z_max")
            }
            box.done()
        boundaries[name] = bd
        b.done()
    return boundaries


def _loads(top, spec, names, bnames):
    """spec's dirichlet, tractions and body_forces; returns ({load name: kind}, {name:
    Dirichlet entry}) for the stages."""
    loads, dirichlet = {}, {}

    def add_load(t, entry, kind):
        if entry["name"] in loads:
            raise SpecError(t.path("name"), f"duplicate load name {entry['name']!r}")
        loads[entry["name"]] = kind
        t.done()
        return entry

    spec["dirichlet"] = []
    for t in top.tables("dirichlet"):
        if t.has("boundary") == t.has("point"):
            raise SpecError(t.path("boundary"), "give exactly one of boundary and point")
        d = {
            "boundary": name_ref(t, "boundary", bnames, "boundary", None),
            "point": t.point("point", None),
            "component": parse_component(t, "component", "all"),
        }
        d["value"] = parse_expression(t.raw("value", 0.0), t.path("value"))
        d["name"] = t.string("name", f"{d['boundary'] or 'point'}.{d['component']}")
        dirichlet[d["name"]] = d
        spec["dirichlet"].append(add_load(t, d, "dirichlet"))
    for section, where in (("tractions", "boundary"), ("body_forces", "body")):
        spec[section] = []
        for t in top.tables(section):
            ref = (
                name_ref(t, "boundary", bnames, "boundary")
                if where == "boundary"
                else name_ref(t, "body", names, "body", None)
            )
            value = t.raw("value")
            if not isinstance(value, list) or len(value) not in (2, 3):
                raise SpecError(t.path("value"), f"must be a vector [f_x, f_y], got {value!r}")
            e = {
                where: ref,
                "value": [
                    parse_expression(v, f"{t.path('value')}[{i}]") for i, v in enumerate(value)
                ],
                "scale": t.number("scale", 1.0),
            }
            e["name"] = t.string("name", ref if ref is not None else f"{section}-{len(loads)}")
            spec[section].append(add_load(t, e, section))
    return loads, dirichlet


def validate(data, base_dir=None, default_name="scene"):
    """Check a description (a dict, as read from TOML) and return a new dict with every
    default filled in. Raises SpecError naming the first bad key."""
    top = Table(copy.deepcopy(data), "")
    name = plain_name(top, default_name)
    if top.string("method", "single-step") != "single-step":
        raise SpecError(
            "method", f"{top.raw('method')!r}: not a single-step description (the multi-step "
            "ones are read by dolfinx_forms.app.description.load)"
        )
    spec = {"name": name, "description": top.string("description", "")}
    units = top.table("units", {})
    spec["units"] = {k: units.string(k, "") for k in ("length", "force")}
    units.done()
    spec["discretization"] = _discretization(top.table("discretization"))
    spec["solver"] = _solver(top.table("solver", {}))

    bodies = _bodies(top, base_dir)
    names = list(bodies)
    spec["bodies"] = list(bodies.values())
    spec["pairs"] = pairs = _pairs(top, bodies)
    boundaries = _boundaries(top, names)
    spec["boundaries"] = list(boundaries.values())
    bnames = list(boundaries)
    loads, dirichlet = _loads(top, spec, names, bnames)

    stages = top.tables("stages")
    spec["stages"] = [
        _stage(s, i, loads, dirichlet, bnames, spec["solver"]["steps"])
        for i, s in enumerate(stages, start=1)
    ]
    if not stages:
        spec["stages"] = [
            {"kind": "ramp", "label": "load", "to": None, "steps": spec["solver"]["steps"]}
        ]

    out = top.table("outputs", {})
    first = next((d["boundary"] for d in spec["dirichlet"] if d["boundary"]), None)
    spec["outputs"] = {k: out.boolean(k, True) for k in ("tractions", "solution", "plot")}
    spec["outputs"]["reaction"] = name_ref(out, "reaction", bnames, "boundary", first)
    out.done()
    an = top.table("analytic", None)
    spec["analytic"] = None if an is None else _analytic(an, bodies, pairs, bnames)
    spec["checks"] = [parse_check(c) for c in top.tables("checks")]
    top.done()
    from dolfinx_forms.app import scene_geometry

    scene_geometry.check(spec)  # polygons, overlaps, the grid's extent, h against the bodies
    return spec


# the discretization keys one kind reads and the other refuses
KIND_ONLY = {"cut": ("extent", "growth", "cells"), "fitted": ("slope", "structured")}


def apply_overrides(data, overrides):
    """Set values given as 'a.b[1].c=VALUE' (VALUE in TOML syntax, or a bare string) in a copy
    of `data`; tables on the way are created. An override that switches discretization.kind
    drops the description's own keys of the other kind (KIND_ONLY; the quadrilateral cell and
    degree 1 a cut grid requires), so that `--set discretization.kind="fitted"` runs a cut
    scene body-fitted; keys given by --set are kept (and checked)."""
    data = copy.deepcopy(data)
    before = data.get("discretization", {}).get("kind") if isinstance(data, dict) else None
    data = _apply(data, overrides)
    d = data.get("discretization") if isinstance(data, dict) else None
    if isinstance(d, dict) and before is not None and d.get("kind") not in (None, before):
        given = {i.partition("=")[0].strip() for i in overrides}
        for k in KIND_ONLY.get(before, ()) + (("cell", "degree") if d["kind"] == "cut" else ()):
            if f"discretization.{k}" not in given:
                d.pop(k, None)
    return data


def _apply(data, overrides):
    for item in overrides:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise SpecError("--set", f"expected KEY=VALUE, got {item!r}")
        try:
            value = tomllib.loads(f"v = {text}")["v"]
        except tomllib.TOMLDecodeError:
            value = text.strip()
        parts = [p for p in key.replace("[", ".").replace("]", "").split(".") if p]
        node = data
        for i, p in enumerate(parts):
            last = i == len(parts) - 1
            if isinstance(node, list):
                if not p.isdigit() or int(p) >= len(node):
                    raise SpecError(key, f"no item {p!r} in the array of {len(node)}")
                p = int(p)
            elif not isinstance(node, dict):
                raise SpecError(key, f"{'.'.join(parts[:i])} is not a table")
            if last:
                node[p] = value
            else:
                if isinstance(node, dict) and p not in node:
                    node[p] = {}
                node = node[p]
    return data


def _merge(base, over):
    """`over` on top of `base`: tables merged key by key, anything else (arrays of tables
    included) replaced."""
    out = dict(base)
    for k, v in over.items():
        out[k] = _merge(base[k], v) if isinstance(v, dict) and isinstance(base.get(k), dict) else v
    return out


def _read(path, seen=()):
    """A TOML file as a dict, with `extends = "other.toml"` (relative to the file) resolved."""
    path = Path(path)
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except OSError as e:
        raise SpecError(str(path), f"cannot read the description ({e.strerror})") from None
    except tomllib.TOMLDecodeError as e:
        raise SpecError(str(path), f"not valid TOML ({e})") from None
    except UnicodeDecodeError as e:
        raise SpecError(str(path), f"not a UTF-8 text file (byte {e.start}: {e.reason})") from None
    base = data.pop("extends", None)
    if base is None:
        return data
    if not isinstance(base, str):
        raise SpecError("extends", f"must be a file name, got {base!r}")
    base = path.parent / base
    if base.resolve() in seen:
        raise SpecError("extends", f"{base} extends itself")
    return _merge(_read(base, (*seen, path.resolve())), data)


def read(source, overrides=()):
    """(data with the overrides applied, base folder, default name) of a TOML file path or a
    dict, before any check of its keys."""
    if isinstance(source, dict):
        return apply_overrides(source, overrides), None, "scene"
    path = Path(source)
    return apply_overrides(_read(path), overrides), path.parent, path.stem


def load(source, overrides=()):
    """A checked single-step description from a TOML file path or a dict (module docstring;
    description.load reads either kind)."""
    data, base_dir, default_name = read(source, overrides)
    return validate(data, base_dir=base_dir, default_name=default_name)
