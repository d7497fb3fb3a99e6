"""Command-line contract shared by all demos (see docs/benchmarks.md in shared docs).

A bad value stops the run with ONE line naming the parameter and the accepted range,
exit status 2, before anything is written.
"""

import argparse
import math
import sys


class DemoParser(argparse.ArgumentParser):
    """argparse with one-line errors (argparse prints usage + error by default)."""

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
        bad = (not math.isfinite(x)
               or (lo is not None and (x <= lo if lo_open else x < lo))
               or (hi is not None and (x >= hi if hi_open else x > hi)))
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
    parser.add_argument("--discretization", choices=["conforming", "cut"], default="conforming",
                        help="body-fitted gmsh meshes, or level sets cutting a structured grid")
    parser.add_argument("--ghost-penalty", type=bounded("--ghost-penalty", 0, None), default=0.01,
                        help="cut path: ghost-penalty factor on the faces of cut cells (0: off)")


def check_discretization(parser, args):
    """The cut path is vector Q1 on quadrilaterals."""
    if args.discretization == "cut" and getattr(args, "degree", 1) != 1:
        parser.error(f"--degree: the cut discretization supports degree 1 only, got {args.degree}")
