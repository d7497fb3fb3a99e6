"""Command-line contract shared by all demos (docs/contract.md).

A bad value stops the run with ONE line naming the parameter and the accepted range,
exit status 2, before anything is written (on every MPI rank: every rank parses).
`--help` shows each option's default. Every program has `--verbose` (the JIT compiler's log
lines, also ILS_VERBOSE=1); programs that write a result folder declare it with
:meth:`DemoParser.add_out`, which adds `--out` and `--force` and checks the folder while
parsing (rules: folders.py), so a run never computes and then refuses its output folder.
"""

import argparse
import copy
import gc
import math
import re
import sys

from dolfinx_forms import defaults
from dolfinx_forms.app.logs import set_verbose
from dolfinx_forms.io.folders import OutputFolderError, check_output_path

FORCE_HELP = (
    "write into an existing folder that is not a result folder of this code, adding "
    "the results next to its content (nothing there is deleted or overwritten)"
)


class DefaultsFormatter(argparse.HelpFormatter):
    """Help text with each option's default (options that take a value and have one)."""

    @staticmethod
    def _shows_default(action):
        d = action.default  # may be an array: no == against the empty values
        empty = d is None or d is argparse.SUPPRESS or (isinstance(d, (list, str)) and not d)
        return bool(action.option_strings) and action.nargs != 0 and not empty

    def _format_action(self, action):
        if not action.help and self._shows_default(action):
            action = copy.copy(action)
            action.help = "default: %(default)s"
        return super()._format_action(action)

    def _get_help_string(self, action):
        text = action.help or ""
        if self._shows_default(action) and "%(default)" not in text:
            text += " (default: %(default)s)"
        return text


