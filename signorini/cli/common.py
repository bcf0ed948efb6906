"""What every command shares: the parser that fails in one line, ``key=value`` pairs, exits."""

from __future__ import annotations

import argparse
import sys
from typing import Any, Sequence

from signorini.errors import InputError

EXIT_FAILED, EXIT_USAGE = 1, 2


class Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line and exit 2, like every other bad input
        raise InputError(f"{message} (see 'signorini {self.prog.split()[-1]} --help')"
                         if " " in self.prog else f"{message} (see 'signorini --help')")


def pairs(items: Sequence[str], flag: str) -> dict[str, Any]:
    """``key=value`` strings to a dict; values parsed as int, float, bool or left as text."""
    out: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise InputError(f"{flag} {item!r} is not key=value: write {flag} name=value")
        out[key.strip()] = value.strip()
    return out


def option_value(text: str) -> Any:
    lowered = text.lower()
    if lowered in ("true", "false"):
        return lowered == "true"
    if lowered in ("none", "null"):
        return None
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def parse_tol(text: str) -> float:
    from signorini.solvers.base import check_tol  # per command (start-up)

    try:
        value = float(text)
    except ValueError:
        raise InputError(f"--tol {text!r} is not a number: give e.g. --tol 1e-9") from None
    return check_tol(value, "--tol")  # the API's rule, said about the option


def parse_time_limit(text: str | None, flag: str = "--time-limit") -> float | None:
    """Seconds as a finite positive float (None stays None), or InputError naming ``flag``."""
    if text is None:
        return None
    try:
        seconds = float(text)
    except ValueError:
        seconds = float("nan")
    if not (seconds > 0 and seconds != float("inf")):
        raise InputError(f"{flag} {text!r} must be a positive number of seconds, e.g. {flag} 30")
    return seconds


def write_json(path: str, text: str) -> None:
    from signorini.files import atomic_write_text  # per command (start-up)

    if path == "-":
        sys.stdout.write(text + "\n")
    else:
        atomic_write_text(path, text + "\n")


def parse_sizes(text: str) -> list[int]:
    try:
        return [int(x) for x in text.split(",")]
    except ValueError:
        raise InputError(f"--sizes {text!r} is not a comma-separated list of sizes, "
                         "e.g. --sizes 0,1,2") from None
