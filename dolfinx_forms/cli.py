"""Command-line contract shared by all demos (see docs/benchmarks.md in shared docs).

A bad value stops the run with ONE line naming the parameter and the accepted range,
exit status 2, before anything is written (on every MPI rank: every rank parses).
`--help` shows each option's default. Every program has `--verbose` (the JIT compiler's log
lines, also ILS_VERBOSE=1); programs that write a result folder declare it with
:meth:`DemoParser.add_out`, which adds `--out` and `--force` and checks the folder while
parsing (rules: folders.py), so a run never computes and then refuses its output folder.
"""

import argparse
import copy
import math
import sys

from .folders import OutputFolderError, check_output_path
from .logs import set_verbose

FORCE_HELP = (
    "write into an existing folder that is not a result folder of this code, adding "
    "the results next to its content (nothing there is deleted or overwritten)"
)


class DefaultsFormatter(argparse.HelpFormatter):
    """Help text with each option's default (options that take a value and have one)."""

    @staticmethod
    def _shows_default(action):
        return (
            bool(action.option_strings)
            and action.nargs != 0
            and action.default not in (None, [], argparse.SUPPRESS, "")
        )

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
    --help, --verbose, and the result-folder options of :meth:`add_out`."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", DefaultsFormatter)
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
        a = super().parse_args(args, namespace)
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
        return f"{left}{'-inf' if lo is None else lo}, {'inf' if hi is None else hi}{')' if hi is None else right}"

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


def petsc_options(parser, items):
    """Parse repeated --petsc KEY=VALUE into a dict (keys without the leading dash)."""
    opts = {}
    for item in items:
        key, sep, value = item.partition("=")
        key = key.lstrip("-")
        if not sep or not key:
            parser.error(f"--petsc: expected KEY=VALUE, got {item!r}")
        opts[key] = value
    return opts


def add_discretization(parser):
    """--discretization and the cut path's --ghost-penalty (shared by every demo)."""
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