class DemoParser(argparse.ArgumentParser):
    """argparse with one-line errors (argparse prints usage + error by default), defaults in
    --help, --verbose, the result-folder options of :meth:`add_out`, and no abbreviated
    options (an unknown option is an error, never a prefix of another one)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", DefaultsFormatter)
        # no abbreviations: `--h 0.1` to a program without --h would be --help (exit 0)
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)
        self._out_dest = None
        self.add_argument(
            "--verbose",
            action="store_true",
            help="show the JIT compiler's log lines (also: ILS_VERBOSE=1)",
        )

    def add_out(self, default, help="result folder (replaced atomically)"):
        """--out DIR (checked while parsing, see folders.py) and --force."""
        self.add_argument("--out", default=default, help=help)
        self.add_argument("--force", action="store_true", help=FORCE_HELP)
        self._out_dest = "out"

    def parse_args(self, args=None, namespace=None):
        """Parse and check; under MPI the ranks agree: a refusal on one rank only (an --out
        folder that exists on its node alone) ends every rank with exit 2, not a hang."""
        same_on_every_rank(self, sys.argv[1:] if args is None else args)
        from mpi4py import MPI

        comm, stop = MPI.COMM_WORLD, None
        try:
            a = self._parse(args, namespace)
        except SystemExit as e:
            stop = e
        if comm.size > 1:
            codes = comm.allgather(None if stop is None else (stop.code or 0))
            other = next((c for c in codes if c is not None), None)
            if stop is None and other is not None:
                sys.exit(other)  # another rank refused: its message is on stderr
        if stop is not None:
            raise stop
        return a

    def _parse(self, args, namespace):
        from mpi4py import MPI

        a = super().parse_args(args, namespace)
        if getattr(self, "_discretization", False):  # add_discretization
            check_discretization(self, a)
        if getattr(self, "_petsc_dest", None) is not None:  # add_petsc: KEY=VALUE -> dict
            # the trial solve reads the options on top of the chosen solver's defaults
            solver = getattr(a, "linear_solver", "auto")
            if solver == "condensed" and getattr(a, self._petsc_dest):
                self.error(
                    "--petsc: the condensed linear solver takes no PETSc options (it factorises "
                    "the bulk with MUMPS itself); give --linear-solver factorised or iterative"
                )
            if solver == "condensed" and MPI.COMM_WORLD.size > 1:
                self.error(
                    "--linear-solver: 'condensed' runs on one process (MUMPS Schur complements "
                    "are serial); give auto, factorised or iterative"
                )
            base = ITERATIVE_DEFAULTS if solver == "iterative" else None
            opts = petsc_options(self, getattr(a, self._petsc_dest), base)
            setattr(a, self._petsc_dest, opts)
        given = sys.argv[1:] if args is None else args
        if getattr(a, "multiplier_mass", None) is not None and a.enforcement != "augmented":
            self.error("--multiplier-mass: needs --enforcement augmented (the penalty has none)")
        if hasattr(a, "multiplier_mass") and a.enforcement == "augmented":
            from dolfinx_forms.geometry.pairs import DEFAULT_MULTIPLIER_MASS

            # the multi-step path's default is the lumped projection (mpm/implicit.py)
            default = "lumped" if getattr(self, "_multi_step", False) else DEFAULT_MULTIPLIER_MASS
            a.multiplier_mass = a.multiplier_mass or default
        if (
            getattr(a, "enforcement", None) == "augmented"
            and hasattr(a, "eps0")
            and not any(t == "--eps0" or str(t).startswith("--eps0=") for t in given)
        ):
            a.eps0 = defaults.TUNING.augmented_eps0  # eps0 sets the loop's speed only: the fast one
        if getattr(self, "_multi_step", False) and hasattr(a, "eps0"):
            check_mpm_eps0(self, a)
        if getattr(a, "verbose", False):
            set_verbose(True)
        if self._out_dest is not None:
            try:
                check_output_path(getattr(a, self._out_dest), force=a.force)
            except OutputFolderError as e:
                self.error(str(e))
        return a

    def error(self, message):
        sys.stderr.write(f"{self.prog}: error: {message}\n")
        sys.exit(2)


def bounded(name, lo=None, hi=None, lo_open=False, hi_open=False):
    """Float type for argparse accepting lo <(=) x <(=) hi; the message names the range."""

    def rng():
        left = "(" if lo_open else "["
        right = ")" if hi_open else "]"
        lo_s, hi_s = ("-inf" if lo is None else lo), ("inf" if hi is None else hi)
        return f"{left}{lo_s}, {hi_s}{')' if hi is None else right}"

    def convert(text):
        try:
            x = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a number in {rng()}, got {text!r}")
        bad = (
            not math.isfinite(x)
            or (lo is not None and (x <= lo if lo_open else x < lo))
            or (hi is not None and (x >= hi if hi_open else x > hi))
        )
        if bad:
            raise argparse.ArgumentTypeError(f"{name} must be in {rng()}, got {text}")
        return x

    return convert


def integer(name, values):
    """Int type for argparse accepting the integers of the range `values`; the message names
    the range (argparse's own `choices` message would list every accepted value)."""
    span = f"[{values[0]}..{values[-1]}]"

    def convert(text):
        try:
            k = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be an integer in {span}, got {text!r}")
        if k not in values:
            raise argparse.ArgumentTypeError(f"{name} must be in {span}, got {text}")
        return k

    return convert


def interval(option, text):
    """A `bounded` float type from an interval: "(0, inf)", "[0, 1)", "(-1, 0.5)"."""
    m = re.fullmatch(r"([\[(])\s*([^,\s]+)\s*,\s*([^\s\])]+)\s*([\])])", text)
    if m is None:
        raise ValueError(f"{option}: not an interval: {text!r}")
    lo, hi = (
        None if v in ("-inf", "inf") else (int(v) if v.lstrip("-").isdigit() else float(v))
        for v in m.group(2, 3)
    )
    return bounded(option, lo, hi, lo_open=m[1] == "(", hi_open=m[4] == ")")


def add_options(parser, rows):
    """Options from a table of rows (option, kind, default[, help]); kind: an interval of
    floats ("(0, inf)", "[0, 1)": checked, see `bounded`), a `range` of integers (shown as
    [lo..hi]), a list of choices, bool (a flag, default False), or int, float, str
    (unchecked). Without help, --help shows the default."""
    for option, kind, default, *help in rows:
        kw = dict(default=default, help=help[0] if help else None)
        if isinstance(kind, str):
            kw["type"] = interval(option, kind)
        elif isinstance(kind, range):
            kw.update(type=integer(option, kind), metavar=f"[{kind[0]}..{kind[-1]}]")
        elif isinstance(kind, list):
            kw.update(type=type(kind[0]), choices=kind)
        elif kind is bool:
            kw["action"] = "store_true"
        elif kind in (int, float, str):
            kw["type"] = kind
        else:
            raise TypeError(f"{option}: unknown kind {kind!r}")
        parser.add_argument(option, **kw)


def add_petsc(parser):
    """--petsc KEY=VALUE (repeatable), parsed into a dict by parse_args (petsc_options)."""
    parser.add_argument(
        "--petsc",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="PETSc option for the linear solver (prefix ils_), repeatable",
    )
    parser._petsc_dest = "petsc"


def petsc_options(parser, items, defaults=None):
    """Parse repeated --petsc KEY=VALUE into a dict (keys without the leading dash); a dict
    (already parsed, see add_petsc) is returned as it is. defaults: the solver's options that
    they override in the trial solve (default SOLVER_DEFAULTS)."""
    if isinstance(items, dict):
        return items
    opts = {}
    for item in items:
        key, sep, value = item.partition("=")
        key = key.lstrip("-")
        if not sep or not key:
            parser.error(f"--petsc: expected KEY=VALUE, got {item!r}")
        opts[key] = value
    why = check_petsc(opts, defaults)
    if why is not None:
        parser.error(f"--petsc: {why}")
    return opts


def check_petsc(opts, defaults=None, linear_solver="auto"):
    """Why PETSc options `opts` cannot be used with the linear solver (None: they can): one
    PETSc refuses (an unknown type, a value of the wrong kind), a trial solve with them fails,
    or the solver does not read one (a misspelled key, or one without effect); the condensed
    solver takes none (it factorises the bulk itself). The demos' --petsc and a scene's
    solver.petsc are checked here alike."""
    defaults = SOLVER_DEFAULTS if defaults is None else defaults
    if opts and linear_solver == "condensed":
        return (
            "the condensed linear solver takes no PETSc options (it factorises the bulk with "
            "MUMPS itself); give linear solver 'factorised' or 'iterative' with them"
        )
    keys = list(opts)
    for n in range(1, len(keys) + 1):  # the first option PETSc refuses, with those before it
        ierr = petsc_refuses({k: opts[k] for k in keys[:n]})
        if ierr is not None:
            k = keys[n - 1]
            return (
                f"PETSc refuses {k}={opts[k]} (error {ierr}: an unknown type or a value of "
                "the wrong kind)"
            )
    if not opts:
        return None
    ierr, unread = petsc_trial(opts, defaults)
    every = {**defaults, **opts}
    given = ", ".join(f"{k}={v}" for k, v in opts.items())
    if ierr is not None:
        return (
            f"a trial solve with {given} fails (PETSc error {ierr}: an option of the wrong kind "
            "for this solver)"
        )
    if unread:
        k = unread[0]
        return (
            f"the linear solver does not read {k}={opts[k]} (an unknown or misspelled key, or "
            f"one without effect with ksp_type={every['ksp_type']}, pc_type={every['pc_type']})"
        )
    return None


def petsc_refuses(opts):
    """PETSc's error code when a KSP/PC reads `opts` (set with a scratch prefix on
    COMM_SELF, then removed), None when it accepts them. Nothing is printed."""
    from petsc4py import PETSc

    o, prefix = PETSc.Options(), "ils_check_"
    for k, v in opts.items():
        o[prefix + k] = v
    ksp = PETSc.KSP().create(PETSc.COMM_SELF)
    ksp.setOptionsPrefix(prefix)
    PETSc.Sys.pushErrorHandler("ignore")
    try:
        ksp.setFromOptions()
        return None
    except PETSc.Error as e:
        return e.ierr
    finally:
        PETSc.Sys.popErrorHandler()
        for k in opts:
            o.delValue(prefix + k)
        ksp.destroy()


# the linear solver's own options (dolfinx_forms/solvers/linear.py DEFAULT_OPTIONS), which --petsc
# overrides: the trial solve reads the user's options on top of them, as the solver does
SOLVER_DEFAULTS = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
# --linear-solver iterative (linear.Iterative: CG + GAMG, its GAMG options in ITERATIVE_OPTIONS)
ITERATIVE_DEFAULTS = {"ksp_type": "cg", "pc_type": "gamg"}


def _petsc_used():
    """PetscOptionsUsed(NULL, name, &flag) of the loaded PETSc library as a function of the
    option name (no leading dash), or None where it cannot be found (then nothing is
    refused as unread)."""
    import ctypes

    try:
        with open("/proc/self/maps") as f:
            path = next(ln.split()[-1] for ln in f if "/libpetsc" in ln and ".so" in ln)
        fn = ctypes.CDLL(path).PetscOptionsUsed
    except (OSError, StopIteration, AttributeError):
        return None
    fn.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.POINTER(ctypes.c_int)]
    fn.restype = ctypes.c_int

    def used(name):
        flag = ctypes.c_int(0)
        return fn(None, name.encode(), ctypes.byref(flag)) == 0 and flag.value != 0

    return used


