"""The values of scene descriptions, single- and multi-step alike (scene_spec.py,
mpm_spec.py): numbers, points and boxes with their bounds, expressions (a small checked
language: numbers, x, y, z, pi, + - * / **, sqrt, sin, cos, tan, exp, log, abs; evaluated once
at sample points, refused if finite at none), typed tables that refuse unknown keys, shapes,
laws, [solver.petsc] and [solver.newton], checks and the scene's name. Each refusal is one
SpecError naming the key."""

from __future__ import annotations

import ast
import math
import re
from pathlib import Path

import numpy as np

from dolfinx_forms.common import SpecError

SIDES = ("left", "right", "bottom", "top")
COMPONENTS = {"x": 0, "y": 1, "z": 2}
LAW_PARAMETERS = {  # type -> (required, optional with defaults); laws.LAWS builds them
    "linear": (("E", "nu"), {}),
    "orthotropic": (("E1", "E2", "E3", "nu12", "nu13", "nu23", "G12"), {"angle": 0.0}),
    "neo-hookean": (("E", "nu"), {}),
    # finite-strain J2 (fem/plasticity.py): the multi-step path only (its history lives on
    # the material points; a single-step description refuses it, scene_spec)
    "j2": (("E", "nu", "yield_stress"), {"hardening": 0.0}),
    # finite-strain Drucker-Prager, the same way; angles in degrees, dilatancy_angle None:
    # associative (the friction angle)
    "drucker-prager": (("E", "nu", "cohesion", "friction_angle"),
                       {"dilatancy_angle": None, "hardening": 0.0}),  # fmt: skip
}
BOUNDS = {"nu": dict(lo=-1, hi=0.5, lo_open=True, hi_open=True)}  # others: moduli > 0
BOUNDS.update({k: dict(lo=0, lo_open=True) for k in ("E", "E1", "E2", "E3", "G12", "yield_stress",
                                                      "cohesion")})  # fmt: skip
SHAPES = {  # type -> (required, optional with defaults)
    "circle": (("centre", "radius"), {}),
    "ellipse": (("centre", "axes"), {"angle": 0.0}),
    "box": (("min", "max"), {}),
    "polygon": ((), {"points": None, "file": None}),
    "half_plane": (("point", "normal"), {}),
}
CHECK_ROOTS = ("results", "analytic", "solver", "mesh", "timing_s")
FUNCTIONS = ("sqrt", "sin", "cos", "tan", "exp", "log", "abs")
# a scene's name: the folder of its results under ./results (no path, nothing outside)
NAME = re.compile(r"[A-Za-z0-9_.-]{1,100}")
REQUIRED = object()


# --------------------------------------------------------------------------- values
def as_number(v, key, lo=None, hi=None, lo_open=False, hi_open=False, integer=False):
    ok = isinstance(v, int) if integer else isinstance(v, (int, float))
    if isinstance(v, bool) or not ok or not math.isfinite(v):
        raise SpecError(key, f"must be {'an integer' if integer else 'a number'}, got {v!r}")
    if lo is not None and (v <= lo if lo_open else v < lo):
        raise SpecError(key, f"must be {'>' if lo_open else '>='} {lo}, got {v}")
    if hi is not None and (v >= hi if hi_open else v > hi):
        raise SpecError(key, f"must be {'<' if hi_open else '<='} {hi}, got {v}")
    return int(v) if integer else float(v)


def as_point(v, key):
    if not isinstance(v, list) or len(v) not in (2, 3):
        raise SpecError(key, f"must be a point [x, y], got {v!r}")
    return [as_number(c, f"{key}[{i}]") for i, c in enumerate(v)]


def as_box(v, key):
    if not isinstance(v, list) or len(v) != 2:
        raise SpecError(key, f"must be a box [[x_min, y_min], [x_max, y_max]], got {v!r}")
    lo, hi = as_point(v[0], f"{key}[0]"), as_point(v[1], f"{key}[1]")
    if len(lo) != len(hi) or not all(a < b for a, b in zip(lo, hi)):
        raise SpecError(key, f"needs min < max in every coordinate, got {v!r}")
    return [lo, hi]


