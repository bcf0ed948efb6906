"""The condensed dual: one factorisation, the Delassus operator, an exact small LCP.

``W = N K⁻¹ Nᵀ`` (m × m) is formed by back-solves of the one factorisation of
K, the complementarity problem ``λ ≥ 0, Wλ − b ≥ 0, λ·(Wλ − b) = 0`` with
``b = N K⁻¹ f − d`` is solved exactly on it (primal-dual active set on the
dense matrix, least-index pivoting should it cycle), and ``u = K⁻¹(f − Nᵀλ)``
is one more back-solve; the LCP stops when its active set repeats or its answer meets the
bounds to ``tol`` (:func:`signorini.numerics.lcp.solve_lcp`). Cost: one factorisation,
m + 2 back-solves and dense m × m work; only for problems with few contact candidates
(memory m²).
"""

from __future__ import annotations

import time
from typing import Any

from signorini.errors import InputError
from signorini.certification.inverse import WithDelassus
from signorini.numerics.factor import BACKENDS as FACTOR_BACKENDS, factorize
from signorini.numerics.lcp import StillChanging, delassus, solve_lcp
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.solvers.base import Method
from signorini.solvers.options import Option, declare, resolved, take_options

DEFAULTS = declare(
    Option("backend", "choice", None, choices=(None, "auto", *FACTOR_BACKENDS)),
    Option("block", "positive_count", None), Option("max_candidates", "positive_count", 20_000))


def condensed(problem: ContactProblem, *, tol: float | None = None, max_iter: int | None = None,
          **options: Any) -> ContactSolution:
    """Exact contact through the Delassus operator of the candidates."""
    opts = take_options("condensed", options, DEFAULTS)
    if problem.m > opts["max_candidates"]:
        raise InputError(f"method 'condensed' forms a dense m × m matrix and m = {problem.m} "
                         f"exceeds max_candidates = {opts['max_candidates']}: use pdas")
    start = time.perf_counter()
    factor = factorize(problem.K, opts["backend"])
    W = delassus(problem.N, factor, block=opts["block"])
    b = problem.N @ factor.solve(problem.f) - problem.d
    build_time = time.perf_counter() - start
    tol, max_iter = resolved("condensed", "active set", tol, max_iter)
    try:
        lam, steps = solve_lcp(W, b, max_iter=max_iter, tol=tol)
        status, said = "converged", f"LCP on {problem.m} candidates solved in {steps} active-set steps"
    except StillChanging as stopped:
        lam, steps, status = stopped.lam, max_iter, "max_iter"
        said = f"LCP on {problem.m} candidates: {stopped}"
    u = factor.solve(problem.f - problem.N.T @ lam)
    return ContactSolution(
        method="condensed", u=u, lam=lam, status=status,
        message=f"{said} ({factor.backend} factorisation)",
        iterations=steps, build_time=build_time,
        solve_time=time.perf_counter() - start - build_time,
        extras={"backend": factor.backend}, factor=WithDelassus(factor, problem.N, W))


METHODS = (
    Method(name="condensed", function=condensed, family="active set", exact=True,
           summary="condensed dual: Delassus operator by back-solves + exact dense LCP",
           typed_options=DEFAULTS),
)


__all__ = ["condensed", "METHODS"]
