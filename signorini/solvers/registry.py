"""The method registry, and running one method on a problem: every solver is a plain function
with one signature.

``solve(problem, *, tol=None, max_iter=None, **options) -> ContactSolution``

The registry (:data:`REGISTRY`) is built once, when the package is imported, from each backend's
``METHODS``, and read only afterwards; a method of one's own is given to a solve as a callable, a
:class:`Method` or ``module:function`` and travels in the checked :class:`Request`, never in a
table. A ``tol`` or ``max_iter`` not asked for is the method's row of
:data:`signorini.solvers.options.TABLE` (None for a QP backend: its own settings, untouched),
which :func:`run` hands every method as numbers. A ``scaled`` method gets a private view of the
problem in units of order one (:func:`scaled_view`), its answer mapped back
(:func:`in_problem_units`) before it is judged; a user's method, and a method given an option in
the problem's units (``Option.in_units``: a step, a starting λ, a callback), gets the problem as
given. Unknown options raise :class:`InputError`.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import logging
import time
from contextlib import contextmanager
from contextvars import ContextVar
from types import MappingProxyType
from typing import Any, Callable, Iterator, Mapping, NamedTuple

import numpy as np
import scipy.sparse as sp

from signorini.errors import BackendNotInstalled, InputError
from signorini.certification.kkt import Certificate
from signorini.numerics.factor import counting
from signorini.problem.contact import ContactProblem, ContactSolution, WarmStart
from signorini.problem.scales import Scales
from signorini.solvers import amg, auto, condensed, cvxpy_, nested, pdas, petsc_, qp, user, uzawa
from signorini.solvers.base import (ACCEPT_FACTOR, Method, certify, check_max_iter, check_tol,
                                    fingerprint, held_to_problem, hold_to_contract, judge)
from signorini.solvers.options import DEFAULT_TOL

log = logging.getLogger(__name__)

#: the backend modules; each lists its methods in ``METHODS`` and never imports this module
BACKENDS = (auto, nested, pdas, amg, condensed, uzawa, qp, cvxpy_, petsc_)

#: every built-in method by name, read only
REGISTRY: Mapping[str, Method] = MappingProxyType(
    {method.name: method for backend in BACKENDS for method in backend.METHODS})

#: methods answering to a name in the current context only (:func:`given`), read before the
#: registry; a context variable, per thread and per task, as the work records are
_GIVEN: ContextVar[Mapping[str, Method]] = ContextVar("given_methods",
                                                      default=MappingProxyType({}))


@contextmanager
def given(methods: Mapping[str, Method]) -> Iterator[None]:
    """While the block runs, each of ``methods`` is what its name looks up (before the registry,
    which is never written): e.g. a user's method wrapped to run in a worker process."""
    token = _GIVEN.set(MappingProxyType({**_GIVEN.get(), **methods}))
    try:
        yield
    finally:
        _GIVEN.reset(token)


def get_method(name: str | Callable[..., Any] | Method) -> Method:
    """Look a method up by name, or take a :class:`Method` or a callable as a method; unknown
    names list the known ones.

    A callable is named by its ``__name__`` (:func:`signorini.solvers.user.of_callable`).
    """
    if isinstance(name, Method):
        return name
    if callable(name) and not isinstance(name, str):
        return user.of_callable(name, REGISTRY)
    if not isinstance(name, str):
        raise InputError(f"method must be a name or a function, got {type(name).__name__}: "
                         f"e.g. method='pdas'")
    if name in _GIVEN.get():
        return _GIVEN.get()[name]
    if name in REGISTRY:
        return REGISTRY[name]
    if ":" in name:
        return user.load(name)
    known = ", ".join(sorted(REGISTRY))
    raise InputError(f"unknown method {name!r}: choose --method from {known}")


def methods(installed_only: bool = False) -> list[Method]:
    """Every registered method, sorted by name."""
    out = sorted(REGISTRY.values(), key=lambda m: m.name)
    return [m for m in out if m.installed] if installed_only else out


class Request(NamedTuple):
    """A solve's method, tolerance, iteration limit and options, checked (:func:`check_request`)."""

    method: Method
    tol: float | None
    max_iter: int | None
    options: dict[str, Any]


def check_request(method: str | Callable[..., Any] | Method, tol: Any = None, max_iter: Any = None,
                  options: dict[str, Any] | None = None) -> Request:
    """The method, tolerance, iteration limit and options of a solve, checked before any work.

    InputError for an unknown method, a bad tolerance or limit, an unknown
    option or a value of the wrong kind; BackendNotInstalled when the method's
    backend is missing.
    """
    spec = get_method(method)
    checked = spec.check_options(options or {})  # also for a backend that is not installed
    tol, max_iter = check_tol(tol), check_max_iter(max_iter)
    if not spec.installed:
        missing = [m for m in spec.requires if importlib.util.find_spec(m) is None]
        raise BackendNotInstalled(
            f"method {spec.name!r} needs {', '.join(missing)}: {spec.install_hint}")
    return Request(spec, tol, max_iter, checked)