def _trial_matrix(PETSc, n=12):
    """A small SPD system with the solver's block size 2: two decoupled 5-point Laplacians
    on an n x n grid (large enough for a multigrid to build levels)."""
    import numpy as np

    rows, cols = [], []
    for i in range(n):
        for j in range(n):
            for ii, jj in ((i, j), (i - 1, j), (i + 1, j), (i, j - 1), (i, j + 1)):
                if 0 <= ii < n and 0 <= jj < n:
                    rows.append(i * n + j)
                    cols.append(ii * n + jj)
    rows, cols = np.array(rows), np.array(cols)
    vals = np.where(rows == cols, 4.0, -1.0)
    r2 = np.concatenate([2 * rows, 2 * rows + 1])
    c2 = np.concatenate([2 * cols, 2 * cols + 1])
    v2 = np.concatenate([vals, vals * 1.5])
    order = np.lexsort((c2, r2))
    r2, c2, v2 = r2[order], c2[order], v2[order]
    indptr = np.searchsorted(r2, np.arange(2 * n * n + 1)).astype(PETSc.IntType)
    A = PETSc.Mat().createAIJ(
        (2 * n * n, 2 * n * n),
        bsize=2,
        csr=(indptr, c2.astype(PETSc.IntType), v2),
        comm=PETSc.COMM_SELF,
    )
    A.assemble()
    return A


