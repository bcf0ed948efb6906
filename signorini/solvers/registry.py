"""The method registry: every solver is a plain function with one signature.

``solve(problem, *, tol=None, max_iter=None, **options) -> ContactSolution``

A ``tol`` or ``max_iter`` not asked for is the method's row of
:mod:`signorini.solvers.defaults` (None for a QP backend: its own settings,
untouched), which :func:`run` hands every method as numbers. A ``scaled`` method
gets a view of the problem in units of order one
(:func:`signorini.problem.scales.scaled_view`); a user's method, and a method given an
option in the problem's units (``Option.in_units``: a step, a starting λ, a
callback), gets the problem as given. Unknown options raise :class:`InputError`.
"""

from __future__ import annotations

import importlib.util
import logging
import time
from typing import Any, Callable, NamedTuple

from signorini.errors import BackendNotInstalled, InputError
from signorini.certification.fingerprint import fingerprint, held_to_problem
from signorini.certification.kkt import Certificate
from signorini.numerics.work import counting, timed
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.problem.scales import Scales, in_problem_units, scaled_view
from signorini.problem.solution import WarmStart
from signorini.solvers import amg, auto, condensed, cvxpy_, nested, pdas, petsc_, qp, user, uzawa
from signorini.solvers.base import (ACCEPT_FACTOR, DEFAULT_TOL, Method, certify, check_max_iter,
                                    check_tol, hold_to_contract, judge)

log = logging.getLogger(__name__)

#: the backend modules; each lists its methods in ``METHODS`` and never imports this module
BACKENDS = (auto, nested, pdas, amg, condensed, uzawa, qp, cvxpy_, petsc_)

REGISTRY: dict[str, Method] = {method.name: method for backend in BACKENDS
                               for method in backend.METHODS}


def register(method: Method) -> Method:
    """Add a method to the registry (a later registration of a name replaces it)."""
    REGISTRY[method.name] = method
    return method


#: the callables given as methods in this process, by the name they are known by
CALLABLES: dict[str, Method] = {}


def get_method(name: str | Callable[..., Any]) -> Method:
    """Look a method up by name, or take a callable as a method; unknown names list the known ones.

    A callable is known afterwards by its name (:func:`signorini.solvers.user.of_callable`).
    """
    if callable(name) and not isinstance(name, str):
        method = user.of_callable(name, {**CALLABLES, **REGISTRY})
        CALLABLES[method.name] = method
        return method
    if not isinstance(name, str):
        raise InputError(f"method must be a name or a function, got {type(name).__name__}: "
                         f"e.g. method='pdas'")
    if name in REGISTRY or name in CALLABLES:
        return REGISTRY.get(name) or CALLABLES[name]
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


def check_request(method: str, tol: Any = None, max_iter: Any = None,
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
            f"method {method!r} needs {', '.join(missing)}: {spec.install_hint}")
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
    if problem.pending and not spec.runs(problem, options, warm_start).matches(problem):
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
    with timed(seconds, "certificate"):
        if problem.pending and "push" not in solution.extras:
            solution = ContactSolution.failure(method, problem, solution.status if
                                               solution.status != "converged" else "failed",
                                               f"{solution.message}; the target load was not matched")
            cert = certify(problem, solution)
        else:
            if problem.pending:
                problem = problem.pushed(float(solution.extras["push"]))
            cert = certify(problem, solution)
            solution = judge(problem, solution, tol, cert)
    solution.seconds = {**solution.seconds, **seconds}
    return problem, solution, cert


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
    (see :class:`signorini.problem.solution.WarmStart`); without it every method
    starts cold. A problem whose target load is pending is matched by
    :func:`signorini.solve` (load control), not here.
    """
    request = check_request(method, tol, max_iter, options)
    return run(problem, request, warm_start=warm_start)[1]


__all__ = ["ACCEPT_FACTOR", "BACKENDS", "DEFAULT_TOL", "Method", "REGISTRY", "Request",
           "check_request", "get_method", "judge", "methods", "register", "run", "solve"]
