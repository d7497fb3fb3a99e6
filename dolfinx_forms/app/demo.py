"""The run skeleton shared by the demos and the scene runner (runner.py).

A demo reads top to bottom, the skeleton called at each step:

    with Run("patch", vars(args)) as run:          # metrics record, phase timer, plot worker
        with run.phase("mesh"):
            run.scene = patch_cut_scene(run.comm, n=8)
        top = Dirichlet("upper_top", 1, 0.0)
        run.problem = run.contact_problem([..., top], band=0.05)
        run.records = [protocol.ramp(run.problem, top, -0.01)]
        run.measure(reactions=["upper_top"])       # reactions, contact points, mesh and solver
        if run.rank0:                              # the check: the points live on rank 0
            run.results.update(...); run.analytic.update(...); run.curves = {...}
        run.finish(summary="patch test: pressure {results[pressure_mean]:.6g}")
    return run.status

`finish` stops the timer, shares the metrics with every rank, writes one atomic folder
(folders.py: solution.xdmf, tractions.csv, tractions.png, the demo's own files, metrics.json
last) and prints the warnings, the summary and "results in ...". A solver failure
(ContactSolverError) anywhere in the block prints one line on stderr (rank 0), writes nothing
and leaves `run.status` 1. `compute` and `write` are the same steps for runner.run, which is
handed its scene, problem and stages as functions of the description.
"""

import sys
from pathlib import Path

from dolfinx_forms.app.checks import console_warnings
from dolfinx_forms.common import SolverChoiceError
from dolfinx_forms.io.results import PhaseTimer, new_metrics
from dolfinx_forms.solvers.newton import ContactSolverError

__all__ = ["Run", "compute", "write", "traction_plot", "problem_options"]

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
    "levelset_update": "levelset_update",  # the multi-step demos (ImplicitMPM)
}


def problem_options(params):
    """The ContactProblem keywords that a run's parameters name (PROBLEM_OPTIONS): what the
    single-stage demos and the multi-step ones (`ImplicitMPM`) pass on alike."""
    return {arg: params[k] for k, arg in PROBLEM_OPTIONS.items() if k in params}


