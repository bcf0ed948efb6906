"""What a method is, and how its claim of success is judged.

A method is a plain function ``solve(problem, *, tol=None, max_iter=None,
**options) -> ContactSolution`` described by a :class:`Method`. Backends
define their methods here-shaped (a ``METHODS`` tuple per backend module);
:mod:`signorini.solvers.registry` collects them. A method's own claim of
success becomes ``converged`` only when the KKT certificate backs it
(:func:`judge`).
"""

from __future__ import annotations

import dataclasses
import hashlib
import importlib.util
import math
from dataclasses import dataclass, field
from numbers import Real
from typing import Any, Callable, Mapping

import numpy as np
import scipy.sparse as sp

from signorini.certification.adequacy import adequacy, warnings
from signorini.certification.diagnosis import explain
from signorini.errors import InputError, install_hint
from signorini.certification.kkt import Certificate, certificate, shortfall
from signorini.problem.contact import STATUSES, ContactProblem, ContactSolution
from signorini.solvers.options import (DEFAULT_TOL, MIN_TOL, Defaults, Option, check_names,
                                       checked, defaults_of, finite_number, guess_value, resolved)

SolverFunction = Callable[..., ContactSolution]

#: a claim of success is accepted when every relative KKT residual is at most
#: ``ACCEPT_FACTOR × tol`` (:func:`acceptance`): success means what qpbenchmark means by it,
#: the residuals under the tolerance
ACCEPT_FACTOR = 1.0


def acceptance(tol: float | None) -> float:
    """The largest relative KKT residual accepted of an answer asked for ``tol`` (None:
    :data:`DEFAULT_TOL`)."""
    return ACCEPT_FACTOR * (DEFAULT_TOL if tol is None else tol)


@dataclass(frozen=True)
class Method:
    """A registered method.

    ``requires`` lists the Python modules it imports and ``extra`` the pip extra that installs
    them. ``dense`` methods build dense matrices; ``exact`` ones reach the answer up to
    round-off when they converge. ``typed_options`` declares the options it takes, their kinds
    and ranges (:class:`~signorini.solvers.options.Option`: :meth:`check_options` refuses a
    bad value before any work); :attr:`defaults` is its row of
    :data:`~signorini.solvers.options.TABLE`, the ``tol`` and ``max_iter`` it runs at when none
    is asked for.

    What it offers load control, which asks and never branches on a name:
    ``matches_load(problem)``, that it matches that problem's pending target load itself (the
    push as a bordered unknown); ``prediction``, the kind of prediction of the contact it takes
    from the scene (``"zone"``: the option ``zone``; ``"active set"``: ``active0``, and
    ``push0`` for a pending load); ``warm_from_load``, that it takes load control's answer as
    its warm start. ``chooses(problem, options, warm_start)`` returns the method it runs
    instead (:meth:`runs`). A ``scaled`` method is handed a view of the problem in units of
    order one, its answer mapped back before it is judged; not said, a method of a ``family``
    is scaled and one without (a user's) is handed the problem in the user's units. A
    ``bound_rows`` method takes each contact row as a bound on dofs of its own and refuses rows
    that share a dof (:meth:`check_rows`). ``factor_free_from`` is the size (dofs) from which it solves a 3D
    model with a target load without a factorisation (None: never), for a scene's memory
    estimate (:mod:`signorini.scenes.size`).
    """

    name: str
    function: SolverFunction
    summary: str
    requires: tuple[str, ...] = ()
    extra: str = ""
    dense: bool = False
    exact: bool = False
    family: str = ""
    typed_options: Mapping[str, Option] = field(default_factory=dict)
    matches_load: Callable[[ContactProblem], bool] | None = None
    prediction: str = ""
    warm_from_load: bool = False
    chooses: Callable[..., "Method"] | None = None
    scaled: bool | None = None
    bound_rows: bool = False
    factor_free_from: float | None = None

    def __post_init__(self) -> None:
        if self.scaled is None:  # a user's method without a family gets the problem as given
            object.__setattr__(self, "scaled", self.family not in ("", "user"))

    @property
    def options(self) -> tuple[str, ...]:
        """The names of the options it takes."""
        return tuple(self.typed_options)

    @property
    def defaults(self) -> Defaults:
        """Its default tolerance and iteration limit, and why."""
        return defaults_of(self.name, self.family)

    @property
    def default_tol(self) -> float | None:
        return self.defaults.tol

    def defaults_for(self, tol: float | None, max_iter: int | None) -> tuple[float | None, int | None]:
        """``(tol, max_iter)`` as asked, each one not asked for from its :attr:`defaults`."""
        return resolved(self.name, self.family, tol, max_iter)

    @property
    def installed(self) -> bool:
        return all(importlib.util.find_spec(mod) is not None for mod in self.requires)

    @property
    def install_hint(self) -> str:
        """The pip command that installs the modules it misses (its extra, or the modules')."""
        missing = [mod for mod in self.requires if importlib.util.find_spec(mod) is None]
        return install_hint(self.extra, missing or self.requires)

    def runs(self, problem: ContactProblem, options: Mapping[str, Any] | None = None,
             warm_start: Any = None) -> "Method":
        """The method that runs on ``problem``: this one, or the one it chooses."""
        return self if self.chooses is None else self.chooses(problem, options or {}, warm_start)

    def check_rows(self, problem: ContactProblem) -> None:
        """InputError when this method takes the rows as bounds and ``problem``'s share a dof."""
        if self.bound_rows and rows_share_dofs(problem.N):
            raise InputError(f"method {self.name!r} takes each contact row as a bound on dofs of "
                             "its own, and this problem's rows share dofs (two bodies, or "
                             "obstacles that meet): use pdas, nested, condensed or a qp-* method")

    def matches(self, problem: ContactProblem) -> bool:
        """It matches ``problem``'s pending target load itself (see ``matches_load``)."""
        return self.matches_load is not None and bool(self.matches_load(problem))

    def check_options(self, given: Mapping[str, Any]) -> dict[str, Any]:
        """``given`` with every declared option checked and converted; InputError otherwise (a
        user's method declares none and takes what its function takes)."""
        return dict(given) if self.family == "user" else checked(self.name, given, self.typed_options)

    def parse_options(self, texts: Mapping[str, str]) -> dict[str, Any]:
        """``--opt name=text`` pairs read as each option's declared kind, and checked."""
        if self.family == "user":
            return {name: guess_value(text) for name, text in texts.items()}
        check_names(self.name, texts, self.typed_options)
        return {name: self.typed_options[name].parse(self.name, text) for name, text in texts.items()}


