"""What a method is, and how its claim of success is judged.

A method is a plain function ``solve(problem, *, tol=None, max_iter=None,
**options) -> ContactSolution`` described by a :class:`Method`. Backends
define their methods here-shaped (a ``METHODS`` tuple per backend module);
:mod:`signorini.solvers.registry` collects them. A method's own claim of
success becomes ``converged`` only when the KKT certificate backs it
(:func:`judge`).
"""

from __future__ import annotations

import hashlib
import importlib.util
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import numpy as np
import scipy.sparse as sp

from signorini.certification.adequacy import adequacy, warnings
from signorini.certification.diagnosis import explain
from signorini.errors import InputError, install_hint
from signorini.certification.kkt import Certificate, certificate, shortfall
from signorini.problem.contact import STATUSES, ContactProblem, ContactSolution
from signorini.solvers.options import (DEFAULT_TOL, MIN_TOL, Defaults, Option, check_names,
                                       defaults_of, guess_value, resolved)

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

    ``requires`` lists the Python modules it imports; ``extra`` is the
    pip extra that installs them. ``dense`` methods build dense matrices and
    refuse problems above ``max_dense_dofs``. ``exact`` methods reach the
    answer up to round-off when they converge. ``options`` names the options
    it takes; its :attr:`defaults` (the row of :mod:`signorini.solvers.options`) are the
    tolerance it runs at and is held to when none is asked for and its iteration limit;
    ``typed_options`` declares their kinds and ranges
    (:class:`signorini.solvers.options.Option`), so that :meth:`check_options`
    refuses a bad value before any work.

    What it offers load control (:mod:`signorini.load_control`), which asks and
    never branches on a name: ``matches_load(problem)`` says it matches that
    problem's pending target load itself (``problem.model.pending``; e.g. the push as
    a bordered unknown), any other problem is matched first; ``prediction``
    the kind of prediction of the contact it takes from the scene (``"zone"``:
    the option ``zone``; ``"active set"``: ``active0``, and ``push0`` for a
    pending load); ``warm_from_load`` that it takes load control's answer as
    its warm start (else it starts cold). ``chooses(problem, options,
    warm_start)`` returns the method it runs instead (a method that picks one),
    whose capabilities are then the ones asked (:meth:`runs`). A ``scaled`` method is
    handed a view of the problem in units that make its numbers of order one (its answer
    mapped back to the problem's units before it is judged); a method that is not scaled (a
    user's) is handed the problem as it was given. A ``bound_rows`` method takes each contact
    row as a bound on dofs of its own (:mod:`signorini.solvers.bounds`): it refuses, by
    :meth:`check_rows`, a problem whose rows share a dof (two bodies' rows on the master's
    dofs, obstacles that meet at a node). ``factor_free_from`` is the size (dofs) from which it
    solves a 3D model with a target load without any factorisation (None: it factorises at
    every size), which a scene's memory estimate reads (:mod:`signorini.scenes.size`).
    """

    name: str
    function: SolverFunction
    summary: str
    requires: tuple[str, ...] = ()
    extra: str = ""
    dense: bool = False
    exact: bool = False
    family: str = ""
    options: tuple[str, ...] = field(default=())
    typed_options: Mapping[str, Option] = field(default_factory=dict)
    matches_load: Callable[[ContactProblem], bool] | None = None
    prediction: str = ""
    warm_from_load: bool = False
    chooses: Callable[..., "Method"] | None = None
    scaled: bool = True
    bound_rows: bool = False
    factor_free_from: float | None = None

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
        """``given`` with every declared option checked and converted; InputError otherwise.

        Unknown names are refused for every method that lists its options (a
        user's method lists none and takes what its function takes).
        """
        if self.family == "user":
            return dict(given)
        check_names(self.name, given, self.options)
        return {name: self.typed_options[name].check(self.name, value)
                if name in self.typed_options else value for name, value in given.items()}

    def parse_options(self, texts: Mapping[str, str]) -> dict[str, Any]:
        """``--opt name=text`` pairs read as each option's declared kind, and checked."""
        if self.family != "user":
            check_names(self.name, texts, self.options)
        return {name: self.typed_options[name].parse(self.name, text)
                if name in self.typed_options else guess_value(text)
                for name, text in texts.items()}


def rows_share_dofs(N: Any) -> bool:
    """Two rows of the constraint matrix N have a nonzero on one dof."""
    columns = sp.csc_matrix(N, copy=True)
    columns.eliminate_zeros()
    return bool(np.any(np.diff(columns.indptr) > 1))


def check_tol(tol: Any, name: str = "tol") -> float | None:
    """``tol`` as a float, or InputError naming ``name`` (the API's argument or the CLI's option)."""
    if tol is None:
        return None
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.floating, np.integer)) \
            or not (np.isfinite(tol) and 0 < tol < 1):
        raise InputError(f"{name} must be a number in (0, 1), got {tol!r}: e.g. {name} 1e-9")
    if tol < MIN_TOL:
        raise InputError(f"{name} {tol:g} is below what double precision can certify (relative "
                         f"residuals of order 1e-16 times the conditioning): give {name} ≥ {MIN_TOL:g}")
    return float(tol)


