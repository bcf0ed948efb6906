"""The public Python API: build a problem, solve it, read the answer in your units.

>>> import signorini
>>> result = signorini.solve("hertz-cylinder", params={"E": 2.1e11, "R": 0.01})
>>> result.status, result.total_force          # doctest: +SKIP
('converged', 22512.3...)

One solve is one pipeline, read top to bottom in :func:`solve`: the request checked once
(:func:`~signorini.solvers.registry.check_request`), the scene built, its target load matched by
load control when it has one (:mod:`signorini.load_control`), the method run on the QP and its
answer certified once (:func:`~signorini.solvers.registry.run`), a :class:`Result` in the
problem's units (:mod:`signorini.result`).
"""

from __future__ import annotations

import logging
from typing import Any, Callable

from signorini import load_control
from signorini.certification import kkt
from signorini.certification.kkt import Certificate
from signorini.errors import InputError
from signorini.numerics.arrays import vector_argument
from signorini.problem.contact import ContactProblem, ContactSolution, WarmStart
from signorini.problem.scales import record_units
from signorini.result import SCHEMA_VERSION, Result, solve_summary
from signorini import scenes  # loaded at first use: a QP given as arrays needs no scene
from signorini.solvers import registry
from signorini.solvers.registry import Method, Request, check_request
from signorini.solvers.registry import methods as _all_methods

DEFAULT_METHOD = "auto"

log = logging.getLogger(__name__)

#: what names a method: a registered name, ``module:function``, a function, a :class:`Method`, or
#: a :class:`Request` already checked (:func:`~signorini.solvers.registry.check_request`)
MethodLike = str | Callable[..., Any] | Method | Request


def checked(method: Any, tol: Any = None, max_iter: Any = None,
            options: dict[str, Any] | None = None) -> Request:
    """The request of a solve, checked once: ``method`` as given when it is a checked
    :class:`Request` (which holds tol, max_iter and the options), else checked here."""
    if not isinstance(method, Request):
        return check_request(method, tol, max_iter, options)
    if tol is not None or max_iter is not None or options:
        raise InputError("a checked Request holds tol, max_iter and the method's options: give "
                         "them to check_request(method, tol, max_iter, options), not to solve")
    return method


def solve(problem: ContactProblem | str, method: MethodLike = DEFAULT_METHOD, *, tol: float | None = None,
          max_iter: int | None = None, warm_start: Any = None, params: dict[str, Any] | None = None,
          keep_factor: bool = False, **options: Any) -> Result:
    """Solve a problem (or a scene by name) and judge the answer with the KKT certificate.

    ``problem`` is a :class:`ContactProblem` (from :func:`build_problem`,
    :meth:`ContactProblem.from_qp` or :meth:`ContactProblem.load`) or the name
    of a scene (see :func:`scene_families`), built with ``params`` in the
    scene's units. A target load is matched first by load control
    (:mod:`signorini.load_control`). ``method`` is one of :func:`methods` (default
    ``auto``: the fastest exact route; the result says which and why): a
    method named here starts cold, or from ``warm_start`` (an earlier
    :class:`Result`), and the iterations it reports are its own (a :class:`Request` from
    :func:`~signorini.solvers.registry.check_request` is taken as checked);
    ``result.solution.work`` lists the work of every stage. ``tol`` is the
    relative KKT tolerance the answer must meet to be ``converged`` (None:
    the method's default; a QP backend then runs at its own settings and its
    answer is held to :data:`signorini.DEFAULT_TOL`); other keyword arguments
    are the method's options. ``keep_factor=True`` keeps the method's last
    factorisation on the result (in memory) for the answer's first derivative
    (:meth:`Result.jvp`, :func:`signorini.derivative`), which reuses it when it
    pins the final active set (``pdas``): back-solves only.
    Bad input raises :class:`signorini.InputError`; a method that fails
    returns a result whose ``status`` says so.
    """
    adaptive = sorted(set(options) & {"target_error", "max_dofs", "target_on"})
    if adaptive:
        raise InputError(f"{', '.join(adaptive)} steer{'s' * (len(adaptive) == 1)} adaptive "
                         "refinement: call signorini.solve_adaptive(scene, target_error, ...)")
    request = checked(method, tol, max_iter, options)  # once, before the scene is built
    if not isinstance(keep_factor, bool):  # here, not numerics.arrays: one file fewer per solve
        raise InputError(f"keep_factor={keep_factor!r} must be True or False")
    if isinstance(problem, str):
        problem = scenes.build_problem(problem, params=scenes.scene_params(params),
                                       solved_by=request.method)
    elif params:
        raise InputError("params= builds a scene by name: give solve('hertz-cylinder', params=...) "
                         "or build the problem with those parameters first")
    elif not isinstance(problem, ContactProblem):
        raise InputError(f"problem must be a ContactProblem or a scene name, got "
                         f"{type(problem).__name__}: build one with signorini.build_problem(...) "
                         "or ContactProblem.from_qp(K, f, N, d)")
    start = None if warm_start is None else WarmStart.of(warm_start).check_fits(problem.n, problem.m)
    if problem.model.pending or request.method.runs(problem, request.options, start).prediction:
        # a target load to match, or the scene's prediction of the contact for the method
        return Result(*load_control.solve(problem, request, warm_start=start,
                                          coarse=scenes.coarse_problem, keep_factor=keep_factor))
    return Result(*registry.run(problem, request, warm_start=start, keep_factor=keep_factor))