MAX_EXPRESSION = 1000  # characters of an expression
MAX_EXPONENT = 100  # |constant exponent| of a power
# where an expression is tried at validation: a few generic points (no zeros, no symmetries)
SAMPLES = np.array([[0.37, 1.13, 2.71, -0.59, 5.3], [0.83, -1.7, 0.11, 3.9, 2.2]])


def parse_expression(text, key, names=("x", "y", "z")):
    """Check an expression (number or string) and return it (a float or the string). A string
    is at most MAX_EXPRESSION characters of arithmetic on the names, numbers and FUNCTIONS;
    every power has a constant exponent of size at most MAX_EXPONENT (so no `9**9**9`); it is
    evaluated once at SAMPLES (floats: no integer overflow, no exception) and refused if it is
    finite at none of them (`1/0`, `sqrt(-1.0)`, `exp(1000.0)`)."""
    if not isinstance(text, str):
        return as_number(text, key)
    if len(text) > MAX_EXPRESSION:
        raise SpecError(
            key, f"an expression of at most {MAX_EXPRESSION} characters, got {len(text)}"
        )
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError:
        raise SpecError(key, f"not an expression: {text!r}") from None
    allowed = set(names) | set(FUNCTIONS) | {"pi"}
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and node.id not in allowed:
            raise SpecError(
                key,
                f"unknown name {node.id!r} in {text!r} (allowed: {', '.join(sorted(allowed))})",
            )
        if isinstance(node, ast.Call) and not (
            isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS
        ):
            raise SpecError(key, f"only {', '.join(FUNCTIONS)} may be called in {text!r}")
        if not isinstance(
            node,
            (
                ast.Expression,
                ast.BinOp,
                ast.UnaryOp,
                ast.Constant,
                ast.Name,
                ast.Call,
                ast.Load,
                ast.operator,
                ast.unaryop,
            ),
        ):
            raise SpecError(key, f"unsupported syntax in {text!r}")
        if isinstance(node, ast.Constant) and not isinstance(node.value, (int, float)):
            raise SpecError(key, f"only numbers are allowed in {text!r}")
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
            e = node.right
            if isinstance(e, ast.UnaryOp) and isinstance(e.op, (ast.USub, ast.UAdd)):
                e = e.operand
            if not (isinstance(e, ast.Constant) and abs(e.value) <= MAX_EXPONENT):
                raise SpecError(
                    key, f"a power's exponent must be a number in [-{MAX_EXPONENT}, "
                    f"{MAX_EXPONENT}] in {text!r}"
                )
    if not np.any(np.isfinite(_sample(tree, names))):
        raise SpecError(
            key, f"{text!r} is not a finite number (tried at {SAMPLES.shape[1]} points)"
        )
    return text


def _sample(tree, names):
    """The expression `tree` (checked by parse_expression) at SAMPLES, in float64 numpy."""
    env = {n: SAMPLES[i % 2] for i, n in enumerate(names)}
    env.update({f: getattr(np, f) for f in FUNCTIONS}, pi=np.pi, np=np)
    code = compile(ast.fix_missing_locations(_FloatConstants().visit(tree)), "<spec>", "eval")
    with np.errstate(all="ignore"):
        try:
            v = eval(code, {"__builtins__": {}}, env)  # names, numbers and FUNCTIONS only
        except (ArithmeticError, ValueError):
            return np.full(SAMPLES.shape[1], np.nan)
    return np.broadcast_to(np.asarray(v, dtype=float), SAMPLES.shape[1:])


class _FloatConstants(ast.NodeTransformer):
    """Integer constants as numpy floats: `1/0` and `2**1000` overflow to inf, not raise."""

    def visit_Constant(self, node):
        f = ast.Attribute(ast.Name("np", ast.Load()), "float64", ast.Load())
        return ast.Call(f, [node], [])


