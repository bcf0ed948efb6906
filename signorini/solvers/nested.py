"""Nested: a predicted contact zone, made exact on one factorisation.

The prediction is the option ``zone`` (``signorini.solve`` passes the scene's: the analytic
contact half-width of its reference, else a coarser model's contact zone, see
:mod:`signorini.load_control`), or the zone a coarser model of the same QP predicts (option
``coarse``, solved here by ``pdas``). :class:`signorini.numerics.zone.ZoneSolver` then pins the
predicted core, condenses the uncertain band onto a small dense LCP and amends the prediction
until every KKT condition holds, so the answer is exact whatever the prediction. Cost: one
factorisation of K and a back-solve per band node.

A ``warm_start`` holding a zone solver for this K (load control leaves one) is reused: the
solve then costs back-solves only; one holding an answer alone predicts the zone from that
answer's contact. Problems with no prediction, or whose rows of N do not each bound one dof
(curved obstacles), are solved by ``pdas``; the message says so.
"""

from __future__ import annotations

import logging
import time
from typing import Any

import numpy as np

from signorini.errors import InputError
from signorini.numerics.active_set import selection_dofs
from signorini.numerics.factor import BACKENDS as FACTOR_BACKENDS
from signorini.numerics.factor import counting
from signorini.numerics.zone import Zone, ZoneSolver, predict_zone
from signorini.problem.contact import ContactProblem, ContactSolution, WarmStart
from signorini.solvers import pdas
from signorini.solvers.base import Method, judge
from signorini.solvers.options import Option, declare, resolved, take_options

log = logging.getLogger(__name__)

DEFAULTS = declare(
    Option("backend", "choice", None, choices=(None, "auto", *FACTOR_BACKENDS)),
    Option("coarse", "object", types=(ContactProblem,)), Option("zone", "object", types=(Zone,)),
    Option("neighbours", "count"), Option("analytic", "bool", True),
    Option("warm_start", "object", types=(WarmStart,)))


def _prediction(problem: ContactProblem, opts: dict[str, Any],
                tol: float) -> tuple[Zone | None, str]:
    """The predicted zone and where it came from (None when there is none, or when the coarse
    model does not converge)."""
    zone, coarse = opts["zone"], opts["coarse"]
    if zone is not None:
        if zone.core.shape != (problem.m,):
            raise InputError(f"method 'nested': option zone must be a signorini.numerics.zone.Zone "
                             f"over the {problem.m} candidates")
        return zone, "the given zone"
    if coarse is None:
        return None, ""
    if coarse.model.pending:
        raise InputError("method 'nested': option coarse must be a problem at its load (its "
                         "target is not matched yet: signorini.load_control.match(coarse).problem)")
    try:
        solution = judge(coarse, pdas.pdas(coarse, tol=tol), tol)
    except Exception as exc:  # noqa: BLE001 - any failure of the coarse solve: no prediction
        log.info("the coarse model did not solve (%s): no prediction", exc)
        return None, ""
    if solution.status != "converged":
        return None, ""
    return (predict_zone(problem.contact_points, coarse.contact_points, solution.lam > 0,
                         opts["neighbours"]), f"coarse model of {coarse.n} dofs")


def nested(problem: ContactProblem, *, tol: float | None = None, max_iter: int | None = None,
          **options: Any) -> ContactSolution:
    """Exact contact from a coarse model's contact zone on one factorisation."""
    opts = take_options("nested", options, DEFAULTS)
    tol, max_iter = resolved("nested", "active set", tol, max_iter)
    start = time.perf_counter()
    warm, given = opts["warm_start"], opts["zone"] is not None or opts["coarse"] is not None
    system = None if warm is None or given else warm.zone_solver
    if system is not None and opts["backend"] not in (None, "auto", system.backend):
        system = None  # factorised by another backend than the one asked for
    if system is not None:
        zone, source = warm.zone, "the warm start's zone and factorisation"
    elif selection_dofs(problem.N) is None:
        zone, source = None, ""
    elif not given and warm is not None and warm.lam is not None:
        points = problem.contact_points
        zone = predict_zone(points, points, warm.lam > 0, opts["neighbours"])
        source = "the warm start's contact"
    else:
        zone, source = _prediction(problem, opts, tol)
    if zone is None:
        solution = pdas.pdas(problem, tol=tol, max_iter=max_iter)
        solution.method = "nested"
        solution.message = f"no coarse model or no pinnable rows: pdas: {solution.message}"
        solution.extras["fallback"] = "pdas"
        return solution
    build_time = time.perf_counter() - start
    if system is None:
        system = ZoneSolver(problem.K, problem.N, opts["backend"])
    with counting() as work:
        u, lam, final = system.solve(problem.f, problem.d, zone)
    moved = int((final.band & ~zone.band).sum())
    return ContactSolution(
        method="nested", u=u, lam=lam, status="converged",
        message=(f"zone from {source}: {final.counts()} ({moved} amended); "
                 f"{work.factorisations} factorisation(s), {work.back_solves} back-solves"),
        iterations=1, build_time=build_time, solve_time=time.perf_counter() - start - build_time,
        extras={"backend": system.backend, "core": int(final.core.sum()),
                "band": int(final.band.sum())}, factor=system.factor)


METHODS = (
    Method(name="nested", function=nested, family="active set", exact=True,
           summary="predicted contact zone (the scene's); one factorisation + exact band LCP",
           typed_options=DEFAULTS, prediction="zone",
           warm_from_load=True),
)


__all__ = ["nested", "DEFAULTS", "METHODS"]
