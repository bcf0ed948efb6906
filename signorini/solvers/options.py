"""Method options, declared with their types and ranges and checked before any work.

A method declares each option it takes as an :class:`Option` (a kind, a default, the allowed
choices); :func:`take_options` fills the defaults and checks every value given, so that a bad
value or an unknown name is an :class:`InputError` naming the option and the fix, never a
``failed`` run. Options whose default is None accept None ("the method decides").

The defaults of ``tol`` and ``max_iter`` are one table, :data:`TABLE`, one row per method (or
family) with its reason (:func:`defaults_of`). ``tol`` is the relative KKT residual the
certificate accepts (:mod:`signorini.certification.kkt`); None leaves a QP backend at its own
settings, its answer then held to :data:`DEFAULT_TOL`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from signorini.errors import InputError

KINDS = ("positive", "nonnegative", "fraction", "number", "integer", "count", "positive_count", "bool",
         "choice", "text", "callable", "vector", "object", "any")

_SAY = {"positive": "a positive number", "nonnegative": "a number ≥ 0",
        "fraction": "a number in (0, 1]", "number": "a finite number", "integer": "an integer",
        "count": "an integer ≥ 0", "positive_count": "an integer ≥ 1",
        "bool": "true or false", "text": "a string", "callable": "a function (Python API only)",
        "vector": "an array of finite floats, one per contact candidate (Python API only)"}

_EXAMPLE = {"positive": "1e-6", "nonnegative": "0", "fraction": "0.5", "number": "0",
            "integer": "0", "count": "10", "positive_count": "100", "bool": "true", "text": "name"}


@dataclass(frozen=True)
class Option:
    """One option of a method: its name, kind (:data:`KINDS`), default and allowed values.

    ``in_units`` marks an option whose value is in the problem's units (a step, a starting λ, a
    callback that reads the iterates): a method given one runs on the problem as given, not on
    a scaled view of it.
    """

    name: str
    kind: str
    default: Any = None
    choices: tuple[Any, ...] = ()
    types: tuple[type, ...] = ()
    in_units: bool = False

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"option {self.name}: unknown kind {self.kind!r}")

    def expected(self) -> str:
        """What the option takes, in words."""
        if self.kind == "choice":
            return "one of " + ", ".join(str(c) for c in self.choices if c is not None)
        if self.kind == "object":
            return "a " + " or ".join(t.__name__ for t in self.types)
        return _SAY.get(self.kind, "anything")

    def check(self, method: str, value: Any) -> Any:
        """``value`` converted to the option's kind, or InputError naming the option and the fix."""
        if value is None and (self.default is None or self.kind == "any"):
            return None
        checked = _convert(self, value)
        if checked is _BAD:
            self.refuse(method, value)
        return checked

    def refuse(self, method: str, value: Any, typed: bool = False) -> None:
        """Raise the InputError that says what ``value`` (the text of ``--opt`` when ``typed``)
        should have been."""
        shown = value if typed and type(guess_value(value)) in (int, float) else repr(value)
        if self.kind == "choice":
            raise InputError(f"method {method!r}: option {self.name}={shown} is not one of "
                             f"{', '.join(str(c) for c in self.choices if c is not None)}")
        example = _EXAMPLE.get(self.kind)
        if example and "time" in self.name.lower():
            example = "60"
        elif self.default is not None and not isinstance(self.default, bool) and example:
            example = f"{self.default:g}" if isinstance(self.default, float) else str(self.default)
        hint = f", e.g. {self.name}={example}" if example is not None else ""
        raise InputError(f"method {method!r}: option {self.name}={shown} must be "
                         f"{self.expected()}{hint}")

    def parse(self, method: str, text: str) -> Any:
        """The value of ``--opt name=text``, read as the option's kind and checked."""
        kind, word = self.kind, text.lower()
        if word in ("none", "null") and (self.default is None or kind == "any") \
                and text not in self.choices:
            return None
        if kind == "any":
            return guess_value(text)
        if kind == "text":
            return text
        value = _BAD  # a function, an array or an object: the Python API only
        if kind == "choice":
            value = next((c for c in self.choices if c is not None and str(c) == text), _BAD)
        elif kind == "bool":
            value = {"true": True, "1": True, "yes": True, "false": False, "0": False,
                     "no": False}.get(word, _BAD)
        elif kind in _NUMBERS or kind in _INTEGERS:
            try:
                value = _convert(self, float(text))
            except ValueError:
                pass
        if value is _BAD:
            self.refuse(method, text, typed=True)
        return value


_BAD = object()


