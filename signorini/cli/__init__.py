"""The ``signorini`` command (``signorini.cli.app``): a thin shell over the library."""

from signorini.cli.app import build_parser, main

__all__ = ["build_parser", "main"]