def petsc_trial(opts, defaults=None):
    """Solve a small system with the solver's defaults (SOLVER_DEFAULTS unless given)
    overridden by `opts` (scratch prefix,
    COMM_SELF, removed after; anything PETSc prints, e.g. ksp_view, is discarded). Returns
    (PETSc's error code or None, the keys of `opts` PETSc never read, in their order)."""
    import ctypes
    import os

    from petsc4py import PETSc

    o, prefix = PETSc.Options(), "ils_check_"
    every = {**(SOLVER_DEFAULTS if defaults is None else defaults), **opts}
    for k, v in every.items():
        o[prefix + k] = v
    A = _trial_matrix(PETSc)
    ksp = PETSc.KSP().create(PETSc.COMM_SELF)
    ksp.setOptionsPrefix(prefix)
    sys.stdout.flush()
    saved = os.dup(1)
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    PETSc.Sys.pushErrorHandler("ignore")
    ierr = None
    try:
        ksp.setOperators(A)
        ksp.setFromOptions()
        b = A.createVecLeft()
        b.set(1.0)
        x = b.duplicate()
        ksp.solve(b, x)
        for v in (b, x):
            v.destroy()
    except PETSc.Error as e:
        ierr = e.ierr
    finally:
        PETSc.Sys.popErrorHandler()
        try:
            ctypes.CDLL(None).fflush(None)  # C stdio buffers still hold the discarded text
        except (OSError, AttributeError):
            pass
        os.dup2(saved, 1)
        os.close(saved)
        os.close(null)
        used = _petsc_used() if ierr is None else None
        unread = [k for k in opts if used is not None and not used(prefix + k)]
        for k in every:
            o.delValue(prefix + k)
        ksp.destroy()
        A.destroy()
    return ierr, unread


def demo_parser(
    prog,
    doc,
    out,
    options=(),
    discretization=True,
    petsc=True,
    cells=None,
    enforcement=("penalty", "augmented"),
    multi_step=False,
    levelset_update=None,
):
    """A demo's parser: the description is the first paragraph of `doc`; --out (default `out`)
    and --force, --discretization and --ghost-penalty (add_discretization), the `options`
    table (add_options), --quads/--triangles (add_cells, with cells = (quads by default,
    help of --quads, help of --triangles)), --enforcement with the `enforcement` choices,
    --linear-solver, --petsc (add_petsc). multi_step: a demo of the MPM (MPM_ENFORCEMENT, and
    --eps0 checked by check_mpm_eps0, --levelset-update with the default `levelset_update`)."""
    p = DemoParser(prog=prog, description=doc.split("\n\n")[0])
    p._multi_step = multi_step
    enforcement = MPM_ENFORCEMENT if multi_step else enforcement
    p.add_out(out)
    if discretization:
        add_discretization(p)
    add_options(p, options)
    if cells is not None:
        add_cells(p, *cells)
    if petsc:
        add_enforcement(p, enforcement)
        add_linear_solver(p)
        add_petsc(p)
    if multi_step:
        add_levelset_update(p, levelset_update)
    return p


