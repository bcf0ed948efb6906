"""The ``signorini`` command (``signorini.cli.app``): a thin shell over the library."""

from signorini.cli.app import build_parser, main, run

__all__ = ["build_parser", "main", "run"]
