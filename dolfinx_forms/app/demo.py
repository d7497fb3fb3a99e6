"""The run skeleton shared by the demos and the scene runner (runner.py).

A demo states the physics (its scene and problem), the protocol (its stages) and the check
(its evaluation); `run_case` does the rest, the same way for every demo:

    metrics record and phase timer -> scene (timed as "mesh") -> problem -> stages
    -> reactions and contact points -> mesh and solver blocks of metrics.json
    -> the demo's collective post-processing -> evaluation (rank 0) -> timer stop
    -> one atomic folder (folders.py): solution.xdmf, tractions.csv, tractions.png, the demo's
       own files, metrics.json -> console summary and "results in ..."

A solver failure (ContactSolverError) in the stages prints one line on stderr (rank 0),
writes nothing and gives exit status 1. Every callback receives the :class:`Run`:

    def scene(run):      return patch_cut_scene(run.comm, n=8)          # timed as "mesh"
    def problem(run):    run.loads["top"] = Dirichlet("upper_top", 1, 0.0)
                         return run.contact_problem([..., run.loads["top"]], band=0.05)
    def stages(run):     return [protocol.ramp(run.problem, run.loads["top"], -0.01)]
    def evaluate(run):   run.results.update(...); run.analytic.update(...); run.curves = {...}
    summary = "patch test: pressure {results[pressure_mean]:.6g}"  # or a function of run

    params = dict(vars(args), derived=...)   # metrics.json "parameters"; out, force from it
    sys.exit(run_case("patch", params, scene, problem, stages, evaluate,
                      reactions=["upper_top"], summary=summary))

The parts `compute` (everything up to the timer stop; raises ContactSolverError) and `write`
(the atomic folder) are what runner.run uses.
"""

import sys
from dataclasses import dataclass, field
from pathlib import Path

from dolfinx_forms.io.results import PhaseTimer, new_metrics
from dolfinx_forms.solvers.newton import ContactSolverError

__all__ = ["Run", "run_case", "compute", "write", "traction_plot", "problem_options"]

# parameters that Run.contact_problem passes on: {parameter: ContactProblem argument}
PROBLEM_OPTIONS = {
    "mu": "mu",
    "eps0": "eps0",
    "degree": "degree",
    "gauss": "num_gauss",
    "ghost_penalty": "ghost_penalty",
    "grid_refine": "grid_refine",
    "petsc": "petsc_options",
    "enforcement": "enforcement",
    "multiplier_mass": "multiplier_mass",
    "linear_solver": "linear_solver",
}


def problem_options(params):
    """The ContactProblem keywords that a run's parameters name (PROBLEM_OPTIONS): what the
    single-stage demos and the multi-step ones (`ImplicitMPM`) pass on alike."""
    return {arg: params[k] for k, arg in PROBLEM_OPTIONS.items() if k in params}


@dataclass
class Run:
    """The state of one run, handed to every callback of `run_case`."""

    name: str  # metrics.json "benchmark"
    discretization: str  # "conforming" or "cut"
    comm: object
    metrics: dict  # the metrics.json record (new_metrics); on every rank after `compute`
    timer: PhaseTimer
    scene: object = None  # build_scene's result
    problem: object = None  # build_problem's result (None: no solver, e.g. a geometry demo)
    loads: dict = field(default_factory=dict)  # named loads (build_problem fills it)
    records: list = field(default_factory=list)  # the stages' StageRecords (protocol.py)
    reactions: dict = field(default_factory=dict)  # {boundary: [Fx, Fy(, Fz)]}, every rank
    pts: dict | None = None  # the contact points (output.gather_points), rank 0 only
    data: dict = field(default_factory=dict)  # the demo's own values (collect, evaluate)
    curves: dict = field(default_factory=dict)  # analytic curves of the default plot
    plot_kw: dict = field(default_factory=dict)  # title, xlabel, ylabel of the default plot

    @property
    def params(self):
        return self.metrics["parameters"]

    @property
    def results(self):
        return self.metrics["results"]

    @property
    def analytic(self):
        return self.metrics["analytic"]

    @property
    def rank0(self):
        return self.comm.rank == 0

    def contact_problem(self, dirichlet=(), **kw):
        """A ContactProblem on the scene, timed by the run's timer, with the options that the
        parameters name: E, nu (every body linear elastic), mu, eps0, degree, ghost_penalty,
        grid_refine, gauss (num_gauss), petsc (petsc_options). Keywords override them."""
        from dolfinx_forms.solvers.problem import ContactProblem

        p, opts = self.params, {"timer": self.timer, "dirichlet": dirichlet}
        if "E" in p:
            opts["materials"] = {b.tag: (p["E"], p["nu"]) for b in self.scene.bodies}
        opts.update(problem_options(p))
        opts.update(kw)
        return ContactProblem(self.scene, opts.pop("materials"), **opts)


def traction_plot(run, path):
    """The default plot: computed tractions against `run.curves` (output.plot_tractions)."""
    from dolfinx_forms.io.output import plot_tractions

    plot_tractions(path, run.pts, run.curves, **run.plot_kw)