def add_levelset_update(parser, default=None):
    """--levelset-update of the multi-step demos: how the bodies' level sets follow them
    (mpm/evolution.py; default its first choice)."""
    from dolfinx_forms.mpm.evolution import LEVELSET_UPDATES

    parser.add_argument(
        "--levelset-update",
        choices=list(LEVELSET_UPDATES),
        default=default or LEVELSET_UPDATES[0],
        help=(
            "how the level sets follow the bodies: advection (the paper's eq 19, HJ-WENO5 with "
            "the extended increment: follows the FE increment, drifts from the points over "
            "many steps), flow (advection by the velocity whose flow is the step's map x + du "
            "to second order: no drift under rotation), reference-map (phi_0 at the MLS fit of the points' reference "
            "positions: no drift, smooths the increment over about h)"
        ),
    )


def check_scale(parser, args, size, what, max_cells=2000, displacement=True):
    """Refuse (parser.error, exit 2) a mesh finer than `max_cells` cells across `size` (mm, the
    scene's `what`) and, with `displacement`, a --displacement above a tenth of `size`
    (small strain): what a scene can mesh and the small-strain kinematics can carry."""
    if args.h < size / max_cells:
        parser.error(
            f"--h: must be >= {size / max_cells:g} mm (at most {max_cells} cells across the "
            f"{size:g} mm {what}), got {args.h}"
        )
    if displacement and args.displacement > 0.1 * size:
        parser.error(
            f"--displacement: must be <= {0.1 * size:g} mm (a tenth of the {size:g} mm {what}: "
            f"small strain), got {args.displacement}"
        )


# the multi-step MPM's --enforcement choices: the penalty, or the augmented Lagrangian (its
# multipliers and friction tractions carried from step to step, mpm/records.py)
MPM_ENFORCEMENT = ("penalty", "augmented")

# the multi-step MPM's accepted penalty factors eps0 (eq 51: eps = eps0 h / E_c), on every
# path (the demos' --eps0, a description's solver.eps0). Measured on the four MPM demos at
# eps0 = 1e-6 ... 1e6 (issue 29): the forces follow F(eps0) = F_rigid / (1 + c eps0), the
# penalty's compliance in series with the bodies'; at eps0 = 1 (the paper's, the defaults) the
# forces are 15-36 % under the rigid-contact limit F_rigid, at 10 already 46-79 %, at 1e6 1e-5
# to 1e-6 of the default's with exit 0 (bodies pass through each other: a converged but wrong
# answer). Hence no softer penalty than eps0 = 1: forces within 40 % of the rigid limit. Stiffer
# penalties give forces closer to it or a Newton failure (exit 1, one line: the grain assembly
# at eps0 <= 0.1, the grains at 1e-3); below 1e-4 Newton fails on every demo: refused.
# With the augmented Lagrangian eps0 sets only the Uzawa loop's speed: [1e-4, 1e4] (the
# parser's interval MPM_EPS0_INTERVAL; the penalty's narrower range is checked after parsing).
MPM_EPS0 = (1e-4, 1.0)
MPM_EPS0_AUGMENTED = (1e-4, 1e4)
MPM_EPS0_INTERVAL = "[1e-4, 1e4]"
MPM_EPS0_HELP = (
    "eq 51, eps = eps0 h / E_c. Penalty: in [1e-4, 1], smaller is stiffer, closer to rigid "
    "contact (forces at 1: 15-36 %% under the rigid limit); above 1 the bodies pass through "
    "each other, below 1e-4 Newton fails. Augmented: in [1e-4, 1e4], the loop's speed only"
)


def check_mpm_eps0(parser, args):
    """--eps0 within MPM_EPS0 with --enforcement penalty (parser.error, exit 2)."""
    if args.enforcement == "penalty" and not MPM_EPS0[0] <= args.eps0 <= MPM_EPS0[1]:
        parser.error(
            f"--eps0: must be in [{MPM_EPS0[0]:g}, {MPM_EPS0[1]:g}] with --enforcement penalty "
            f"(above 1 the bodies pass through each other; augmented takes up to 1e4), got "
            f"{args.eps0:g}"
        )