class Table:
    """One table of the description: typed reads with defaults, unknown keys refused."""

    def __init__(self, data, key):
        if not isinstance(data, dict):
            raise SpecError(key, f"must be a table, got {data!r}")
        self.data, self.key, self.used = data, key, set()

    def path(self, k):
        return f"{self.key}.{k}" if self.key else k

    def has(self, k):
        return k in self.data

    def raw(self, k, default=REQUIRED):
        self.used.add(k)
        if k not in self.data:
            if default is REQUIRED:
                raise SpecError(self.path(k), "missing")
            return default
        return self.data[k]

    def number(self, k, default=REQUIRED, **bounds):
        if k not in self.data:
            return self.raw(k, default)
        return as_number(self.raw(k), self.path(k), **bounds)

    def integer(self, k, default=REQUIRED, **bounds):
        return self.number(k, default, integer=True, **bounds)

    def string(self, k, default=REQUIRED, choices=None):
        if k not in self.data:
            return self.raw(k, default)
        v = self.raw(k)
        if not isinstance(v, str):
            raise SpecError(self.path(k), f"must be a string, got {v!r}")
        if choices is not None and v not in choices:
            raise SpecError(
                self.path(k), f"must be one of {', '.join(map(repr, choices))}, got {v!r}"
            )
        return v

    def boolean(self, k, default=REQUIRED):
        v = self.raw(k, default)
        if v is None and default is None:  # absent: the program chooses
            return None
        if not isinstance(v, bool):
            raise SpecError(self.path(k), f"must be true or false, got {v!r}")
        return v

    def box(self, k, default=REQUIRED):
        v = self.raw(k, default)
        return v if v is None else as_box(v, self.path(k))

    def point(self, k, default=REQUIRED):
        v = self.raw(k, default)
        return v if v is None else as_point(v, self.path(k))

    def table(self, k, default=REQUIRED):
        v = self.raw(k, default)
        return None if v is None else Table(v, self.path(k))

    def tables(self, k):
        v = self.raw(k, [])
        if not isinstance(v, list):
            raise SpecError(self.path(k), f"must be an array of tables ([[{k}]]), got {v!r}")
        return [Table(item, f"{self.path(k)}[{i}]") for i, item in enumerate(v)]

    def done(self):
        unknown = set(self.data) - self.used
        if unknown:
            k = sorted(unknown)[0]
            known = ", ".join(sorted(self.used))
            raise SpecError(self.path(k), f"unknown key (expected one of: {known})")


def name_ref(t, k, names, what, default=REQUIRED):
    """A reference to one of `names` (e.g. a body name)."""
    v = t.string(k, default)
    if v is not None and v not in names:
        raise SpecError(t.path(k), f"unknown {what} {v!r} (known: {', '.join(names) or 'none'})")
    return v


def parse_component(t, k, default):
    v = t.raw(k, default)
    if v in ("all", None):
        return "all"
    if isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= 2:
        return "xyz"[v]
    if v not in COMPONENTS:
        raise SpecError(t.path(k), f"must be one of 'x', 'y', 'z', 'all', got {v!r}")
    return v


def petsc_table(t, linear_solver):
    """`t.petsc` {KEY = VALUE}: strings, checked as the demos' --petsc (cli.check_petsc)."""
    petsc = t.table("petsc", {})
    out = {}
    for k, v in petsc.data.items():
        if isinstance(v, (dict, list)):
            raise SpecError(petsc.path(k), f"must be a string or a number, got {v!r}")
        out[k] = str(v).lower() if isinstance(v, bool) else str(v)
    if out or linear_solver == "condensed":  # checked as the demos' --petsc
        from dolfinx_forms.app.cli import ITERATIVE_DEFAULTS, check_petsc

        base = ITERATIVE_DEFAULTS if linear_solver == "iterative" else None
        why = check_petsc(out, base, linear_solver)
        if why is not None:
            raise SpecError(t.path("petsc"), why)
    return out


def newton_table(t):
    """`t.newton` {rtol, ftol, atol, stol, max_iterations, max_cutbacks}: the given ones."""
    newton = t.table("newton", {})
    out = {k: newton.number(k, None, lo=0, lo_open=True) for k in ("rtol", "ftol", "atol", "stol")}
    for k, lo in (("max_iterations", 1), ("max_cutbacks", 0)):
        out[k] = newton.integer(k, None, lo=lo)
    newton.done()
    return {k: v for k, v in out.items() if v is not None}