#: the largest iteration limit: every backend's counter holds it (a C int)
MAX_ITER = 2 ** 31 - 1


def check_max_iter(max_iter: Any) -> int | None:
    if max_iter is None:
        return None
    ok = isinstance(max_iter, (int, np.integer)) and not isinstance(max_iter, bool)
    ok = ok or (isinstance(max_iter, (float, np.floating)) and np.isfinite(max_iter)
                and float(max_iter).is_integer())
    if not ok or not 1 <= max_iter <= MAX_ITER:
        raise InputError(f"max_iter must be a positive integer up to {MAX_ITER} (2³¹ − 1, what "
                         f"every backend's counter holds), got {max_iter!r}")
    return int(max_iter)


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
    for name, size in (("u", problem.n), ("lam", problem.m)):
        value = getattr(solution, name)
        if not isinstance(value, np.ndarray) or value.shape != (size,) \
                or value.dtype.kind not in "fiu":
            got = (f"{value.dtype} array of shape {value.shape}" if isinstance(value, np.ndarray)
                   else type(value).__name__)
            return failed(f"{name} must be an array of {size} floats, got a {got}")
        if value.dtype.kind != "f":
            setattr(solution, name, value.astype(float))
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
MEANING = {"K": "the stiffness", "f": "the load", "N": "the contact normals", "d": "the gaps"}


def _digest(array: np.ndarray) -> str:
    return hashlib.blake2b(np.ascontiguousarray(array).view(np.uint8), digest_size=16).hexdigest()


def _probe(n: int) -> np.ndarray:
    return np.random.default_rng(1).uniform(0.5, 1.5, n)


@dataclass(frozen=True)
class Fingerprint:
    """What :func:`fingerprint` keeps of a problem's data (a few vectors, no copy of K)."""

    shapes: tuple
    f: str
    d: str
    K: np.ndarray
    N: np.ndarray


def fingerprint(problem: ContactProblem) -> Fingerprint:
    """Hashes of f and d, ``K x`` and ``N x`` for a fixed random x, and the shapes."""
    x = _probe(problem.K.shape[1])
    return Fingerprint((problem.K.shape, problem.N.shape, problem.f.shape, problem.d.shape),
                       _digest(problem.f), _digest(problem.d), problem.K @ x, problem.N @ x)


def changed(problem: ContactProblem, before: Fingerprint) -> list[str]:
    """The names of the arrays of ``problem`` that differ from ``before`` (none: unchanged)."""
    now = (problem.K.shape, problem.N.shape, np.shape(problem.f), np.shape(problem.d))
    if now != before.shapes:
        return [name for name, a, b in zip("KNfd", now, before.shapes) if a != b]
    x = _probe(problem.K.shape[1])
    out = []
    for name, product, kept in (("K", problem.K @ x, before.K), ("N", problem.N @ x, before.N)):
        if not np.allclose(product, kept, rtol=SAME_PRODUCT_RTOL, atol=0.0):
            out.append(name)
    out += [name for name, value, kept in (("f", problem.f, before.f), ("d", problem.d, before.d))
            if _digest(np.asarray(value, dtype=float)) != kept]
    return sorted(out, key="KfNd".index)


def held_to_problem(problem: ContactProblem, before: Fingerprint, solution: ContactSolution,
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
            "K, f, N or d (copy them first), so its answer cannot be judged")
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