def rows_share_dofs(N: Any) -> bool:
    """Two rows of the constraint matrix N have a nonzero on one dof."""
    columns = sp.csc_matrix(N, copy=True)
    columns.eliminate_zeros()
    return bool(np.any(np.diff(columns.indptr) > 1))


def check_tol(tol: Any, name: str = "tol") -> float | None:
    """``tol`` as a float, or InputError naming ``name`` (the API's argument or the CLI's option)."""
    if tol is None:
        return None
    number = finite_number(tol)
    if number is None or not 0 < number < 1:
        raise InputError(f"{name} must be a number in (0, 1), got {tol!r}: e.g. {name} 1e-9")
    if number < MIN_TOL:
        raise InputError(f"{name} {tol:g} is below what double precision can certify (relative "
                         f"residuals of order 1e-16 times the conditioning): give {name} ≥ {MIN_TOL:g}")
    return number


#: the largest iteration limit: every backend's counter holds it (a C int)
MAX_ITER = 2 ** 31 - 1


def check_max_iter(max_iter: Any) -> int | None:
    """``max_iter`` as an int in [1, :data:`MAX_ITER`], or InputError."""
    if max_iter is None:
        return None
    number = finite_number(max_iter)
    if number is None or not number.is_integer() or not 1 <= number <= MAX_ITER:
        raise InputError(f"max_iter must be a positive integer up to {MAX_ITER} (2³¹ − 1, what "
                         f"every backend's counter holds), got {max_iter!r}")
    return int(number)


def _count(value: Any) -> bool:
    return isinstance(value, (int, np.integer)) and not isinstance(value, bool) and value >= 0


def _seconds(value: Any) -> bool:
    return isinstance(value, Real) and not isinstance(value, bool) and math.isfinite(value) \
        and value >= 0


