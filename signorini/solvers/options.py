"""Method options, declared with their types and ranges and checked before any work.

A method declares each option it takes as an :class:`Option` (a kind, a
default, the allowed choices); :func:`take_options` fills the defaults and
checks every value given, so that a string where a number belongs, a
negative time limit or an unknown name is an :class:`InputError` naming the
option and what to give instead — never a ``failed`` run of the solver.

Kinds: ``positive`` (finite float > 0), ``nonnegative`` (finite float ≥ 0),
``fraction`` (float in (0, 1]), ``number`` (any finite float), ``integer``
(any sign), ``count``
(integer ≥ 0), ``positive_count`` (integer ≥ 1), ``bool``, ``choice`` (one
of ``choices``), ``text`` (a string), ``callable``, ``vector`` (an array of
finite floats; its length is checked by the method, which knows m),
``object`` (an instance of ``types``) and ``any`` (passed on unchecked).
Options whose default is None accept None ("the method decides").

The two options every method takes, ``tol`` and ``max_iter``, have their defaults in one
table, :data:`TABLE`, one row per method (or per family) with its reason. A method asked for
no ``tol`` runs at its row's ``tol`` and its answer is held to it; asked for no ``max_iter``,
it stops after its row's ``max_iter`` steps. A row is found by the method's name, else by its
family (:func:`defaults_of`). ``tol`` is the relative KKT residual the certificate accepts
(:mod:`signorini.certification.kkt`); None leaves a QP backend at its own settings, its answer
then held to :data:`DEFAULT_TOL`.
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

    def refuse(self, method: str, value: Any) -> None:
        """Raise the InputError that says what ``value`` should have been."""
        shown = value.shown() if isinstance(value, _Typed) else repr(value)
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
        kind, typed = self.kind, _Typed(text)
        if text.lower() in ("none", "null") and (self.default is None or kind == "any") \
                and not (kind == "choice" and text in self.choices):
            return None
        if kind in ("callable", "vector", "object"):
            self.refuse(method, typed)
        if kind == "choice":
            for choice in self.choices:
                if choice is not None and str(choice) == text:
                    return choice
            self.refuse(method, typed)
        if kind == "bool":
            word = text.lower()
            if word not in ("true", "false", "1", "0", "yes", "no"):
                self.refuse(method, typed)
            return word in ("true", "1", "yes")
        if kind in ("text",):
            return text
        if kind == "any":
            return guess_value(text)
        try:
            checked = _convert(self, float(text))
        except ValueError:
            checked = _BAD
        if checked is _BAD:
            self.refuse(method, typed)
        return checked


_BAD = object()


@dataclass(frozen=True)
class _Typed:
    """The text a user typed after ``--opt name=``, shown as typed in messages."""

    text: str

    def shown(self) -> str:
        """A number as typed (``-1``), anything else quoted (``'abc'``)."""
        try:
            float(self.text)
        except ValueError:
            return repr(self.text)
        return self.text


def _number(value: Any) -> float | None:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer,
                                                                      np.floating)):
        return None
    number = float(value)
    return number if math.isfinite(number) else None


def _convert(option: Option, value: Any) -> Any:
    kind = option.kind
    if kind == "any":
        return value
    if kind in ("positive", "nonnegative", "fraction", "number"):
        number = _number(value)
        ok = number is not None and {"positive": lambda x: x > 0,
                                     "nonnegative": lambda x: x >= 0,
                                     "fraction": lambda x: 0 < x <= 1,
                                     "number": lambda x: True}[kind](number)
        return number if ok else _BAD
    if kind in ("integer", "count", "positive_count"):
        number = _number(value)
        least = {"integer": -math.inf, "count": 0, "positive_count": 1}[kind]
        if number is None or not number.is_integer() or number < least:
            return _BAD
        return int(number)
    if kind == "bool":
        if isinstance(value, (bool, np.bool_)):
            return bool(value)
        return bool(value) if isinstance(value, (int, np.integer)) and value in (0, 1) else _BAD
    if kind == "choice":
        return value if any(value == c and type(value) is type(c) for c in option.choices) else _BAD
    if kind == "text":
        return value if isinstance(value, str) else _BAD
    if kind == "callable":
        return value if callable(value) else _BAD
    if kind == "vector":
        if isinstance(value, (str, bytes)):
            return _BAD
        try:
            array = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            return _BAD
        return array if array.ndim == 1 and np.all(np.isfinite(array)) else _BAD
    if kind == "object":
        return value if isinstance(value, option.types) else _BAD
    return _BAD  # pragma: no cover - kinds are checked when an Option is made


def declare(*options: Option) -> dict[str, Option]:
    """The options of one method, by name (what :func:`take_options` takes)."""
    return {option.name: option for option in options}


def check_names(method: str, given: Mapping[str, Any], known: Any) -> None:
    """InputError for the first name in ``given`` that is not in ``known``, listing the known."""
    unknown = sorted(set(given) - set(known))
    if unknown:
        listed = ", ".join(sorted(known)) or "none"
        raise InputError(f"method {method!r} has no option {unknown[0]!r}; accepted options: {listed}")


def take_options(method: str, given: Mapping[str, Any], defaults: Mapping[str, Any]) -> dict[str, Any]:
    """``defaults`` overridden by ``given``, every given value checked.

    ``defaults`` maps each name to an :class:`Option` (its value checked and
    converted) or to a plain default value (passed on as given).
    """
    check_names(method, given, defaults)
    out: dict[str, Any] = {}
    for name, declared in defaults.items():
        if isinstance(declared, Option):
            out[name] = declared.check(method, given[name]) if name in given else declared.default
        else:
            out[name] = given.get(name, declared)
    return out


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


def positive_number(method: str, name: str, value: Any) -> float:
    """``value`` as a finite positive float, or InputError naming the option."""
    return Option(name, "positive", 1.0).check(method, value)


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
           "declare", "defaults_of", "guess_value", "positive_number", "resolved", "take_options"]
