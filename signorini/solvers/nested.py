"""Nested: a predicted contact zone, made exact on one factorisation.

The prediction is, in this order: a zone given as an option; the analytic
contact half-width of the scene's reference for its target load (Hertz's a,
:attr:`signorini.references.Reference.extent`), trusted to its
``extent_margin`` of a — it costs nothing; or the coarse model of the same
scene (about 16× fewer dofs; see
:func:`signorini.scenes.coarse_values`) is solved first, by this method
again, down to a model with no coarser one (solved by ``pdas``). Its contact
zone predicts the fine one; :class:`signorini.numerics.zone.ZoneSolver` then pins
the predicted core, condenses the uncertain band onto a small dense LCP and
amends the prediction until every KKT condition holds, so the answer is
exact whatever the prediction. Cost: one factorisation of K, a back-solve per
band node and the coarse solve; time includes building the coarse model.

When load targeting already ran on a predicted zone (the solver is kept on
the problem) the factorisation is reused and the solve costs back-solves only.
Problems with no coarse model, or whose rows of N do not each bound one dof
(curved obstacles), are solved by ``pdas``; the message says so.
"""

from __future__ import annotations

import logging
import time
from typing import Any

import numpy as np

from signorini.errors import InputError
from signorini.numerics.factor import BACKENDS as FACTOR_BACKENDS
from signorini.numerics.factor import selection_dofs
from signorini.numerics.zone import Zone, ZoneSolver, predict_zone, zone_around_points
from signorini.problem import ContactProblem, ContactSolution
from signorini.references import reference_of
from signorini.solvers import pdas
from signorini.solvers.base import Method, judge
from signorini.solvers.options import Option, declare, take_options

log = logging.getLogger(__name__)

DEFAULT_TOL = 1e-9
DEFAULTS = declare(
    Option("backend", "choice", None, choices=(None, "auto", *FACTOR_BACKENDS)),
    Option("coarse", "object", types=(ContactProblem,)), Option("zone", "object", types=(Zone,)),
    Option("neighbours", "count"), Option("analytic", "bool", True))


def analytic_zone(problem: ContactProblem) -> tuple[Zone, float] | None:
    """The zone from the reference's contact half-width (radius) a and a, in the problem's length
    units (:func:`signorini.numerics.zone.zone_around_points`: 2D, axisymmetric and 3D models);
    None without."""
    reference = reference_of(problem)
    if reference is None or reference.extent is None:
        return None
    a = reference.extent(problem.params)
    if a is None:
        return None
    a /= problem.scales.length
    zone = zone_around_points(problem.contact_points, a, reference.extent_margin)
    return None if zone is None else (zone, a)


def _prediction(problem: ContactProblem, opts: dict[str, Any]) -> tuple[Zone | None, str]:
    """The predicted zone and where it came from (None when there is no coarse model)."""
    if opts["zone"] is not None:
        zone = opts["zone"]
        if not isinstance(zone, Zone) or zone.core.shape != (problem.m,):
            raise InputError(f"method 'nested': option zone must be a signorini.numerics.zone.Zone "
                             f"over the {problem.m} candidates")
        return zone, "given zone"
    if opts["analytic"] and opts["coarse"] is None:
        found = analytic_zone(problem)
        if found is not None:
            return found[0], f"the reference's analytic zone (a = {found[1]:.4g})"
    coarse = opts["coarse"]
    if coarse is None and problem.coarse_model is not None:
        coarse = problem.coarse_model(problem)
    if coarse is None:
        return None, ""
    zone = zone_from_coarse(problem.contact_points, coarse, opts["neighbours"])
    return zone, f"coarse model of {coarse.n} dofs"


def zone_from_coarse(points: np.ndarray, coarse, neighbours: int | None = None) -> Zone | None:
    """The zone at ``points`` predicted by the coarse model ``coarse`` (a ContactProblem).

    Its contact forces come from its load targeting when that ran (exact
    already), else from solving it with the ``nested`` method; None when
    that does not converge.
    """
    lam = coarse.warm_start.lam
    if lam is None:
        try:
            solution = judge(coarse, solve(coarse), DEFAULT_TOL)
        except Exception as exc:  # noqa: BLE001 - any failure of the coarse solve: no prediction
            log.info("the coarse model did not solve (%s): no prediction", exc)
            return None
        if solution.status != "converged":
            return None
        lam = solution.lam
    return predict_zone(points, coarse.contact_points, lam > 0, neighbours)


def solve(problem: ContactProblem, *, tol: float | None = None, max_iter: int | None = None,
          **options: Any) -> ContactSolution:
    """Exact contact from a coarse model's contact zone on one factorisation."""
    opts = take_options("nested", options, DEFAULTS)
    start = time.perf_counter()
    system = problem.warm_start.zone_solver
    if system is not None and opts["zone"] is None and opts["coarse"] is None:
        zone, source = problem.warm_start.zone, "the load targeting's zone and factorisation"
    else:
        system = None
        if selection_dofs(problem.N) is None:
            zone, source = None, ""
        else:
            zone, source = _prediction(problem, opts)
    if zone is None:
        solution = pdas.solve(problem, tol=tol, max_iter=max_iter)
        solution.method = "nested"
        solution.message = f"no coarse model or no pinnable rows: pdas: {solution.message}"
        solution.extras["fallback"] = "pdas"
        return solution
    build_time = time.perf_counter() - start
    if system is None:
        system = ZoneSolver(problem.K, problem.N, opts["backend"])
    factorisations, back_solves = system.factorisations, system.back_solves
    u, lam, final = system.solve(problem.f, problem.d, zone)
    problem.warm_start.zone_solver, problem.warm_start.zone = system, final
    moved = int((final.band & ~zone.band).sum())
    return ContactSolution(
        method="nested", u=u, lam=lam, status="converged",
        message=(f"zone from {source}: {final.counts()} ({moved} amended); "
                 f"{system.factorisations - factorisations} factorisation(s), "
                 f"{system.back_solves - back_solves} back-solves"),
        iterations=1, build_time=build_time, solve_time=time.perf_counter() - start - build_time,
        extras={"backend": system.backend, "core": int(final.core.sum()),
                "band": int(final.band.sum())}, factor=system.factor)


METHODS = (
    Method(name="nested", function=solve, family="active set", exact=True,
           summary="analytic or coarse-model contact zone; one factorisation + exact band LCP",
           default_tol=DEFAULT_TOL, options=tuple(DEFAULTS),
           typed_options=DEFAULTS),
)