#: what a method reports beside its answer, by field: (the test it passes, what it must be)
REPORTED = {"iterations": (_count, "a whole number ≥ 0"),
            "build_time": (_seconds, "seconds, a finite number ≥ 0"),
            "solve_time": (_seconds, "seconds, a finite number ≥ 0"),
            "message": (lambda v: isinstance(v, str), "a str"),
            "extras": (lambda v: isinstance(v, dict), "a dict"),
            "history": (lambda v: isinstance(v, dict), "a dict of lists")}


def hold_to_contract(problem: ContactProblem, method: str, solution: Any) -> ContactSolution:
    """``solution`` when it is what a method must return, else a ``failed`` one saying why.

    A method returns a :class:`ContactSolution` whose ``u`` holds n floats and
    ``lam`` m floats (finite when it claims ``converged``; a method without an
    answer returns NaN, :meth:`ContactSolution.failure`), and whose status is
    one of :data:`signorini.problem.contact.STATUSES`; or the pair ``(u, lam)`` (the same two
    arrays), which claims ``converged`` and is judged by the certificate like any
    claim. A user's method that returns anything else cannot be judged, so it
    cannot be ``converged``.
    """
    def failed(reason: str) -> ContactSolution:
        return ContactSolution.failure(method, problem, "failed",
                                       f"the method broke its contract: {reason}")

    if isinstance(solution, tuple) and len(solution) == 2:  # (u, lam): the answer alone
        solution = ContactSolution(method, solution[0], solution[1], "converged",
                                   "returned (u, lam)")
    elif isinstance(solution, tuple):
        return failed(f"it returned a tuple of {len(solution)} items, not (u, lam) or a "
                      "ContactSolution")
    if not isinstance(solution, ContactSolution):
        return failed(f"it returned {type(solution).__name__}, not a ContactSolution")
    if solution.status not in STATUSES:
        return failed(f"status {solution.status!r} is not one of {', '.join(STATUSES)}")
    for name, (fits, said) in REPORTED.items():
        if not fits(getattr(solution, name)):
            return failed(f"its {name} must be {said}, got {getattr(solution, name)!r}")
    for name, size in (("u", problem.n), ("lam", problem.m)):
        value = getattr(solution, name)
        if not isinstance(value, np.ndarray) or isinstance(value, np.ma.MaskedArray) \
                or value.shape != (size,) or value.dtype.kind not in "fiu":
            got = (f"{value.dtype} array of shape {value.shape}" if type(value) is np.ndarray
                   else type(value).__name__)
            return failed(f"{name} must be an array of {size} floats, got a {got}")
        if value.dtype.kind != "f" or type(value) is not np.ndarray:  # a memmap, ints
            setattr(solution, name, np.array(value, dtype=float))
    if solution.status == "converged" and not (np.all(np.isfinite(solution.u)) and np.all(np.isfinite(solution.lam))):
        return failed(f"status {solution.status!r} with non-finite entries in u or lam")
    return solution


# -- the problem a method is judged on is the problem it was given ------------------------
# The certificate judges (u, λ) against the problem's K, f, N and d: a method that changed them
# (problem.f *= 0.5) would have its answer judged against its own question. So the data are
# fingerprinted before the method runs and checked after: f and d by a hash of their bytes, K
# and N by their product with a fixed random vector (equal up to summation order) and their
# shapes. The package itself pushes a pending problem to the push a load-matching method
# reports, so no method can hand in another problem to be judged on.

#: ``K x`` before and after a method agree to this (relative): summation order only
SAME_PRODUCT_RTOL = 1e-12
#: what each array is, for the message
MEANING = {"K": "the stiffness", "f": "the load", "N": "the contact normals", "d": "the gaps",
           "weights": "the candidates' boundary weights", "contact_points": "their positions",
           "force_multiplicity": "the copies of the model in the body", "scales": "the units",
           "prescribed": "the prescribed displacements"}


def _summary(array: Any, x: np.ndarray) -> Any:
    """``A x`` of a sparse matrix (K or N); a hash of the bytes of any other array."""
    if sp.issparse(array):
        return array @ x
    return hashlib.blake2b(np.ascontiguousarray(array, dtype=float).view(np.uint8),
                           digest_size=16).hexdigest()


