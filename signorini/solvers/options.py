"""Checking the options a method is given."""

from __future__ import annotations

from typing import Any

from signorini.errors import InputError


def take_options(method: str, given: dict[str, Any], defaults: dict[str, Any]) -> dict[str, Any]:
    """``defaults`` overridden by ``given``; an unknown name raises InputError listing the known."""
    unknown = sorted(set(given) - set(defaults))
    if unknown:
        known = ", ".join(sorted(defaults)) or "none"
        raise InputError(f"method {method!r} has no option {unknown[0]!r}: --opt takes {known}")
    return {**defaults, **given}


def positive_number(method: str, name: str, value: Any) -> float:
    """``value`` as a finite positive float, or InputError naming the option."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = float("nan")
    if not number > 0 or number == float("inf"):
        raise InputError(f"method {method!r}: option {name}={value!r} must be a positive number")
    return number