def add_enforcement(parser, choices=("penalty", "augmented")):
    """--enforcement: penalty (eqs 8, 12) or augmented Lagrangian (Uzawa, seed 003); a demo of
    the multi-step MPM offers MPM_ENFORCEMENT."""
    parser.add_argument(
        "--enforcement",
        choices=list(choices),
        default="penalty",
        help=(
            "contact enforcement: penalty (the answer depends on --eps0) or augmented "
            "(augmented Lagrangian, P1 multipliers along the contact: --eps0 sets only the "
            f"loop's speed, default {defaults.TUNING.augmented_eps0:g} with it)"
            if "augmented" in choices
            else "contact enforcement"
        ),
    )
    if "augmented" in choices:
        from dolfinx_forms.geometry.pairs import DEFAULT_MULTIPLIER_MASS, MULTIPLIER_MASSES

        parser.add_argument(
            "--multiplier-mass",
            choices=list(MULTIPLIER_MASSES),
            default=None,
            help=(
                "--enforcement augmented: Uzawa's projection of the point tractions on the P1 "
                "multipliers: hybrid (consistent on the nodes in contact, lumped at the edge: "
                "zero weighted gap in contact, the lumped pressure's edge), consistent (zero "
                "weighted mean gap at every node in contact, a coarser pressure) or lumped "
                f"(weighted gaps ~1e-3 h) (default: {DEFAULT_MULTIPLIER_MASS})"
            ),
        )


def add_linear_solver(parser):
    """--linear-solver: Newton's linear solver (dolfinx_forms/solvers/linear.py)."""
    parser.add_argument(
        "--linear-solver",
        choices=["auto", "condensed", "factorised", "iterative"],
        default="auto",
        help="Newton's linear solver: auto (by the problem), condensed (the bulk factorised "
        "once, Schur complement on the contact dofs), factorised (MUMPS LU per changed J) or "
        "iterative (CG/GMRES + GAMG with the rigid-body modes; --petsc options apply)",
    )


def add_cells(parser, quads, quads_help, triangles_help):
    """--quads / --triangles, mutually exclusive, into args.quads (default `quads`)."""
    cells = parser.add_mutually_exclusive_group()
    cells.add_argument("--quads", dest="quads", action="store_true", default=quads, help=quads_help)
    cells.add_argument("--triangles", dest="quads", action="store_false", help=triangles_help)


def add_discretization(parser):
    """--discretization and the cut path's --ghost-penalty (shared by every demo), checked by
    DemoParser.parse_args (check_discretization)."""
    parser._discretization = True
    parser.add_argument(
        "--discretization",
        choices=["conforming", "cut"],
        default="conforming",
        help="body-fitted gmsh meshes, or level sets cutting a structured grid",
    )
    parser.add_argument(
        "--ghost-penalty",
        type=bounded("--ghost-penalty", 0, None),
        default=0.01,
        help="cut path: ghost-penalty factor on the faces of cut cells (0: off)",
    )


def check_discretization(parser, args):
    """The cut path is vector Q1 on quadrilaterals."""
    if args.discretization == "cut" and getattr(args, "degree", 1) != 1:
        parser.error(f"--degree: the cut discretization supports degree 1 only, got {args.degree}")


def same_on_every_rank(parser, argv):
    """Under mpirun every rank parses its own command line: ranks given different ones would
    take different paths and wait for each other forever. Refused on every rank (exit 2)."""
    from mpi4py import MPI

    comm = MPI.COMM_WORLD
    if comm.size == 1:
        return
    lines = comm.allgather([str(a) for a in argv])
    other = next((r for r, line in enumerate(lines) if line != lines[0]), None)
    if other is not None:
        parser.error(
            f"the MPI ranks were given different command lines (rank 0: {' '.join(lines[0])!r}, "
            f"rank {other}: {' '.join(lines[other])!r})"
        )


def exit_process(status):
    """sys.exit(status) at the end of a program's __main__. gc.freeze() first: the interpreter's
    clean-up then skips its garbage collections over every object still alive (matplotlib's,
    dolfinx's: 0.1-0.2 s of each run); objects are still released, PETSc and MPI finalized."""
    gc.freeze()
    sys.exit(status)
