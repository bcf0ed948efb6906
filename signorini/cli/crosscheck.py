"""``signorini crosscheck``: one scene or problem file, several methods, every pair compared."""

from __future__ import annotations

import argparse

from signorini.cli.common import (EXIT_FAILED, OPT_METAVAR, SCENE_HELP, add_command, input_files,
                                  method_options, pairs, parse_tol, stdout_to_stderr,
                                  user_methods_in_workers, write_output)
from signorini.errors import InputError
from signorini.solvers.options import DEFAULT_TOL
from signorini.solvers.options import guess_value


def cmd_crosscheck(args: argparse.Namespace) -> int:
    from signorini.crosschecking import DEFAULT_METHODS, crosscheck  # per command (start-up)
    from signorini.files import STDOUT, all_or_none, check_outputs, to_json  # as above

    if args.json == args.md == STDOUT:
        raise InputError("--json - and --md - both ask for stdout: give one of them a file name")
    methods = args.method or list(DEFAULT_METHODS)
    outputs = check_outputs({"--json": args.json, "--md": args.md},
                            inputs=input_files(args.scene, methods))
    params = pairs(args.set, "--set")
    options = {name: {key: guess_value(value) for key, value in given.items()}
               for name, given in method_options(args.opt, args.method).items()}
    tol = parse_tol(args.tol) if args.tol is not None else None
    # what a method prints stays off the record; a user's method runs in a worker process
    with stdout_to_stderr(STDOUT in outputs.values()), user_methods_in_workers(methods):
        check = crosscheck(args.scene, methods, tol=DEFAULT_TOL if tol is None else tol,
                           params=params, options=options, allow=args.allow,
                           polish=args.polish)
    texts = {"--json": to_json(check.to_dict()) + "\n", "--md": check.markdown().rstrip("\n") + "\n"}
    with all_or_none():  # both files, or neither
        for flag, path in outputs.items():
            if path is not None:
                write_output(path, texts[flag])
    if STDOUT not in outputs.values():
        print(check.summary(verbose=args.verbose))
    return 0 if check.passed else EXIT_FAILED


def add_parsers(sub) -> None:
    """Register ``crosscheck``."""
    cross = add_command(
        sub, "crosscheck", "solve one scene with several methods and compare every pair",
        "Solve one scene or problem file with several methods at one tolerance and compare every "
        "pair of answers: λ and u (relative), nodes classified differently, each method's status "
        "and KKT certificate, its own (unpolished) answer's distance to pdas's and its active "
        "set, Hertz's errors.",
        ["signorini crosscheck hertz-cylinder",
         "signorini crosscheck my.npz --method pdas --method mine.py:solve --json check.json",
         "signorini crosscheck block --method pdas --method qp-osqp --opt qp-osqp:eps_abs=1e-10"],
        {0: "every method converged and every pair agrees",
         1: "a method did not converge, or two that say converged disagree (--allow lets a "
            "method through)"})
    cross.add_argument("scene", help=SCENE_HELP)
    cross.add_argument("--method", action="append", default=[], metavar="M",
                       help="a method to compare (repeat; default uzawa, qp-osqp, qp-clarabel, "
                            "cvxpy, pdas)")
    cross.add_argument("--tol", help="the relative KKT tolerance asked of every method "
                                     f"(default {DEFAULT_TOL:g})")
    cross.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       help="scene parameter, e.g. --set a_over_R=0.05")
    cross.add_argument("--opt", action="append", default=[], metavar=OPT_METAVAR,
                       help="an option of one method, e.g. --opt qp-osqp:eps_abs=1e-10 "
                            "(KEY=VALUE alone when one --method is named)")
    cross.add_argument("--allow", action="append", default=[], metavar="M",
                       help="a known-weak method whose failure or disagreement does not fail the "
                            "check (repeat)")
    cross.add_argument("--polish", action="store_true",
                       help="also polish each QP method's answer on its active set and show its "
                            "distance to pdas in an extra column (the judged answer stays the "
                            "method's own)")
    cross.add_argument("--json", metavar="FILE", help="write the record as JSON ('-' for stdout)")
    cross.add_argument("--md", metavar="FILE", help="write the tables as Markdown ('-' for stdout)")
    cross.set_defaults(run=cmd_crosscheck)


__all__ = ["cmd_crosscheck", "add_parsers"]