def run(problem: ContactProblem, request: Request, *, warm_start: WarmStart | None = None,
        keep_factor: bool = False) -> tuple[ContactProblem, ContactSolution, Certificate]:
    """Run the method of ``request`` on ``problem``; its answer judged by its certificate, once:
    ``(problem solved, solution, certificate)``.

    The problem solved is ``problem`` itself, or, for a method that matches
    a pending target load with the answer (``Method.matches_load``), ``problem``
    at the push it reports (``solution.extras["push"]``). The method's work
    (factorisations, back-solves, CG iterations) is ``solution.work["method"]``;
    its wall time ``solution.seconds["method"]`` and the certificate's (judging
    included) ``solution.seconds["certificate"]``.
    ``keep_factor`` keeps the method's last factorisation on the solution after
    judging (for the answer's derivatives). See :func:`solve`.
    """
    spec, tol, max_iter, options = request
    method = spec.name  # a callable given as the method is known by its name
    spec.runs(problem, options, warm_start).check_rows(problem)
    if problem.model.pending and not spec.runs(problem, options, warm_start).matches(problem):
        raise InputError(f"method {method!r} solves the QP as it is, and this problem's target "
                         "load is not matched yet: solve it with signorini.solve (load control "
                         "finds the push), or match it first with signorini.load_control.match")
    if warm_start is not None:
        if "warm_start" not in spec.options:
            takers = ", ".join(m.name for m in REGISTRY.values() if "warm_start" in m.options)
            raise InputError(f"method {method!r} takes no warm start: give warm_start to one of "
                             f"{takers}")
        fits = WarmStart.of(warm_start).check_fits(problem.n, problem.m)
        options = {**options, "warm_start": fits}
    log.info("solving %d dofs, %d contact candidates with %s", problem.n, problem.m, method)
    start = time.perf_counter()
    tol, max_iter = spec.defaults_for(tol, max_iter)
    as_given = not spec.scaled or any(  # a step, a start or a callback in the problem's units
        value is not None and name in spec.typed_options and spec.typed_options[name].in_units
        for name, value in options.items())
    given, units = (problem, Scales()) if as_given else scaled_view(problem, options)
    held = fingerprint(given)
    with counting() as work:
        try:
            solution = spec.function(given, tol=tol, max_iter=max_iter, **options)
        except InputError:
            raise
        except Exception as exc:  # a backend's own error (CHOLMOD on a singular K): a failed run
            said, trace = user.raised(exc)
            log.warning("method %s raised %s", method, said)
            log.info("the traceback of method %s:\n%s", method, trace)
            solution = ContactSolution.failure(method, problem, "failed", said,
                                               solve_time=time.perf_counter() - start)
            solution.extras["traceback"] = trace
        except SystemExit as exc:  # a method that exits ends neither the run nor fakes its success
            solution = ContactSolution.failure(
                method, problem, "failed", f"the method called sys.exit({exc.code!r})",
                solve_time=time.perf_counter() - start)
    solution = hold_to_contract(given, method, solution)
    solution = in_problem_units(problem, held_to_problem(given, held, solution, method), units)
    # the method's own wall time; judging below (the certificate factorises K) is not the method's
    seconds = {"method": time.perf_counter() - start}
    solution.work["method"] = work.listed(steps=int(solution.iterations))
    solution.keep_factor = keep_factor
    if "auto" not in solution.extras:  # auto names the method it picked
        solution.method = method
    log.info("checking the answer: the KKT certificate")
    judging = time.perf_counter()
    if problem.model.pending and "push" not in solution.extras:
        solution = ContactSolution.failure(method, problem, solution.status if
                                           solution.status != "converged" else "failed",
                                           f"{solution.message}; the target load was not matched")
        cert = certify(problem, solution)
    else:
        if problem.model.pending:
            problem = problem.pushed(float(solution.extras["push"]))
        cert = certify(problem, solution)
        solution = judge(problem, solution, tol, cert)
    seconds["certificate"] = time.perf_counter() - judging
    solution.seconds = {**solution.seconds, **seconds}
    return problem, solution, cert


# -- a method's private view of the problem in units of order one ------------------------------

def qp_scales(K: sp.spmatrix, f: np.ndarray, d: np.ndarray,
              weights: np.ndarray | None = None) -> Scales:
    """The units that make a QP given as arrays dimensionless, by a scene's rule.

    A scene divides K by its stiffness ``E·L^k`` and displacements by its
    largest prescribed displacement, else its largest gap. A QP given as arrays
    has its prescribed displacements lifted into f and d, so: the stiffness
    ``k`` is the mean of K's diagonal, the displacement ``U`` the larger of
    ``‖d‖∞`` and ``‖f‖∞ / k`` (the gaps, and how far the load moves one dof),
    the force ``k·U`` (so that ``K̂ = K/k``, ``f̂ = f/(k·U)``, ``d̂ = d/U`` and
    ``λ̂ = λ/(k·U)``) and the weight the mean weight. A scale that comes out
    zero is 1; lengths keep the user's unit.
    """
    diagonal = np.abs(K.diagonal())
    stiffness = float(np.mean(diagonal)) if diagonal.size else 0.0
    stiffness = stiffness if np.isfinite(stiffness) and stiffness > 0 else 1.0
    largest = max(float(np.max(np.abs(d), initial=0.0)),
                  float(np.max(np.abs(f), initial=0.0)) / stiffness)
    displacement = largest if np.isfinite(largest) and largest > 0 else 1.0
    weight = float(np.mean(weights)) if weights is not None and weights.size else 1.0
    return Scales(length=1.0, displacement=displacement, force=stiffness * displacement,
                  weight=weight)


