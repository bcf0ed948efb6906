"""``signorini crosscheck``: one scene, several methods, every pair of answers compared."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from signorini.cli.common import EXIT_FAILED, option_value, pairs, parse_tol
from signorini.errors import InputError


def check_output(path: str | None, flag: str) -> None:
    """A result file ``flag`` can write, checked before anything is solved."""
    if path is None or path == "-":
        return
    target = Path(path)
    if target.is_dir():
        raise InputError(f"{flag} {path!r} is a directory: give a file name, "
                         f"e.g. {flag} {target / 'crosscheck'}{'.json' if 'json' in flag else '.md'}")
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(f"{flag} {path!r}: no directory {str(parent)!r}: create it first")
    if not os.access(parent, os.W_OK):
        raise InputError(f"{flag} {path!r}: directory {str(parent)!r} is not writable")


def method_options(items: list[str]) -> dict[str, dict]:
    """``METHOD:key=value`` strings (``--opt qp-osqp:polish=false``) to per-method options."""
    out: dict[str, dict] = {}
    for item in items:
        method, sep, setting = item.rpartition(":")
        if not sep or not method or "=" not in setting:
            raise InputError(f"--opt {item!r} is not METHOD:key=value: write e.g. "
                             "--opt qp-osqp:polish=false")
        for key, value in pairs([setting], "--opt").items():
            out.setdefault(method, {})[key] = option_value(value)
    return out


def cmd_crosscheck(args: argparse.Namespace) -> int:
    from signorini.crosschecking import DEFAULT_METHODS, DEFAULT_TOL, crosscheck  # per command (start-up)
    from signorini.files import atomic_write_text, to_json  # per command (start-up)

    check_output(args.json, "--json")
    check_output(args.md, "--md")
    if args.json == "-" and args.md == "-":
        raise InputError("--json - and --md - both ask for stdout: give one of them a file name")
    params = pairs(args.set, "--set")
    tol = parse_tol(args.tol) if args.tol is not None else None
    methods = args.method or list(DEFAULT_METHODS)
    check = crosscheck(args.scene, methods, tol=DEFAULT_TOL if tol is None else tol, params=params,
                       options=method_options(args.opt))
    record = check.to_dict()
    if args.json == "-":
        print(to_json(record))
    elif args.json:
        atomic_write_text(args.json, to_json(record) + "\n")
    if args.md == "-":
        print(check.markdown())
    elif args.md:
        atomic_write_text(args.md, check.markdown())
    if "-" not in (args.json, args.md):
        print(check.summary())
    return 0 if check.passed else EXIT_FAILED


def add_parsers(sub) -> None:
    """Register ``crosscheck``."""
    cross = sub.add_parser(
        "crosscheck", help="solve one scene with several methods and compare every pair",
        description="Solve one scene with several methods at one tolerance and compare every pair "
                    "of answers: λ and u (relative), nodes classified differently, each method's "
                    "status and KKT certificate, Hertz's errors. Exit 1 when two methods that say "
                    "converged disagree.")
    cross.add_argument("scene", help="scene name (see 'signorini scenes') or a .toml scene file")
    cross.add_argument("--method", action="append", default=[], metavar="M",
                       help="a method to compare (repeat; default uzawa, qp-osqp, qp-clarabel, "
                            "cvxpy, pdas)")
    cross.add_argument("--tol", help="the relative KKT tolerance asked of every method (default 1e-8)")
    cross.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       help="scene parameter, e.g. --set a_over_R=0.05")
    cross.add_argument("--opt", action="append", default=[], metavar="METHOD:KEY=VALUE",
                       help="an option of one method, e.g. --opt qp-osqp:polish=false")
    cross.add_argument("--json", metavar="FILE", help="write the record as JSON ('-' for stdout)")
    cross.add_argument("--md", metavar="FILE", help="write the tables as Markdown ('-' for stdout)")
    cross.set_defaults(run=cmd_crosscheck)