def parse_shape(t, base_dir):
    kind = t.string("type", choices=tuple(SHAPES))
    s = {"type": kind}
    if kind == "circle":
        s.update(centre=t.point("centre"), radius=t.number("radius", lo=0, lo_open=True))
    elif kind == "ellipse":
        s.update(centre=t.point("centre"), angle=t.number("angle", 0.0))
        axes = t.raw("axes")
        if not isinstance(axes, list) or len(axes) != 2:
            raise SpecError(t.path("axes"), f"must be [a, b], got {axes!r}")
        s["axes"] = [
            as_number(a, f"{t.path('axes')}[{i}]", lo=0, lo_open=True) for i, a in enumerate(axes)
        ]
    elif kind == "box":
        s["min"], s["max"] = as_box([t.raw("min"), t.raw("max")], t.key)
    elif kind == "polygon":
        pts, file = t.raw("points", None), t.string("file", None)
        if (pts is None) == (file is None):
            raise SpecError(t.path("points"), "give exactly one of points and file")
        if file is not None:
            path = Path(base_dir or ".") / file
            try:
                rows = [ln.replace(",", " ").split() for ln in path.read_text().splitlines()]
                pts = [[float(c) for c in r] for r in rows if r and not r[0].startswith("#")]
            except (OSError, ValueError) as e:
                raise SpecError(t.path("file"), f"cannot read points from {path}: {e}") from None
            s["file"] = file
        if not isinstance(pts, list) or len(pts) < 3:
            raise SpecError(
                t.path("points" if file is None else "file"), "a polygon needs at least 3 points"
            )
        s["points"] = [as_point(p, f"{t.path('points')}[{i}]") for i, p in enumerate(pts)]
    else:
        s.update(point=t.point("point"), normal=t.point("normal"))
        if not any(s["normal"]):
            raise SpecError(t.path("normal"), "must not be zero")
    t.done()
    return s


def make_law(law):
    """The solver material of a checked law description: the one place where a description
    becomes a `laws.Law` (angles in the description are in degrees)."""
    from dolfinx_forms.fem.laws import LAWS
    from dolfinx_forms.fem.plasticity import DruckerPrager, J2Plasticity

    params = {k: v for k, v in law.items() if k != "type"}
    return dict(LAWS, j2=J2Plasticity, **{"drucker-prager": DruckerPrager})[law["type"]](**params)


def parse_law(t):
    kind = t.string("type", choices=tuple(LAW_PARAMETERS))
    required, optional = LAW_PARAMETERS[kind]
    law = {
        "type": kind,
        **{k: t.number(k, **BOUNDS.get(k, {})) for k in required},
        **{k: t.number(k, v) for k, v in optional.items()},
    }
    t.done()
    try:
        make_law(law)
    except ValueError as e:
        raise SpecError(t.key, str(e)) from None
    return law


def path_or_number(t, k):
    v = t.raw(k, None)
    if v is None or not isinstance(v, str):
        return v if v is None else as_number(v, t.path(k))
    metric_path(v, t.path(k))
    return v


def metric_path(v, key):
    root = v.split(".")[0].split("[")[0]
    if not isinstance(v, str) or root not in CHECK_ROOTS:
        raise SpecError(
            key,
            f"must be a metrics path starting with one of {', '.join(CHECK_ROOTS)}, got {v!r}",
        )
    return v


def parse_check(t):
    c = {"quantity": metric_path(t.string("quantity"), t.path("quantity"))}
    c["label"] = t.string("label", c["quantity"])
    for k in ("close_to", "below", "above"):
        c[k] = path_or_number(t, k)
    c["rtol"] = t.number("rtol", None, lo=0)
    c["atol"] = t.number("atol", None, lo=0)
    if c["close_to"] is None and c["below"] is None and c["above"] is None:
        raise SpecError(t.key, "give close_to (with rtol or atol), below or above")
    if c["close_to"] is not None and c["rtol"] is None and c["atol"] is None:
        raise SpecError(t.path("close_to"), "needs rtol or atol")
    t.done()
    return c


def plain_name(top, default_name):
    """The description's `name`: a plain file name, the folder of its results (default: the
    file's stem, made plain: "my scene.toml" gives "my_scene")."""
    default_name = re.sub(r"[^A-Za-z0-9_.-]", "_", default_name)[:100].strip(".") or "scene"
    name = top.string("name", default_name)
    if not NAME.fullmatch(name) or name in (".", ".."):
        raise SpecError(
            "name", f"a plain file name (letters, digits, '-', '_', '.'; at most 100), got {name!r}"
        )
    return name