def compute(
    name,
    params,
    build_scene,
    build_problem=None,
    stages=None,
    evaluate=None,
    *,
    discretization=None,
    reactions=(),
    collect=None,
    comm=None,
):
    """Scene, problem, stages, reactions at `reactions` (boundary names), contact points,
    mesh and solver blocks, collect(run) on every rank, evaluate(run) on rank 0, timer stop;
    the metrics are then broadcast to every rank. Returns the Run. Raises ContactSolverError.
    discretization: metrics.json's (default params["discretization"], else "conforming").

    build_scene may set metrics["mesh"]["h_contact"] (default: scene.h_contact).
    Without build_problem (a geometry demo) the stages still run (stages(run), timed by the
    demo) and the mesh block is the demo's to fill."""
    from mpi4py import MPI

    from dolfinx_forms.io.output import gather_points
    from dolfinx_forms.solvers.problem import solver_metrics

    comm = MPI.COMM_WORLD if comm is None else comm
    discretization = discretization or params.get("discretization", "conforming")
    metrics = new_metrics(name, discretization, params)
    run = Run(name, discretization, comm, metrics, PhaseTimer(metrics))
    with run.timer.phase("mesh"):
        run.scene = build_scene(run)
    if build_problem is not None:
        run.problem = build_problem(run)
    run.records = list((stages(run) if stages is not None else None) or [])
    problem = run.problem
    if problem is not None:
        run.reactions = {b: [float(f) for f in problem.reaction(b)] for b in reactions}
        run.pts = gather_points(problem)
        mesh = run.scene.mesh
        h = metrics["mesh"]["h_contact"]  # build_scene may state its own
        metrics["mesh"].update(
            h_contact=run.scene.h_contact if h is None else h,
            num_cells=mesh.topology.index_map(mesh.topology.dim).size_global,
            num_dofs=problem.num_dofs,
        )
        metrics["solver"] = solver_metrics(problem)
    if collect is not None:
        collect(run)
    if evaluate is not None and run.rank0:
        evaluate(run)
    run.timer.stop()
    run.metrics = comm.bcast(metrics if run.rank0 else None, root=0)
    return run


def write(
    run,
    out,
    force=False,
    *,
    plot=traction_plot,
    files=None,
    solution=True,
    tractions=True,
    program=None,
):
    """The atomic result folder: solution.xdmf (collective), then on rank 0 tractions.csv,
    plot(run, folder / "tractions.png"), files(run, folder) and metrics.json last. Returns
    the folder's resolved path. Raises OutputFolderError (nothing written)."""
    from dolfinx_forms.io.folders import atomic_output_dir
    from dolfinx_forms.io.output import write_fields, write_tractions
    from dolfinx_forms.io.results import write_metrics

    with atomic_output_dir(out, run.comm, force=force, program=program) as folder:
        folder = Path(folder)
        if solution and run.problem is not None:
            write_fields(folder, run.problem)
        if run.rank0:
            if tractions and run.pts is not None:
                write_tractions(folder, run.pts)
            if plot is not None and run.pts is not None:
                plot(run, folder / "tractions.png")
            if files is not None:
                files(run, folder)
            write_metrics(folder, run.metrics)
    return Path(out).resolve()


def run_case(
    name,
    params,
    build_scene,
    build_problem=None,
    stages=None,
    evaluate=None,
    *,
    discretization=None,
    out=None,
    force=None,
    reactions=(),
    collect=None,
    plot=traction_plot,
    files=None,
    summary=None,
    comm=None,
    prog=None,
):
    """One demo run (module doc): `compute`, then `write` into `out` (default params["out"],
    force: params["force"]), then the summary (printed on rank 0: summary(run), or a format
    string filled with the metrics, "{results[peak_pressure]:.5g}") and "results in
    ...". Returns the exit status: 0, or 1 after a ContactSolverError (one line "prog: message"
    on stderr, nothing written). params: every input after defaults (metrics.json's
    "parameters"), usually dict(vars(args), derived values...)."""
    from mpi4py import MPI

    from dolfinx_forms.io import output

    prog = prog or Path(sys.argv[0]).name
    out = params["out"] if out is None else out
    force = params.get("force", False) if force is None else force
    rank0 = (comm or MPI.COMM_WORLD).rank == 0
    if plot is traction_plot and rank0:  # matplotlib's import and clean-up overlap the run
        output.start_plot_worker()
    try:
        try:
            run = compute(
                name,
                params,
                build_scene,
                build_problem,
                stages,
                evaluate,
                discretization=discretization,
                reactions=reactions,
                collect=collect,
                comm=comm,
            )
        except ContactSolverError as e:
            if rank0:
                sys.stderr.write(f"{prog}: {e}\n")
            return 1
        folder = write(run, out, force, plot=plot, files=files)
    finally:
        output.stop_plot_worker()
    if run.rank0:
        for w in run.metrics.get("solver", {}).get("warnings", []):
            print(f"WARNING: {w}")
        if summary is not None:
            print(summary(run) if callable(summary) else summary.format(**run.metrics))
        print(f"results in {folder}")
    return 0
