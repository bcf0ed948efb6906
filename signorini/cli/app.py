"""The ``signorini`` command: a thin shell over the library.

Bad input gives a one-line message on stderr and exit code 2; a failed
validation exits 1. Each command lives in its own module of this package and
registers its parser there; this one parses, sets up logging and maps errors
to exit codes.
"""

from __future__ import annotations

import argparse
import logging
import os
import sys
from typing import Sequence

from signorini.cli import bench, crosscheck, listing, solve, studies
from signorini.cli.common import EXIT_FAILED, EXIT_USAGE, Parser
from signorini.errors import InputError, SignoriniError

COMMANDS = (solve, crosscheck, studies, bench, listing)


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="signorini", description="Frictionless contact as one QP, solved many ways.")
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress to stderr")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for module in COMMANDS:
        module.add_parsers(sub)
    return parser


def _check_distributed(args: argparse.Namespace, ranks: int) -> None:
    """Under mpirun only ``solve`` with a distributed (petsc-*) method makes sense."""
    from signorini.solvers.registry import get_method  # per command (start-up)

    if args.run is not solve.cmd_solve:
        raise InputError(f"under mpirun -n {ranks} only 'signorini solve' runs: run the other "
                         "commands without mpirun")
    if get_method(args.method).family != "petsc":
        raise InputError(f"under mpirun -n {ranks} only the petsc methods run distributed: give "
                         f"--method petsc-vi (or petsc-tron, petsc-gpcg), or run {args.method} "
                         "without mpirun")


def main(argv: Sequence[str] | None = None) -> int:
    from signorini.solvers import cluster  # per command (start-up)

    if cluster.launched_size() > 1:
        return _main_ranks(argv)
    return _main(argv)


def _main_ranks(argv: Sequence[str] | None) -> int:
    """Under ``mpirun -n N``: rank 0 runs the command, the other ranks serve its solves."""
    from signorini.solvers import cluster  # per command (start-up)

    try:
        if cluster.rank() != 0:
            return cluster.serve()
    except ImportError:
        print("signorini: error: started by mpirun but mpi4py is not installed: "
              "pip install 'signorini[petsc]' (see README, 'PETSc and MPI')", file=sys.stderr)
        return EXIT_USAGE
    try:
        return _main(argv, ranks=cluster.size())
    finally:
        cluster.release()


def _main(argv: Sequence[str] | None, ranks: int = 1) -> int:
    try:
        args = build_parser().parse_args(argv)
        logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                            format="%(levelname)s %(name)s: %(message)s")
        if ranks > 1:
            _check_distributed(args, ranks)
        return args.run(args)
    except InputError as exc:
        print(f"signorini: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except SignoriniError as exc:
        print(f"signorini: {type(exc).__name__}: {exc}", file=sys.stderr)
        return EXIT_FAILED
    except KeyboardInterrupt:
        print("signorini: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # e.g. piped into `head`: say so once, on stderr, and fail
        try:  # what is still buffered for the closed stdout must not raise again at exit
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError):
            pass
        print("signorini: error: standard output was closed before the output was written",
              file=sys.stderr)
        return EXIT_FAILED
