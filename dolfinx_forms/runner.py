"""Run a scene description (scene_spec.py): scene, problem, stages, results, checks, outputs.

    result = dolfinx_forms.run("demos/scenes/hertz.toml", out="results/hertz")
    result.passed, result.metrics["results"]["contact_half_width"]

`run` reads and checks the description (SpecError names the bad key; nothing is computed or
written), builds the scene through `meshes.from_spec` (imported at run time: the library does
not import the scene builders), the loads and the ContactProblem, runs the stages
(protocol.py), measures the contact (results: reaction, half-width, peak pressure, ...),
compares with the analytic reference if one is named ([analytic]), evaluates the [[checks]]
and writes metrics.json (the results contract, plus `stages` and `checks`), tractions.csv,
tractions.png and solution.xdmf into one atomic folder. A failed check is reported, recorded
and makes `passed` False (the command line exits with 1); a solver failure raises
ContactSolverError and writes nothing.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mpi4py import MPI

from . import analytic, protocol
from .scene_spec import FUNCTIONS, SpecError, load, make_law

__all__ = ["run", "RunResult", "contact_results", "evaluate_checks"]
DISCRETIZATION_NAMES = {"cut": "cut", "fitted": "conforming"}  # metrics.json names


@dataclass
class RunResult:
    metrics: dict  # the metrics.json record (every rank)
    passed: bool  # every check passed
    failures: list = field(default_factory=list)  # one line per failed check
    folder: Path | None = None  # where the results are (None: not written)
    problem: object = None


# --------------------------------------------------------------------------- expressions
def _namespace(x, lib):
    """Names of a checked expression (scene_spec.parse_expression): coordinates, pi and the
    functions of numpy or UFL (`lib`)."""
    ns = {"x": x[0], "y": x[1], "z": x[2] if len(x) > 2 else 0.0, "pi": math.pi, "abs": abs}
    for f in FUNCTIONS:
        if f != "abs":
            ns[f] = getattr(lib, "ln" if (f == "log" and lib.__name__ == "ufl") else f)
    return ns


def evaluate(expr, x, lib=np):
    """A checked expression at coordinates x (numpy arrays, or the UFL SpatialCoordinate)."""
    if not isinstance(expr, str):
        return float(expr)
    return eval(compile(expr, "<expression>", "eval"), {"__builtins__": {}}, _namespace(x, lib))


def _vector(mesh, exprs):
    """A UFL vector from checked expressions (a Constant when none depends on x)."""
    import ufl
    from dolfinx import fem

    if not any(isinstance(e, str) for e in exprs):
        return fem.Constant(mesh, np.array(exprs, float))
    x = ufl.SpatialCoordinate(mesh)
    return ufl.as_vector([evaluate(e, x, ufl) for e in exprs])


# --------------------------------------------------------------------------- the problem
def _point_marker(p):
    return lambda x: np.all([np.isclose(x[k], p[k]) for k in range(len(p))], axis=0)


def _check_scene(scene, spec):
    """Every boundary marks facets, not all outside its body (a window side that the shape
    cuts off), and every Dirichlet point is a mesh vertex (collective)."""
    from dolfinx.mesh import compute_midpoints

    comm, tdim = scene.mesh.comm, scene.mesh.topology.dim
    owned = scene.mesh.topology.index_map(tdim - 1).size_local
    names = [b["name"] for b in spec["bodies"]]
    for i, b in enumerate(spec["boundaries"]):
        facets = scene.facet_tags.find(scene.boundaries[b["name"]])
        facets = facets[facets < owned]
        if comm.allreduce(len(facets)) == 0:
            raise SpecError(f"boundaries[{i}]", f"{b['name']!r} marks no facet of the mesh")
        if b["body"] is not None:
            body = scene.bodies[names.index(b["body"])]
            mid = compute_midpoints(scene.mesh, tdim - 1, facets)[:, :2]
            tol = 1e-6 * scene.h_contact
            inside = bool(len(facets)) and bool(np.any(np.asarray(body.shape(mid)) <= tol))
            if not comm.allreduce(inside, op=MPI.LOR):
                raise SpecError(
                    f"boundaries[{i}]",
                    f"{b['name']!r}: every facet lies outside "
                    f"body {b['body']!r} (a side its shape cuts off?)",
                )
    X = scene.mesh.geometry.x
    for i, d in enumerate(spec["dirichlet"]):
        if d["point"] is not None:
            hit = bool(np.any(_point_marker(d["point"])(X.T[: len(d["point"])])))
            if not comm.allreduce(hit):
                raise SpecError(f"dirichlet[{i}].point", f"{d['point']} is not a mesh vertex")


def build_problem(spec, scene, timer=None, log=print):
    """(ContactProblem, loads {name: load}, targets {name: declared value or scale})."""
    from .solver import BodyForce, ContactProblem, Dirichlet, NewtonOptions, Traction

    tags = {b["name"]: i + 1 for i, b in enumerate(spec["bodies"])}
    loads, comp = {}, {"all": None, "x": 0, "y": 1, "z": 2}
    for d in spec["dirichlet"]:
        where = d["boundary"] if d["boundary"] is not None else _point_marker(d["point"])
        loads[d["name"]] = Dirichlet(where, comp[d["component"]], 0.0)
    tractions = [
        Traction(t["boundary"], _vector(scene.mesh, t["value"]), protocol.Path(0.0, 0.0))
        for t in spec["tractions"]
    ]
    forces = [
        BodyForce(_vector(scene.mesh, f["value"]), tags.get(f["body"]), protocol.Path(0.0, 0.0))
        for f in spec["body_forces"]
    ]
    loads.update({t["name"]: ld for t, ld in zip(spec["tractions"], tractions)})
    loads.update({f["name"]: ld for f, ld in zip(spec["body_forces"], forces)})
    s = spec["solver"]
    options = "mu eps0 band grid_refine num_gauss ghost_penalty quadrature_degree cut_degree"
    problem = ContactProblem(
        scene,
        {tags[b["name"]]: make_law(b["law"]) for b in spec["bodies"]},
        degree=spec["discretization"].get("degree", 1),
        timer=timer,
        log=log,
        dirichlet=[loads[x["name"]] for x in spec["dirichlet"]],
        tractions=tractions,
        loads=forces,
        newton=NewtonOptions(**s["newton"]),
        petsc_options=s["petsc"],
        **{k: s[k] for k in options.split()},
    )
    targets = {x["name"]: x["value"] for x in spec["dirichlet"]}
    targets.update({x["name"]: x["scale"] for x in spec["tractions"] + spec["body_forces"]})
    return problem, loads, targets


def _target(problem, load, value):
    """A stage target: a number, or an expression evaluated at the condition's dofs."""
    if not isinstance(value, str):
        return float(value)
    k = next(i for i, d in enumerate(problem.dirichlet) if d is load)
    X = problem.V.tabulate_dof_coordinates()[problem.bc_dofs[k] // problem.bs]
    return np.broadcast_to(evaluate(value, X.T), (len(X),)).astype(float)


def run_stages(problem, spec, loads, targets):
    """The [[stages]] in order; returns their StageRecords. Raises ContactSolverError."""
    records = []
    for st in spec["stages"]:
        if st["kind"] == "friction":
            rec = protocol.friction_on(problem, st["mu"], label=st["label"])
        elif st["kind"] == "ramp":
            to = st["to"] if st["to"] is not None else targets
            names = list(to)
            values = [_target(problem, loads[n], to[n]) for n in names]
            boundary = spec["outputs"]["reaction"] if st["to"] is None else None
            rec = protocol.ramp(
                problem,
                [loads[n] for n in names],
                values,
                st["steps"],
                st["label"],
                boundary=boundary,
                names=names,
            )
        else:
            keys = ("boundary", "target", "first_guess", "tol", "max_iter", "monotone", "steps")
            rec = protocol.reach_force(
                problem,
                loads[st["dirichlet"]],
                component="xyz".index(st["component"]),
                label=st["label"],
                name=st["dirichlet"],
                **{k: st[k] for k in keys},
            )
        records.append(rec)
    return records


# --------------------------------------------------------------------------- results
def contact_results(pts, mu):
    """Measures of the contact points (gather_points): reaction-free, any scene. The zone
    ends are along x (zone_ends): half-widths suit interfaces that run along x."""
    from .solver import zone_ends

    x, p, q, w, gap, slip, state = (
        pts[k] for k in ("x", "p_n", "p_t", "w", "gap_n", "slip", "state")
    )
    active = state != 0
    res = {
        "num_points": {n: int(np.sum(state == k)) for k, n in enumerate(("open", "stick", "slip"))},
        "contact_force": float(np.sum(w * p)),
        "tangential_force": float(np.sum(w * q)),
        "contact_length": float(np.sum(w[active])),
        "peak_pressure": float(p.max()) if p.size else None,
        "shear_max": float(np.abs(q).max()) if q.size else None,
        "max_penetration": float(max(0.0, -gap[active].min())) if active.any() else None,
    }
    xl, xr = zone_ends(x, active, gap)
    res["contact_half_width"] = None if xl is None else float(0.5 * (xr - xl))
    res["contact_centre"] = None if xl is None else float(0.5 * (xr + xl))
    if mu > 0:  # stick zone: active points that never slipped since friction was switched on
        slipped = np.abs(slip) > 1e-9 * max(np.abs(slip).max(initial=0.0), 1e-300)
        sl, sr = zone_ends(x, active & ~slipped)
        res["stick_half_width"] = None if sl is None else float(0.5 * (sr - sl))
    return res


def _rel_l2(w, a, b):
    den = np.sum(w * b**2)
    return float(np.sqrt(np.sum(w * (a - b) ** 2) / den)) if den > 0 else None


def _hertz(ref, spec, pts, reactions, problem):
    """Hertz (and Cattaneo-Mindlin with a tangential force) at the computed loads."""
    laws = {b["name"]: b["law"] for b in spec["bodies"]}
    (l1, l2) = (laws[n] for n in ref["bodies"])
    E_star = analytic.effective_modulus(l1["E"], l1["nu"], l2["E"], l2["nu"])
    nf = ref["normal_force"]
    P = abs(reactions[nf["boundary"]]["xyz".index(nf["component"])])
    if P == 0:  # no load reached the contact: nothing to compare
        return {}, {}, {}
    a, p0 = analytic.hertz_line(P, ref["R"], E_star)
    x, w = pts["x"], pts["w"]
    res = {"pressure_rel_l2_error": _rel_l2(w, pts["p_n"], analytic.hertz_pressure(x, a, p0))}
    an = {"contact_half_width": float(a), "peak_pressure": float(p0), "load": float(P)}
    tf, mu = ref["tangential_force"], problem.mu
    if tf is not None and mu > 0:
        Q = abs(reactions[tf["boundary"]]["xyz".index(tf["component"])])
        res["tangential_ratio"] = float(Q / (mu * P))
        an["tangential_force"] = float(Q)
        if Q < mu * P:  # partial slip: Cattaneo-Mindlin
            c = float(analytic.mindlin_stick_half_width(a, Q, mu, P))
            qa = analytic.mindlin_shear(x, a, c, p0, mu)
            res["traction_rel_l2_error"] = _rel_l2(w, np.abs(pts["p_t"]), qa)
            an["stick_half_width"] = c
    xs = np.linspace(-1.5 * a, 1.5 * a, 400)
    plot = {"Hertz p(x)": (xs, analytic.hertz_pressure(xs, a, p0))}
    if "stick_half_width" in an:
        sign = np.sign(np.sum(pts["p_t"])) or 1.0
        plot["Cattaneo-Mindlin q(x)"] = (
            xs,
            sign * analytic.mindlin_shear(xs, a, an["stick_half_width"], p0, mu),
        )
    return res, an, plot


def _patch(ref, spec, pts, reactions, problem):
    """Uniform pressure of the frictionless patch test, exact and penalised (eq 51)."""
    law = next(b["law"] for b in spec["bodies"] if b["name"] == ref["body"])
    Ep, d, H = law["E"] / (1 - law["nu"] ** 2), ref["displacement"], ref["height"]
    exact = float(analytic.patch_pressure(law["E"], law["nu"], d / H))
    penalised = float(Ep * d / (H + Ep * problem.eps_n))
    an = {"pressure": exact, "pressure_penalised": penalised}
    p, w = pts["p_n"], pts["w"]
    if not p.size:  # no contact point: nothing to compare (the checks fail with a reason)
        return {}, an, {}
    res = {
        "pressure_mean": float(np.sum(w * p) / np.sum(w)),
        "pressure_max_rel_deviation": float(np.max(np.abs(p - penalised)) / penalised),
        "pressure_rel_error_vs_exact": float(np.max(np.abs(p - exact)) / exact),
        "pressure_rel_l2_error": _rel_l2(w, p, np.full_like(p, penalised)),
    }
    xs = np.array([pts["x"].min(), pts["x"].max()])
    return res, an, {"exact": (xs, [exact] * 2), "penalised": (xs, [penalised] * 2)}


REFERENCES = {"hertz": _hertz, "patch": _patch}


# --------------------------------------------------------------------------- checks
def lookup(metrics, path):
    """metrics['results']['reaction'][1] for 'results.reaction[1]' (KeyError if absent)."""
    node = metrics
    for part in re.findall(r"[^.\[\]]+", path):
        try:
            node = node[int(part)] if isinstance(node, list) else node[part]
        except (KeyError, IndexError, ValueError, TypeError):
            raise KeyError(path) from None
    return node


def evaluate_checks(metrics, checks):
    """Records {label, quantity, value, criterion, passed, reason} of the checks."""
    out = []
    for c in checks:
        rec = {
            "label": c["label"],
            "quantity": c["quantity"],
            "value": None,
            "passed": False,
            "reason": "",
        }
        try:
            value = lookup(metrics, c["quantity"])
            refs = {
                k: lookup(metrics, c[k]) if isinstance(c[k], str) else c[k]
                for k in ("close_to", "below", "above")
            }
        except KeyError as e:
            rec.update(criterion="", reason=f"{e.args[0]} is not in metrics.json")
            out.append(rec)
            continue
        parts, ok = [], True
        if refs["close_to"] is not None:
            tol = max(c["atol"] or 0.0, (c["rtol"] or 0.0) * abs(refs["close_to"] or 0.0))
            parts.append(f"close to {refs['close_to']:.6g} within {tol:.3g}")
            ok &= (
                value is not None
                and refs["close_to"] is not None
                and abs(value - refs["close_to"]) <= tol
            )
        if refs["below"] is not None:
            parts.append(f"<= {refs['below']:.6g}")
            ok &= value is not None and value <= refs["below"]
        if refs["above"] is not None:
            parts.append(f">= {refs['above']:.6g}")
            ok &= value is not None and value >= refs["above"]
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            ok, why = False, f"{c['quantity']} is {value!r}, not a number"
        else:
            why = "" if ok else f"{c['quantity']} = {value:.6g} is not " + " and ".join(parts)
        rec.update(value=value, criterion=" and ".join(parts), passed=bool(ok), reason=why)
        out.append(rec)
    return out


# --------------------------------------------------------------------------- run
def _reaction_boundaries(spec):
    names = [spec["outputs"]["reaction"]]
    ref = spec["analytic"] or {}
    names += [ref[k]["boundary"] for k in ("normal_force", "tangential_force") if ref.get(k)]
    return [n for n in dict.fromkeys(names) if n is not None]


def run(
    source,
    out=None,
    *,
    overrides=(),
    comm=None,
    force=False,
    write=True,
    log=print,
    build_scene=None,
) -> RunResult:
    """Run a description (a TOML path or a dict, see scene_spec). out: the result folder
    (default results/<name>); write=False computes without writing. build_scene(comm, spec)
    -> Scene replaces meshes.from_spec.build_scene. Raises SpecError (bad description),
    OutputFolderError (refused --out) before computing, ContactSolverError (solver failure)."""
    from .folders import atomic_output_dir, check_output_path
    from .output import gather_points, plot_tractions, write_fields, write_tractions
    from .results import PhaseTimer, new_metrics, write_metrics
    from .solver import solver_metrics

    spec = load(source, overrides)
    comm = MPI.COMM_WORLD if comm is None else comm
    out = Path(out if out is not None else Path("results") / spec["name"])
    if write:
        check_output_path(out, force)
    if build_scene is None:
        raise ValueError("build_scene: pass a scene builder (e.g. meshes.from_spec.build_scene),"
                         " or call dolfinx_forms.run, which passes it")
    kind = spec["discretization"]["kind"]
    metrics = new_metrics(spec["name"], DISCRETIZATION_NAMES[kind], spec)
    timer = PhaseTimer(metrics)
    with timer.phase("mesh"):
        scene = build_scene(comm, spec)
    _check_scene(scene, spec)
    problem, loads, targets = build_problem(spec, scene, timer, log)
    records = run_stages(problem, spec, loads, targets)

    reactions = {b: [float(f) for f in problem.reaction(b)] for b in _reaction_boundaries(spec)}
    pts = gather_points(problem)
    metrics["mesh"].update(
        h_contact=scene.h_contact,
        num_dofs=problem.num_dofs,
        num_cells=scene.mesh.topology.index_map(scene.mesh.topology.dim).size_global,
    )
    metrics["solver"] = solver_metrics(problem)
    metrics["stages"] = [r.as_dict() for r in records]
    plot = {}
    if comm.rank == 0:
        res = metrics["results"]
        res.update(contact_results(pts, problem.mu))
        res["reaction"] = reactions.get(spec["outputs"]["reaction"])
        res["reactions"] = reactions
        if spec["analytic"] is not None:
            r, an, plot = REFERENCES[spec["analytic"]["type"]](
                spec["analytic"], spec, pts, reactions, problem
            )
            res.update(r)
            metrics["analytic"].update(an)
        metrics["checks"] = evaluate_checks(metrics, spec["checks"])
        metrics["checks_passed"] = all(c["passed"] for c in metrics["checks"])
        for c in metrics["checks"]:
            log(
                f"check {c['label']}: {'ok' if c['passed'] else 'FAILED'} "
                f"({c['reason'] or c['criterion']})"
            )
    timer.stop()
    metrics = comm.bcast(metrics if comm.rank == 0 else None, root=0)
    failures = [
        f"check {c['label']!r} failed: {c['reason']}" for c in metrics["checks"] if not c["passed"]
    ]
    result = RunResult(metrics, not failures, failures, None, problem)
    if not write:
        return result
    o = spec["outputs"]
    with atomic_output_dir(out, comm, force=force, program="dolfinx_forms run") as folder:
        if o["solution"]:
            write_fields(folder, problem)
        if comm.rank == 0:
            if o["tractions"]:
                write_tractions(folder, pts)
            if o["plot"] and len(pts["x"]):
                plot_tractions(
                    Path(folder) / "tractions.png",
                    pts,
                    plot,
                    title=f"{spec['name']}, h = {scene.h_contact:.3g}",
                )
            write_metrics(folder, metrics)
    result.folder = out.resolve()
    return result