def _arrays(problem: ContactProblem) -> dict[str, Any]:
    """What the answer is judged and reported by: the QP, and what turns it into forces,
    pressures, positions and units."""
    return {"K": problem.K, "f": problem.f, "N": problem.N, "d": problem.d,
            "weights": np.zeros(0) if problem.weights is None else problem.weights,
            "contact_points": problem.contact_points,
            "force_multiplicity": np.array([problem.force_multiplicity], dtype=float),
            "scales": np.array(dataclasses.astuple(problem.scales), dtype=float),
            "prescribed": getattr(problem.model, "prescribed", np.zeros(0))}


def fingerprint(problem: ContactProblem) -> dict[str, tuple]:
    """Of each of :func:`_arrays`: its shape and its :func:`_summary` with a fixed random x (a
    few vectors, no copy of K)."""
    x = np.random.default_rng(1).uniform(0.5, 1.5, problem.K.shape[1])
    return {name: (np.shape(a), _summary(a, x)) for name, a in _arrays(problem).items()}


def changed(problem: ContactProblem, before: dict[str, tuple]) -> list[str]:
    """The names of the arrays of ``problem`` that differ from their ``before`` fingerprint."""
    moved = [name for name, a in _arrays(problem).items() if np.shape(a) != before[name][0]]
    if moved:
        return moved
    now = fingerprint(problem)
    return [name for name, (_, kept) in before.items() if not (
        np.allclose(now[name][1], kept, rtol=SAME_PRODUCT_RTOL, atol=0.0)
        if isinstance(kept, np.ndarray) else now[name][1] == kept)]


def held_to_problem(problem: ContactProblem, before: dict[str, tuple], solution: ContactSolution,
                    method: str) -> ContactSolution:
    """``solution``, or a ``failed`` one when the method changed ``problem``.

    ``before`` is :func:`fingerprint` of ``problem`` taken before the method ran.
    """
    touched = changed(problem, before)
    if touched:
        names = ", ".join(f"{name} ({MEANING[name]})" for name in touched)
        return ContactSolution.failure(
            method, problem, "failed",
            f"the method changed the problem it was given: {names}; a method must not change "
            "the problem (copy what it changes first), so its answer cannot be judged")
    return solution


def certify(problem: ContactProblem, solution: ContactSolution) -> Certificate:
    """The certificate of ``solution``; without the duality gap when K is singular (no dual)."""
    try:
        return certificate(problem, solution)
    except np.linalg.LinAlgError:
        return certificate(problem, solution, duality_gap=False)


def judge(problem: ContactProblem, solution: ContactSolution, tol: float | None,
          cert: Certificate | None = None) -> ContactSolution:
    """Downgrade a claim of convergence that the certificate (``cert``, computed here when not
    given) does not back, or the model cannot.

    An answer the certificate accepts becomes ``model_inadequate`` when the
    boundary beyond the contact candidates shows that the contact outgrew
    them (:func:`signorini.certification.adequacy.adequacy`); warnings about the model are
    appended to the message. A problem no model made (a QP given as arrays) has neither.
    """
    if solution.status != "converged":
        return solution
    accept = acceptance(tol)
    cert = certify(problem, solution) if cert is None else cert
    reason = shortfall(cert, accept)
    if reason is not None:  # which candidates fail and how, with the advice that fits
        with np.errstate(all="ignore"):  # an answer beyond double precision is named, not warned of
            by_constraint = explain(problem, solution, accept)
        if by_constraint is not None:
            reason = f"{shortfall(cert, accept, advice='')}: {by_constraint}"
        solution.claimed_status = "converged"
        solution.status = "inaccurate"
        solution.message = f"{solution.message}; {reason}".lstrip("; ")
        return solution
    if problem.model.watch is None:  # nothing beyond the candidates to judge (a QP given as arrays)
        return solution
    found = adequacy(problem, solution, accept)
    if found is not None:
        solution.extras["adequacy"] = found.as_dict()
        if found.inadequate(accept):
            solution.claimed_status = "converged"
            solution.status = "model_inadequate"
            solution.message = f"{solution.message}; {found.message()}".lstrip("; ")
    for warning in warnings(problem, solution):
        solution.message = f"{solution.message}; warning: {warning}".lstrip("; ")
    return solution


__all__ = ["REPORTED", "acceptance", "Method", "rows_share_dofs", "check_tol", "check_max_iter",
           "hold_to_contract", "fingerprint", "changed", "held_to_problem", "certify", "judge",
           "ACCEPT_FACTOR", "MAX_ITER"]
