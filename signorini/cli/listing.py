"""The listings: ``signorini scenes`` and ``signorini methods``."""

from __future__ import annotations

import argparse


def cmd_scenes(args: argparse.Namespace) -> int:
    from signorini.scenes import SCENES  # per command (start-up)

    for family in SCENES.values():
        print(f"{family.name}: {family.summary}")
        for p in family.params:
            default = "—" if p.default is None else p.default
            print(f"    {p.name:<11} {str(default):<8} {p.doc}")
    return 0


def cmd_methods(args: argparse.Namespace) -> int:
    from signorini.numerics.factor import available_backends, resolve_backend  # per command (start-up)
    from signorini.solvers.registry import methods  # per command (start-up)

    print(f"factorisation backend: {resolve_backend()} (installed: {', '.join(available_backends())}; "
          "set SIGNORINI_FACTOR to choose)")
    for m in methods():
        state = "installed" if m.installed else f"not installed ({m.install_hint})"
        kind = ", ".join(x for x in ("exact" if m.exact else "", "dense" if m.dense else "",
                                     "one row per dof: one body" if m.bound_rows else "") if x)
        print(f"{m.name:<14} {state:<12} {m.summary}" + (f" [{kind}]" if kind else ""))
    return 0


def add_parsers(sub) -> None:
    """Register the listings."""
    sub.add_parser("scenes", help="list the scenes and their parameters").set_defaults(run=cmd_scenes)
    sub.add_parser("methods", help="list the methods and whether they are installed").set_defaults(
        run=cmd_methods)
