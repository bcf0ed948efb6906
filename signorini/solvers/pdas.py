"""Primal-dual active set = semismooth Newton (Hintermüller, Ito & Kunisch 2002).

With the complementarity function ``λ = max(0, λ + c(Nu − d))``, each step guesses the active
set ``A = {i : λᵢ + c (Nu − d)ᵢ > 0}`` and solves the equality-constrained system on it
(:class:`signorini.numerics.active_set.ActiveSetSolver`: the active dofs pinned in K when each
row of N bounds one dof, else the saddle-point matrix by LU)::

    [ K    N_Aᵀ ] [ u   ]   [ f   ]
    [ N_A  0    ] [ λ_A ] = [ d_A ],   λ_I = 0.

It stops when A repeats (the answer is then exact up to round-off), or one solve sooner when
the answer on A already meets the remaining conditions to ``tol`` (no force on A below
``−tol`` times the force scale, no penetration off A beyond ``tol`` times the gap scale, as
:mod:`signorini.certification.kkt` measures them). PDAS can cycle when W is not an M-matrix:
a set seen before is a cycle, and the method finishes on the condensed LCP with Murty's
least-index pivoting, which terminates for SPD W. After the first step ``c`` no longer
matters, so it only weighs a warm start against the gaps. It starts cold, from no contact,
or from ``warm_start`` (:class:`signorini.problem.contact.WarmStart`) or ``lam0``.

Option ``callback(iteration, u, λ)`` is called with the iterate of each step.
"""

from __future__ import annotations

import logging
import time
from typing import Any

import numpy as np

from signorini.certification.kkt import force_scale, gap_scale
from signorini.numerics.active_set import ActiveSetSolver
from signorini.numerics.factor import BACKENDS as FACTOR_BACKENDS, factorize
from signorini.numerics.lcp import delassus, least_index_lcp
from signorini.problem.contact import ContactProblem, ContactSolution, WarmStart
from signorini.solvers.base import Method
from signorini.solvers.options import Option, declare, per_candidate, resolved, take_options

log = logging.getLogger(__name__)

DEFAULTS = declare(
    Option("c", "positive", 1.0, in_units=True), Option("lam0", "vector", in_units=True),
    Option("callback", "callable", in_units=True),
    Option("warm_start", "object", types=(WarmStart,)),
    Option("backend", "choice", None, choices=(None, "auto", *FACTOR_BACKENDS)))


def _finish_condensed(problem: ContactProblem, lam: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """Finish on the condensed LCP with a method that cannot cycle (Murty's least index)."""
    factor = factorize(problem.K)
    W = delassus(problem.N, factor)
    b = problem.N @ factor.solve(problem.f) - problem.d
    lam, steps = least_index_lcp(W, b)
    return factor.solve(problem.f - problem.N.T @ lam), lam, steps


def pdas(problem: ContactProblem, *, tol: float | None = None, max_iter: int | None = None,
          **options: Any) -> ContactSolution:
    """Semismooth Newton / PDAS on the full saddle-point system (one sparse LU per step)."""
    opts = take_options("pdas", options, DEFAULTS)
    c, warm = opts["c"], opts["warm_start"]
    lam0 = per_candidate("pdas", "lam0", opts["lam0"], problem.m)
    tol, max_iter = resolved("pdas", "active set", tol, max_iter)
    start = time.perf_counter()
    system = ActiveSetSolver(problem.K, problem.N, opts["backend"])
    if lam0 is None and warm is not None and warm.lam is not None and warm.u is not None:
        u, lam = warm.u, warm.lam  # an earlier answer at this load: one step confirms it
    elif lam0 is not None or warm is not None and warm.lam is not None:
        lam = np.maximum(warm.lam if lam0 is None else lam0, 0.0)
        u = problem.displacement_for(lam)
    else:
        u, lam = system.solve(np.zeros(problem.m, dtype=bool), problem.f, problem.d)
    history: dict[str, list[float]] = {"changes": [], "primal": [], "active": []}
    active = None
    seen: set[bytes] = set()
    status, message = "max_iter", f"active set still changing after {max_iter} steps"
    for iteration in range(1, max_iter + 1):
        Nu = problem.N @ u
        violation = Nu - problem.d
        new_active = lam + c * violation > 0
        changes = problem.m if active is None else int(np.sum(new_active != active))
        history["changes"].append(changes)
        history["primal"].append(float(max(violation.max(), 0.0)) / gap_scale(problem, u, Nu))
        history["active"].append(int(new_active.sum()))
        if opts["callback"] is not None:
            opts["callback"](iteration, u, lam)
        if active is not None:
            slack = 0.0 if changes == 0 else max(
                history["primal"][-1], float(np.max(-lam, initial=0.0)) / force_scale(problem, lam, u, Nu))
            if slack <= tol:
                status, iteration = "converged", iteration - 1
                message = (f"active set of {int(active.sum())} nodes repeated after {iteration} steps"
                           if changes == 0 else
                           f"active set of {int(active.sum())} nodes after {iteration} steps: its "
                           f"answer meets the bounds to {slack:.1e} ≤ tol {tol:.0e}")
                break
        if new_active.tobytes() in seen:
            u, lam, steps = _finish_condensed(problem, lam)
            status = "converged"
            message = (f"PDAS cycled after {iteration - 1} steps; finished by least-index pivoting "
                       f"on the condensed LCP in {steps} steps")
            history["fallback_steps"] = [steps]
            break
        seen.add(new_active.tobytes())
        active = new_active
        log.info("pdas step %d: %d candidates in contact, %d changed", iteration,
                 history["active"][-1], changes)
        reused = warm.factor if warm is not None and iteration == 1 else None
        u, lam = system.solve(active, problem.f, problem.d, factor=reused)
    return ContactSolution(method="pdas", u=u, lam=lam, status=status, message=message,
                           iterations=iteration, solve_time=time.perf_counter() - start,
                           history=history, factor=system.factor)


METHODS = (
    Method(name="pdas", function=pdas, family="active set", exact=True,
           summary="primal-dual active set / semismooth Newton, exact when it converges",
           typed_options=DEFAULTS),
)


__all__ = ["pdas", "DEFAULTS", "METHODS"]