def at_load(problem: ContactProblem) -> ContactProblem:
    """``problem`` at its target load, or itself when it has none: the QP any method (or your
    own code) can then solve as it is. Load control matches the push (:mod:`signorini.load_control`)."""
    if not isinstance(problem, ContactProblem):
        raise InputError(f"at_load takes a ContactProblem, got {type(problem).__name__}: build one "
                         "with signorini.build_problem('hertz-cylinder') first")
    return load_control.at_load(problem, scenes.coarse_problem)


def solve_adaptive(scene: str, target_error: float | str, method: MethodLike = DEFAULT_METHOD, *,
                   tol: float | None = None, max_iter: int | None = None,
                   params: dict[str, Any] | None = None, max_dofs: int | None = None,
                   target_on: str | None = None, **options: Any) -> Result:
    """Refine a scene's mesh adaptively until the estimated relative error meets ``target_error``.

    ``target_error`` is ``0.001`` or ``"0.1%"``; the loop stops there, or
    when the next mesh would exceed ``max_dofs`` (default 100,000). With
    ``target_on="pressure"`` (the default for 2D scenes with contact
    pressures) the error of the contact pressure in L² over the candidates
    (``result.estimate.pressure.relative``), with ``"energy"`` the energy
    norm's (``result.estimate.relative``). Each step is solved as
    :func:`solve` would; the message says what stopped the loop and
    ``result.solution.extras["adaptive"]`` lists the steps
    (:mod:`signorini.scenes.adapt`).
    """
    if not isinstance(scene, str):
        raise InputError("adaptive refinement refines a scene's mesh: give the scene by name, "
                         "solve_adaptive('hertz-cylinder', 0.01)")
    params = scenes.scene_params(params)
    request = checked(method, tol, max_iter, options)
    certificates: dict[int, Certificate] = {}

    def solver(problem: ContactProblem) -> tuple[ContactProblem, ContactSolution]:
        solved = load_control.solve(problem, request, coarse=scenes.coarse_problem)
        certificates[id(solved.solution)] = solved.certificate
        return solved.problem, solved.solution

    run = scenes.adapt.solve_adaptive(scene, params, scenes.adapt.parse_target(target_error),
                                      solver, max_dofs=max_dofs, quantity=target_on,
                                      solved_by=request.method)
    result = Result(run.problem, run.solution, certificates[id(run.solution)])
    result._estimate = run.estimate
    return result


def certificate(problem: ContactProblem, solution: ContactSolution | None = None, *,
                u: Any = None, force: Any = None, duality_gap: bool = True) -> Certificate:
    """The relative KKT residuals of an answer ``(u, λ)`` of ``problem`` (:class:`Certificate`).

    Give the answer as a ``solution`` (a :class:`ContactSolution` in the units of the
    problem's own arrays: ``result.solution``), or as arrays in
    your units: ``u`` the QP's unknown (n entries, as ``Result.u``) and
    ``force`` the contact forces λ (m entries, as ``Result.force``); they are
    scaled by ``problem.scales`` as every method's answer is.
    ``cert.passed(tol)`` says whether the answer is certified at ``tol``;
    ``duality_gap=False`` leaves out what needs K⁻¹ (for a singular K).
    """
    if not isinstance(problem, ContactProblem):
        raise InputError(f"certificate: problem must be a ContactProblem, got {type(problem).__name__}")
    if problem.model.pending:  # its QP is at a nominal push, not the load an answer is for
        raise InputError("certificate: this problem's target load is not matched yet, so its QP "
                         "is at a nominal push: certify against the problem solved "
                         "(result.problem) or signorini.at_load(problem)")
    if not isinstance(duality_gap, bool):
        raise InputError(f"certificate: duality_gap must be True or False, got {duality_gap!r}")
    arrays = u is not None or force is not None
    if arrays and solution is not None:
        raise InputError("certificate: give either a solution or the arrays u= and force=, not both")
    if arrays:
        if u is None or force is None:
            raise InputError("certificate: give both u= (the QP's unknown, n entries) and force= "
                             "(the contact forces λ, m entries), in the problem's units")
        u, force = vector_argument(u, "u"), vector_argument(force, "force")
        if u.shape != (problem.n,) or force.shape != (problem.m,):
            raise InputError(f"certificate: u must have {problem.n} entries and force {problem.m}, "
                             f"got {u.shape} and {force.shape}")
        scales = problem.scales
        solution = ContactSolution(method="given", u=u / scales.displacement,
                                   lam=force / scales.force, status="converged")
    return kkt.certificate(problem, solution, duality_gap)


def methods(installed_only: bool = False) -> list[Method]:
    """The registered methods (name, summary, family, whether installed)."""
    return _all_methods(installed_only)


def scene_families() -> dict[str, scenes.SceneFamily]:
    """The built-in scene families by name (each lists its parameters and reference).

    (Not ``scenes``: that name is the subpackage :mod:`signorini.scenes`.)
    """
    return dict(scenes.SCENES)


__all__ = ["DEFAULT_METHOD", "SCHEMA_VERSION", "Request", "Result", "at_load",
           "certificate", "check_request", "checked", "methods", "record_units", "scene_families",
           "solve", "solve_adaptive", "solve_summary"]
