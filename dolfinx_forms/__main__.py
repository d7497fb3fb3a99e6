"""Command line: run or check a scene description (see dolfinx_forms/app/scene_spec.py).

    python3 -m dolfinx_forms run SCENE.toml [--out DIR] [--force] [--set KEY=VALUE ...]
    python3 -m dolfinx_forms check SCENE.toml [--set KEY=VALUE ...]

`--set discretization.h=0.1` changes one value of the description (TOML syntax; arrays of
tables by index: `bodies[1].law.E=2e4`). Exit status: 0 done and every check passed; 1 a
failed check (the results are written, the reasons printed) or a solver failure (nothing
written); 2 a bad description, option or --out (one line naming the key, nothing written).
"""

import sys

from dolfinx_forms.app.cli import DemoParser, exit_process
from dolfinx_forms.app.scene_spec import SpecError
from dolfinx_forms.common import SolverChoiceError
from dolfinx_forms.io.folders import OutputFolderError

PROG = "python3 -m dolfinx_forms"


def parse(argv):
    p = DemoParser(prog=PROG, description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="command", required=True, parser_class=DemoParser)
    for name, what in (
        ("run", "run a scene and write its results"),
        ("check", "check a scene description without running it"),
    ):
        s = sub.add_parser(name, help=what, description=what)
        s.add_argument("scene", help="scene description (TOML)")
        s.add_argument(
            "--set",
            action="append",
            default=[],
            metavar="KEY=VALUE",
            help="change one value of the description (repeatable)",
        )
        if name == "run":
            s.add_argument("--out", default=None, help="result folder (default results/NAME)")
            s.add_argument(
                "--force",
                action="store_true",
                help="write into an existing folder that is not a result folder "
                "of this code (nothing there is deleted)",
            )
    return p, p.parse_args(argv)


def main(argv=None):
    parser, args = parse(sys.argv[1:] if argv is None else argv)
    from mpi4py import MPI

    rank0 = MPI.COMM_WORLD.rank == 0
    try:
        if args.command == "check":
            from dolfinx_forms.app.description import load

            spec = load(args.scene, args.set)
            if rank0:
                obstacles = f"{len(spec['obstacles'])} obstacles, " if "obstacles" in spec else ""
                print(
                    f"{args.scene}: {spec['name']}, {len(spec['bodies'])} bodies, {obstacles}"
                    f"{len(spec['stages'])} stages, {len(spec['checks'])} checks: ok"
                )
            return 0
        from dolfinx_forms.app import run
        from dolfinx_forms.solvers.newton import ContactSolverError

        try:
            result = run(
                args.scene,
                args.out,
                overrides=args.set,
                force=args.force,
                log=print if rank0 else (lambda *a, **k: None),
            )
        except ContactSolverError as e:
            if rank0:
                sys.stderr.write(f"{PROG}: {e}\n")
            return 1
    except (SpecError, OutputFolderError) as e:
        parser.error(str(e))
    except SolverChoiceError as e:  # found once the problem is built, on every rank alike
        parser.error(f"solver.linear_solver: {e}")
    if rank0:
        for line in result.failures:
            sys.stderr.write(f"{PROG}: {line}\n")
        print(f"results in {result.folder}")
    return 0 if result.passed else 1


if __name__ == "__main__":
    exit_process(main())
