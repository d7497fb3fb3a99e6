"""Run a scene description (scene_spec.py): scene, problem, stages, results, checks, outputs.

    result = dolfinx_forms.run("demos/scenes/hertz.toml", out="results/hertz")
    result.passed, result.metrics["results"]["contact_half_width"]

`run` reads and checks the description (SpecError names the bad key; nothing is computed or
written), builds the scene through `dolfinx_forms.mesh.from_spec` (imported at run time: the library
does not import the scene builders), the loads and the ContactProblem, runs the stages
(protocol.py), measures the contact (results: reaction, half-width, peak pressure, ...),
compares with the analytic reference if one is named ([analytic]), evaluates the [[checks]]
and writes metrics.json (the results contract, plus `stages` and `checks`), tractions.csv,
tractions.png and solution.xdmf into one atomic folder. A failed check is reported, recorded
and makes `passed` False (the command line exits with 1); a solver failure raises
ContactSolverError and writes nothing. The run skeleton is the demos' (demo.compute and
demo.write), the measures and analytic comparisons theirs too (compare.py).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from mpi4py import MPI

from dolfinx_forms.analysis import analytic, compare
from dolfinx_forms.app.checks import RunResult, console_warnings, evaluate_checks
from dolfinx_forms.app.description import load
from dolfinx_forms.app.spec_values import FUNCTIONS, SpecError, make_law
from dolfinx_forms.solvers import protocol

__all__ = ["run", "RunResult", "evaluate_checks"]
DISCRETIZATION_NAMES = {"cut": "cut", "fitted": "conforming"}  # metrics.json names


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
            mid = np.ascontiguousarray(compute_midpoints(scene.mesh, tdim - 1, facets)[:, :2])
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
                dist = np.linalg.norm(X[:, : len(d["point"])] - d["point"], axis=1)
                k = int(np.argmin(dist)) if len(dist) else -1
                near = comm.allgather(
                    (dist[k], X[k, : len(d["point"])].tolist()) if k >= 0 else (np.inf, None)
                )
                _, q = min(near, key=lambda t: t[0])
                raise SpecError(
                    f"dirichlet[{i}].point",
                    f"{d['point']} is not a mesh vertex (the nearest is " f"[{q[0]!r}, {q[1]!r}])",
                )


def build_problem(spec, scene, timer=None, log=print):
    """(ContactProblem, loads {name: load}, targets {name: declared value or scale})."""
    from dolfinx_forms.fem.boundary import BodyForce, Dirichlet, Traction
    from dolfinx_forms.solvers.newton import NewtonOptions
    from dolfinx_forms.solvers.options import options
    from dolfinx_forms.solvers.problem import ContactProblem

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
    named = "mu eps0 band band_growth grid_refine num_gauss ghost_penalty quadrature_degree"
    named += " cut_degree"
    named += " linear_solver enforcement multiplier_mass"
    problem = ContactProblem(
        scene,
        {tags[b["name"]]: make_law(b["law"]) for b in spec["bodies"]},
        timer=timer,
        log=log,
        dirichlet=[loads[x["name"]] for x in spec["dirichlet"]],
        tractions=tractions,
        loads=forces,
        **options(
            **{k: s[k] for k in named.split()},
            degree=spec["discretization"].get("degree", 1),
            newton=NewtonOptions(**s["newton"]),
            petsc_options=s["petsc"],
        ),
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
def _hertz(ref, spec, pts, reactions, problem):
    """Hertz (and Cattaneo-Mindlin with a tangential force) at the computed loads."""
    laws = {b["name"]: b["law"] for b in spec["bodies"]}
    (l1, l2) = (laws[n] for n in ref["bodies"])
    E_star = analytic.effective_modulus(l1["E"], l1["nu"], l2["E"], l2["nu"])
    nf, tf = ref["normal_force"], ref["tangential_force"]
    P = abs(reactions[nf["boundary"]]["xyz".index(nf["component"])])
    if P == 0:  # no load reached the contact: nothing to compare
        return {}, {}, {}
    Q = None
    if tf is not None and problem.mu > 0:
        Q = abs(reactions[tf["boundary"]]["xyz".index(tf["component"])])
    res, an, curves = compare.hertz(pts, P, ref["R"], E_star, problem.mu, Q)
    an["load"] = float(P)
    if Q is not None:
        an["tangential_force"] = float(Q)
    return res, an, curves


def _patch(ref, spec, pts, reactions, problem):
    """Uniform pressure of the frictionless patch test, exact and penalised (eq 51; the
    augmented Lagrangian's fixed point has no penalty compliance: eps_n 0 there)."""
    law = next(b["law"] for b in spec["bodies"] if b["name"] == ref["body"])
    d, H = ref["displacement"], ref["height"]
    eps_n = 0.0 if problem.contact.augmented else problem.eps_n
    return compare.patch(pts, law["E"], law["nu"], d, H, eps_n)


REFERENCES = {"hertz": _hertz, "patch": _patch}


# --------------------------------------------------------------------------- run
def labels(spec):
    """The traction plot's axis labels in the scene's [units] (none given: no unit)."""
    u = spec["units"]
    length = f" ({u['length']})" if u["length"] else ""
    stress = f" ({u['force']}/{u['length']}^2)" if u["force"] and u["length"] else ""
    return dict(xlabel=f"x{length}", ylabel=f"traction{stress}")


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
    -> Scene replaces dolfinx_forms.mesh.from_spec.build_scene. Raises SpecError (bad description),
    OutputFolderError (refused --out) before computing, ContactSolverError (solver failure)."""
    from dolfinx_forms.app.demo import compute, traction_plot
    from dolfinx_forms.app.demo import write as write_folder
    from dolfinx_forms.io.folders import check_output_path

    spec = load(source, overrides)
    comm = MPI.COMM_WORLD if comm is None else comm
    if comm.size > 1:  # ranks that read different files would take different paths and hang
        import json

        texts = comm.allgather(json.dumps(spec, sort_keys=True, default=str))
        other = next((r for r, t in enumerate(texts) if t != texts[0]), None)
        if other is not None:
            raise SpecError(str(source), f"rank {other} read another description than rank 0")
    out = Path(out if out is not None else Path("results") / spec["name"])
    if write:
        check_output_path(out, force)
    if spec.get("method") == "mpm":  # a multi-step scene: the implicit MPM over its stages
        from dolfinx_forms.app import mpm_runner

        return mpm_runner.run(spec, out, comm=comm, force=force, write=write, log=log)
    if build_scene is None:
        raise ValueError(
            "build_scene: pass a scene builder (e.g. dolfinx_forms.mesh.from_spec.build_scene),"
            " or call dolfinx_forms.run, which passes it"
        )

    def problem(r):
        _check_scene(r.scene, spec)
        pb, r.loads, r.data["targets"] = build_problem(spec, r.scene, r.timer, log)
        return pb

    def stages(r):
        return run_stages(r.problem, spec, r.loads, r.data["targets"])

    def collect(r):  # every rank: the checks may name the stages' records
        r.metrics["stages"] = [rec.as_dict() for rec in r.records]

    def evaluate(r):
        res = r.results
        res.update(compare.contact_results(r.pts, r.problem.mu))
        res["reaction"] = r.reactions.get(spec["outputs"]["reaction"])
        res["reactions"] = r.reactions
        if spec["analytic"] is not None:
            ref = REFERENCES[spec["analytic"]["type"]]
            found, an, r.curves = ref(spec["analytic"], spec, r.pts, r.reactions, r.problem)
            res.update(found)
            r.analytic.update(an)
        r.metrics["checks"] = evaluate_checks(r.metrics, spec["checks"])
        r.metrics["checks_passed"] = all(c["passed"] for c in r.metrics["checks"])
        for line in console_warnings(r.metrics["solver"]["warnings"]):  # as the demos do
            log(line)
        for c in r.metrics["checks"]:
            log(
                f"check {c['label']}: {'ok' if c['passed'] else 'FAILED'} "
                f"({c['reason'] or c['criterion']})"
            )
        r.plot_kw = dict(title=f"{spec['name']}, h = {r.scene.h_contact:.3g}", **labels(spec))

    r = compute(
        spec["name"],
        spec,
        lambda r: build_scene(comm, spec),
        problem,
        stages,
        evaluate,
        discretization=DISCRETIZATION_NAMES[spec["discretization"]["kind"]],
        reactions=_reaction_boundaries(spec),
        collect=collect,
        comm=comm,
    )
    metrics = r.metrics
    failures = [
        f"check {c['label']!r} failed: {c['reason']}" for c in metrics["checks"] if not c["passed"]
    ]
    result = RunResult(metrics, not failures, failures, None, r.problem)
    if not write:
        return result
    o = spec["outputs"]

    def plot(r, path):
        if len(r.pts["x"]):
            traction_plot(r, path)

    result.folder = write_folder(
        r,
        out,
        force,
        plot=plot if o["plot"] else None,
        solution=o["solution"],
        tractions=o["tractions"],
        program="dolfinx_forms run",
    )
    return result
