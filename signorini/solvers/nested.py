"""Nested: a coarse model predicts the contact zone, one factorisation makes it exact.

The coarse model of the same scene (about 16× fewer dofs; see
:func:`signorini.scenes.coarse_values`) is solved first, by this method
again, down to a model with no coarser one (solved by ``pdas``). Its contact
zone predicts the fine one; :class:`signorini.nested.ZoneSolver` then pins
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

import time
from typing import Any

from ..errors import InputError
from ..linalg import selection_dofs
from ..nested import Zone, ZoneSolver, zone_from_coarse
from ..problem import ContactProblem, ContactSolution
from .options import take_options
from .registry import Method, register, solve as solve_with

DEFAULTS = {"backend": None, "coarse": None, "zone": None, "neighbours": None}


def _prediction(problem: ContactProblem, opts: dict[str, Any]) -> tuple[Zone | None, str]:
    """The predicted zone and where it came from (None when there is no coarse model)."""
    if opts["zone"] is not None:
        zone = opts["zone"]
        if not isinstance(zone, Zone) or zone.core.shape != (problem.m,):
            raise InputError(f"method 'nested': option zone must be a signorini.nested.Zone "
                             f"over the {problem.m} candidates")
        return zone, "given zone"
    coarse = opts["coarse"]
    if coarse is None:
        from ..scenes import coarse_problem

        coarse = coarse_problem(problem)
    if coarse is None:
        return None, ""
    zone = zone_from_coarse(problem.contact_points, coarse, opts["neighbours"])
    return zone, f"coarse model of {coarse.n} dofs"


def solve(problem: ContactProblem, *, tol: float | None = None, max_iter: int | None = None,
          **options: Any) -> ContactSolution:
    """Exact contact from a coarse model's contact zone on one factorisation."""
    opts = take_options("nested", options, DEFAULTS)
    start = time.perf_counter()
    system = getattr(problem, "zone_solver", None)
    if system is not None and opts["zone"] is None and opts["coarse"] is None:
        zone, source = problem.zone, "the load targeting's zone and factorisation"
    else:
        system = None
        if selection_dofs(problem.N) is None:
            zone, source = None, ""
        else:
            zone, source = _prediction(problem, opts)
    if zone is None:
        solution = solve_with(problem, "pdas", tol=tol, max_iter=max_iter)
        solution.method = "nested"
        solution.message = f"no coarse model or no pinnable rows: pdas: {solution.message}"
        solution.extras["fallback"] = "pdas"
        return solution
    build_time = time.perf_counter() - start
    if system is None:
        system = ZoneSolver(problem.K, problem.N, opts["backend"])
    factorisations, back_solves = system.factorisations, system.back_solves
    u, lam, final = system.solve(problem.f, problem.d, zone)
    problem.zone_solver, problem.zone = system, final
    moved = int((final.band & ~zone.band).sum())
    return ContactSolution(
        method="nested", u=u, lam=lam, status="converged",
        message=(f"zone from {source}: {final.counts()} ({moved} amended); "
                 f"{system.factorisations - factorisations} factorisation(s), "
                 f"{system.back_solves - back_solves} back-solves"),
        iterations=1, build_time=build_time, solve_time=time.perf_counter() - start - build_time,
        extras={"backend": system.backend, "core": int(final.core.sum()),
                "band": int(final.band.sum())})


register(Method(name="nested", function=solve, family="active set", exact=True,
                summary="coarse model predicts the contact zone; one factorisation + exact band LCP",
                default_tol=1e-9, options=tuple(DEFAULTS)))