#: a scale within this factor of 1 is of order one
ORDER_ONE = 10.0


def scaled_view(problem: Any, options: dict[str, Any]) -> tuple[Any, Scales]:
    """``(view, scales)``: ``problem`` in units of order one and the units that undo it; the
    options' warm start (an earlier answer in the problem's units) is moved into the view."""
    if problem.scales != Scales():
        return problem, Scales()
    s = qp_scales(problem.K, problem.f, problem.d, problem.weights)
    if all(1 / ORDER_ONE <= value <= ORDER_ONE for value in (s.displacement, s.force, s.weight)):
        return problem, Scales()
    view = dataclasses.replace(
        problem, K=problem.K * (s.displacement / s.force), f=problem.f / s.force,
        d=problem.d / s.displacement, scales=s,
        weights=None if problem.weights is None else problem.weights / s.weight)
    warm = options.get("warm_start")
    if isinstance(warm, WarmStart):
        options["warm_start"] = dataclasses.replace(
            warm, lam=None if warm.lam is None else np.asarray(warm.lam) / s.force,
            u=None if warm.u is None else np.asarray(warm.u) / s.displacement)
    return view, s


def in_problem_units(problem: Any, solution: Any, scales: Scales) -> Any:
    """``solution`` of the view made with ``scales``, as an answer of ``problem`` itself."""
    if scales == Scales():
        return solution
    solution.u = solution.u * scales.displacement
    solution.lam = solution.lam * scales.force
    stiffness = scales.force / scales.displacement
    in_units = getattr(solution.factor, "in_units", None)  # a saddle-point system's own
    if solution.factor is not None:
        solution.factor = (in_units(problem.K, stiffness) if in_units is not None
                           else UnitsFactor(solution.factor, problem.K, stiffness))
    return solution


class UnitsFactor:
    """A factorisation of the view's ``K̂ = K/k`` that solves with the problem's ``K``.

    ``solve(rhs)`` gives u with ``(K u)[free] = rhs[free]`` and ``u[fixed] = rhs[fixed]``
    (the pinned dofs of the factorisation, none for a plain one): the loads are divided
    by k, the prescribed values kept. ``matrix`` is the problem's K, so that the
    certificate reuses it; the Delassus operator a factorisation carries is ``Ŵ/k``.
    """

    def __init__(self, factor: Any, K: Any, stiffness: float):
        self.factor, self.matrix, self.stiffness = factor, K, stiffness
        self.fixed = np.asarray(getattr(factor, "fixed", np.zeros(0, dtype=int)), dtype=int)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.factor, name)

    @property
    def delassus(self) -> Any:
        W = getattr(self.factor, "delassus", None)
        return None if W is None else W / self.stiffness

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        scaled = np.array(rhs, dtype=float) / self.stiffness
        scaled[self.fixed] = np.asarray(rhs, dtype=float)[self.fixed]
        return self.factor.solve(scaled)

    def fixed_rows(self, u: np.ndarray) -> np.ndarray:
        """``(K u)[fixed]``."""
        return self.stiffness * self.factor.fixed_rows(u)


def solve(problem: ContactProblem, method: str = "pdas", *, tol: float | None = None,
          max_iter: int | None = None, warm_start: WarmStart | None = None,
          **options: Any) -> ContactSolution:
    """Solve ``problem`` with ``method`` and judge the answer with the KKT certificate.

    The method's own claim of success becomes ``converged`` only when every
    relative residual of :func:`signorini.certification.kkt.certificate` is within
    ``ACCEPT_FACTOR × tol``; otherwise the status is ``inaccurate`` and the
    message says by how much it missed. A backend exception becomes a
    ``failed`` solution; bad input (unknown options, non-positive tolerances)
    raises :class:`InputError`. ``warm_start`` is where the method starts
    (see :class:`signorini.problem.contact.WarmStart`); without it every method
    starts cold. A problem whose target load is pending is matched by
    :func:`signorini.solve` (load control), not here.
    """
    request = check_request(method, tol, max_iter, options)
    return run(problem, request, warm_start=warm_start)[1]


__all__ = ["ACCEPT_FACTOR", "BACKENDS", "DEFAULT_TOL", "ORDER_ONE", "Method", "REGISTRY", "Request",
           "UnitsFactor", "check_request", "get_method", "given", "in_problem_units", "judge", "methods",
           "qp_scales", "run", "scaled_view", "solve"]