def finite_number(value: Any) -> float | None:
    """``value`` as a float when it is a finite real number (not a bool), else None."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer,
                                                                      np.floating)):
        return None
    number = float(value)
    return number if math.isfinite(number) else None


#: the test of each numeric kind, and the least value of each integer kind
_NUMBERS = {"positive": lambda x: x > 0, "nonnegative": lambda x: x >= 0,
            "fraction": lambda x: 0 < x <= 1, "number": lambda x: True}
_INTEGERS = {"integer": -math.inf, "count": 0, "positive_count": 1}


def _convert(option: Option, value: Any) -> Any:
    kind = option.kind
    number = finite_number(value)
    if kind in _NUMBERS:
        return number if number is not None and _NUMBERS[kind](number) else _BAD
    if kind in _INTEGERS:
        ok = number is not None and number.is_integer() and number >= _INTEGERS[kind]
        return int(number) if ok else _BAD
    if kind == "bool":
        ok = isinstance(value, (bool, np.bool_)) or isinstance(value, (int, np.integer)) and value in (0, 1)
        return bool(value) if ok else _BAD
    if kind == "vector":
        try:
            array = None if isinstance(value, (str, bytes)) else np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            array = None
        return array if array is not None and array.ndim == 1 and np.all(np.isfinite(array)) else _BAD
    return value if _KEPT[kind](option, value) else _BAD


#: the test of each kind whose value is kept as given
_KEPT = {"any": lambda option, value: True,
         "choice": lambda option, value: any(value == c and type(value) is type(c)
                                             for c in option.choices),
         "text": lambda option, value: isinstance(value, str),
         "callable": lambda option, value: callable(value),
         "object": lambda option, value: isinstance(value, option.types)}


def declare(*options: Option) -> dict[str, Option]:
    """The options of one method, by name (what :func:`take_options` takes)."""
    return {option.name: option for option in options}


def check_names(method: str, given: Mapping[str, Any], known: Any) -> None:
    """InputError for the first name in ``given`` that is not in ``known``, listing the known."""
    unknown = sorted(set(given) - set(known))
    if unknown:
        listed = ", ".join(sorted(known)) or "none"
        raise InputError(f"method {method!r} has no option {unknown[0]!r}; accepted options: {listed}")


def checked(method: str, given: Mapping[str, Any], declared: Mapping[str, Option]) -> dict[str, Any]:
    """``given``, every value checked and converted by its ``declared`` option; InputError for
    an unknown name or a bad value."""
    check_names(method, given, declared)
    return {name: declared[name].check(method, value) for name, value in given.items()}


def take_options(method: str, given: Mapping[str, Any], declared: Mapping[str, Option]) -> dict[str, Any]:
    """Every ``declared`` option: its value in ``given``, checked and converted, else its default."""
    return {**{name: option.default for name, option in declared.items()},
            **checked(method, given, declared)}


def per_candidate(method: str, name: str, vector: Any, m: int) -> Any:
    """The option ``name`` (a vector, or None) when it has one entry per contact candidate."""
    if vector is not None and np.shape(vector) != (m,):
        raise InputError(f"method {method!r}: option {name} has {np.size(vector)} entries, the "
                         f"problem {m} contact candidates")
    return vector


def guess_value(text: str) -> Any:
    """An undeclared option's text as a bool, None, int or float, else left as text."""
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


# -- the defaults of tol and max_iter ------------------------------------------------------
#: the package's default relative KKT tolerance: what :func:`signorini.crosscheck` asks every
#: method for, what a user's method is handed when nobody names one, and what an answer is
#: held to when neither the caller nor its method names one (a QP backend at its own settings)
DEFAULT_TOL = 1e-8
#: what an exact method (its answer exact up to round-off once its active set is found) is held
#: to: one digit tighter than an iterative method is asked for
EXACT_TOL = 1e-9

#: relative KKT residuals cannot be certified below a few hundred times double precision's ε:
#: the smallest tol a method may be asked for
MIN_TOL = 1e-14


@dataclass(frozen=True)
class Defaults:
    """A method's default ``tol`` and ``max_iter`` (None: its backend's own), and why."""

    tol: float | None
    max_iter: int | None
    reason: str


#: one row per method, or per family where its methods share one (read only)
TABLE: Mapping[str, Defaults] = MappingProxyType({
    "pdas": Defaults(EXACT_TOL, 100, "exact once its active set repeats, a few Newton steps; "
                                     "100 means a cycle or a degenerate set"),
    "nested": Defaults(EXACT_TOL, 100, "exact on the predicted zone; its fallback is pdas's"),
    "condensed": Defaults(EXACT_TOL, 200, "an exact dense LCP, a few active-set steps"),
    "pdas-amg": Defaults(EXACT_TOL, 50, "Newton steps on the active set with CG solves driven "
                                        "below tol; a predicted set needs a few"),
    "auto": Defaults(EXACT_TOL, None, "picks an exact method, which has its own limit"),
    "dual": Defaults(DEFAULT_TOL, 50_000, "projected gradient on the dual converges linearly, "
                                          "slowly when W is ill-conditioned: 1e-8 in its budget"),
    "petsc-vi": Defaults(EXACT_TOL, 200, "semismooth Newton (SNES-VI): exact once its active "
                                         "set settles"),
    "petsc": Defaults(EXACT_TOL, 2000, "bound-constrained TAO solvers: many cheap steps, each "
                                       "stopped below tol by PETSc's own test"),
    "qp": Defaults(None, None, "the backend's own settings (what a user of it gets); its "
                               "answer is held to DEFAULT_TOL"),
    "cvxpy": Defaults(None, None, "the chosen solver's own settings; held to DEFAULT_TOL"),
    "user": Defaults(DEFAULT_TOL, 1000, "the package's default tolerance, and a limit a user's "
                                        "method may read or ignore"),
})


def defaults_of(name: str, family: str) -> Defaults:
    """The row of the method ``name`` (of ``family``): its own, else its family's."""
    return TABLE.get(name) or TABLE.get(family) or TABLE["user"]


def resolved(name: str, family: str, tol: float | None,
             max_iter: int | None) -> tuple[float | None, int | None]:
    """``(tol, max_iter)`` as asked, each one not asked for taken from the method's row."""
    row = defaults_of(name, family)
    return (row.tol if tol is None else tol,
            row.max_iter if max_iter is None else int(max_iter))


__all__ = ["DEFAULT_TOL", "EXACT_TOL", "KINDS", "MIN_TOL", "Defaults", "Option", "TABLE", "check_names",
           "checked", "declare", "defaults_of", "finite_number", "guess_value", "per_candidate",
           "resolved", "take_options"]
