"""The listings: ``signorini scenes`` and ``signorini methods``."""

from __future__ import annotations

import argparse

from signorini.cli.common import add_command


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
    add_command(sub, "scenes", "list the scenes and their parameters",
                "List the built-in scenes, each with its parameters, their defaults and meaning; "
                "a command takes them as --set KEY=VALUE, a scene file as keys.",
                ["signorini scenes",
                 "signorini solve hertz-cylinder --set n_contact=60 --set grading=0.1"],
                {0: "listed"}).set_defaults(run=cmd_scenes)
    add_command(sub, "methods", "list the methods and whether they are installed",
                "List the methods, whether each is installed (with the pip command that installs "
                "it when not) and what it is, and the factorisation backend in use.",
                ["signorini methods", "SIGNORINI_FACTOR=superlu signorini methods"],
                {0: "listed"}).set_defaults(run=cmd_methods)


__all__ = ["cmd_scenes", "cmd_methods", "add_parsers"]