class Run:
    """One run: its metrics record and timer, then what the demo adds (scene, problem,
    records, reactions, contact points, curves of the default plot). A context manager: a
    ContactSolverError inside ends the run with one line and status 1 (module doc)."""

    def __init__(
        self, name, params, *, discretization=None, comm=None, plot=True, prog=None, reraise=False
    ):
        from mpi4py import MPI

        self.name = name  # metrics.json "benchmark"
        self.comm = MPI.COMM_WORLD if comm is None else comm
        # metrics.json's "conforming" or "cut" (default params["discretization"])
        self.discretization = discretization or params.get("discretization", "conforming")
        self.metrics = new_metrics(name, self.discretization, params)
        self.timer = PhaseTimer(self.metrics)
        self.prog = prog or Path(sys.argv[0]).name
        self.scene = None
        self.problem = None  # None: no solver (a geometry demo)
        self.loads = {}  # named loads
        self.records = []  # the stages' StageRecords (protocol.py), or the steps' records
        self.sim = None  # a multi-step run's ImplicitMPM (mpm_run.Steps)
        self.rows = []  # a multi-step run's steps.csv rows (mpm_run.Steps)
        self.reactions = {}  # {boundary: [Fx, Fy(, Fz)]}, every rank
        self.pts = None  # the contact points (output.gather_points), rank 0 only
        self.data = {}  # the demo's own values
        self.curves = {}  # analytic curves of the default plot
        self.plot_kw = {}  # title, xlabel, ylabel of the default plot
        self.status = None  # the exit status, once the run ended
        self.reraise = reraise  # one process: a ContactSolverError leaves the block (an API)
        self._plot = plot and self.rank0
        if self._plot:  # matplotlib's import and clean-up overlap the run
            from dolfinx_forms.io import output

            output.start_plot_worker()

    def __enter__(self):
        return self

    def __exit__(self, kind, error, tb):
        if self._plot:
            from dolfinx_forms.io import output

            output.stop_plot_worker()
        if kind is SystemExit and error.code not in (0, None) and self.comm.size > 1:
            # one rank leaving mid-run would leave the others in their next collective
            sys.stdout.flush()
            sys.stderr.write(f"{self.prog}: rank {self.comm.rank} exited ({error.code})\n")
            sys.stderr.flush()
            self.comm.Abort(error.code if isinstance(error.code, int) else 1)
        if kind is not None and issubclass(kind, SolverChoiceError) and not self.reraise:
            # a bad --linear-solver found once the problem is built: every rank raises it
            if self.rank0:
                sys.stderr.write(f"{self.prog}: error: --linear-solver: {error}\n")
            self.status = 2
            return True
        if kind is not None and issubclass(kind, ContactSolverError):
            if self.comm.size > 1:
                # one rank may fail alone (a step's geometry on its part): the others would
                # wait for it in their next collective, so this rank ends them all
                sys.stdout.flush()
                sys.stderr.write(f"{self.prog}: error on rank {self.comm.rank}: {error}\n")
                sys.stderr.flush()
                self.comm.Abort(1)
            if self.reraise:
                return False
            if self.rank0:
                sys.stderr.write(f"{self.prog}: {error}\n")
            self.status = 1
            return True
        return False

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

    @property
    def problem_options(self):
        """The ContactProblem keywords its parameters name (mu, eps0, --petsc,
        --linear-solver, ...), for `ContactProblem` and `ImplicitMPM` alike."""
        return problem_options(self.params)

    def phase(self, name):
        """Time a block as one of the phases of metrics.json (results.PHASES)."""
        return self.timer.phase(name)

    def contact_problem(self, dirichlet=(), **kw):
        """A ContactProblem on the scene, timed by the run's timer, with the options that the
        parameters name: E, nu (every body linear elastic), mu, eps0, degree, ghost_penalty,
        grid_refine, gauss (num_gauss), petsc (petsc_options). Keywords override them."""
        from dolfinx_forms.solvers.options import options
        from dolfinx_forms.solvers.problem import ContactProblem

        p = self.params
        materials = kw.pop("materials", None)
        if materials is None:
            materials = {b.tag: (p["E"], p["nu"]) for b in self.scene.bodies}
        direct = {k: kw.pop(k) for k in ("tractions", "loads", "obstacles", "log") if k in kw}
        grouped = options(**{**problem_options(p), **kw})
        return ContactProblem(
            self.scene, materials, dirichlet=dirichlet, timer=self.timer, **direct, **grouped
        )

    def measure(self, reactions=()):
        """After the stages: the reactions at `reactions` (boundary names), the contact points
        (on rank 0), the mesh and solver blocks of metrics.json. Collective. Without a problem
        (a geometry demo) the mesh block is the demo's to fill."""
        from dolfinx_forms.contact.resultants import contact_resultant
        from dolfinx_forms.io.output import gather_points
        from dolfinx_forms.solvers.problem import solver_metrics

        problem = self.problem
        if problem is None:
            return
        self.reactions = {b: [float(f) for f in problem.reaction(b)] for b in reactions}
        self.pts = gather_points(problem)
        mesh, block = self.scene.mesh, self.metrics["mesh"]
        h = block["h_contact"]  # the demo may state its own
        block.update(
            h_contact=self.scene.h_contact if h is None else h,
            num_cells=mesh.topology.index_map(mesh.topology.dim).size_global,
            num_dofs=problem.num_dofs,
        )
        self.metrics["solver"] = solver_metrics(problem)
        # the contact force as a vector: the resultant of the tractions (collective)
        self.results["contact_resultant"] = contact_resultant(problem)

    def close(self):
        """Stop the timer and give every rank rank 0's metrics (the evaluation is rank 0's)."""
        self.timer.stop()
        self.metrics = self.comm.bcast(self.metrics if self.rank0 else None, root=0)

    def finish(self, summary=None, *, out=None, force=None, **kw):
        """close, then the result folder (`write`: out default params["out"], force
        params["force"]; kw: plot, files, solution, tractions), then on rank 0 the warnings,
        the summary (a function of the run, or a format string filled with the metrics,
        "{results[peak_pressure]:.5g}") and "results in ...". Sets status 0."""
        self.close()
        out = self.params["out"] if out is None else out
        force = self.params.get("force", False) if force is None else force
        folder = write(self, out, force, **kw)
        if self.rank0:
            for line in console_warnings(self.metrics.get("solver", {}).get("warnings", [])):
                print(line)
            if summary is not None:
                print(summary(self) if callable(summary) else summary.format(**self.metrics))
            print(f"results in {folder}")
        self.status = 0


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
    """The steps of a demo's `with Run(...)` block with the parts given as functions of the run
    (runner.run): scene (timed as "mesh"), problem, stages, `Run.measure`, collect(run) on every
    rank, evaluate(run) on rank 0, `Run.close`. Returns the Run. Raises ContactSolverError."""
    run = Run(name, params, discretization=discretization, comm=comm, plot=False)
    with run.phase("mesh"):
        run.scene = build_scene(run)
    if build_problem is not None:
        run.problem = build_problem(run)
    run.records = list((stages(run) if stages is not None else None) or [])
    run.measure(reactions)
    if collect is not None:
        collect(run)
    if evaluate is not None and run.rank0:
        evaluate(run)
    run.close()
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
                write_tractions(folder, run.pts, frictionless=run.problem.contact.mu == 0)
            if plot is not None and run.pts is not None:
                plot(run, folder / "tractions.png")
            if files is not None:
                files(run, folder)
            write_metrics(folder, run.metrics)
    return Path(out).resolve()
