"""Primal-dual active set = semismooth Newton (Hintermüller, Ito & Kunisch 2002).

With the complementarity function ``λ = max(0, λ + c(Nu − d))``, each step
guesses the active set ``A = {i : λᵢ + c (Nu − d)ᵢ > 0}`` and solves the
equality-constrained saddle-point system on it::

    [ K    N_Aᵀ ] [ u   ]   [ f   ]
    [ N_A  0    ] [ λ_A ] = [ d_A ],   λ_I = 0.

It stops when A repeats; the answer is then exact up to round-off. PDAS can
cycle through active sets when W is not an M-matrix; a set seen before (but
not the last one) is a cycle, and the method then finishes on the condensed
LCP with Murty's least-index pivoting, which terminates for SPD W. After the
first step ``c`` no longer matters (closed gaps are zero on A, forces zero
off A), so ``c`` only weighs a warm start ``lam0`` against the gaps.

Option ``callback(iteration, u, λ)`` is called with the iterate of each step.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..condensed import delassus, least_index_lcp
from ..kkt import gap_scale
from ..linalg import factorize
from ..problem import ContactProblem, ContactSolution
from .options import positive_number, take_options
from .registry import Method, register

DEFAULTS = {"c": 1.0, "lam0": None, "callback": None}
MAX_ITER = 100


def _saddle_point_solve(problem: ContactProblem, active: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Solve the saddle-point system on ``active``; returns ``(u, λ)``.

    The constraint rows are scaled by ``s = mean |diag K|`` so that both
    blocks are of one size whatever the units (``λ = s μ``); unscaled, K of
    1e12 next to N of 1 leaves the gap rows satisfied only to 1e-4.
    """
    N_A = problem.N[active]
    k = N_A.shape[0]
    if k == 0:
        return factorize(problem.K).solve(problem.f), np.zeros(problem.m)
    s = float(np.mean(np.abs(problem.K.diagonal()))) or 1.0
    system = sp.bmat([[problem.K, s * N_A.T], [s * N_A, None]], format="csc")
    rhs = np.concatenate([problem.f, s * problem.d[active]])
    solution = spla.splu(system).solve(rhs)
    lam = np.zeros(problem.m)
    lam[active] = s * solution[problem.n:]
    return solution[:problem.n], lam


def _finish_condensed(problem: ContactProblem, lam: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """Finish on the condensed LCP with a method that cannot cycle (Murty's least index)."""
    factor = factorize(problem.K)
    W, _ = delassus(problem.N, factor)
    b = problem.N @ factor.solve(problem.f) - problem.d
    lam, steps = least_index_lcp(W, b)
    return factor.solve(problem.f - problem.N.T @ lam), lam, steps


def solve(problem: ContactProblem, *, tol: float | None = None, max_iter: int | None = None,
          **options: Any) -> ContactSolution:
    """Semismooth Newton / PDAS on the full saddle-point system (one sparse LU per step)."""
    opts = take_options("pdas", options, DEFAULTS)
    c = positive_number("pdas", "c", opts["c"])
    max_iter = MAX_ITER if max_iter is None else int(max_iter)
    start = time.perf_counter()
    if opts["lam0"] is None:
        u, lam = _saddle_point_solve(problem, np.zeros(problem.m, dtype=bool))
    else:
        lam = np.maximum(np.asarray(opts["lam0"], dtype=float), 0.0)
        u = problem.displacement_for(lam)
    history: dict[str, list[float]] = {"changes": [], "primal": [], "active": []}
    active = None
    seen: set[bytes] = set()
    status, message = "max_iter", f"active set still changing after {max_iter} steps"
    for iteration in range(1, max_iter + 1):
        violation = problem.N @ u - problem.d
        new_active = lam + c * violation > 0
        changes = problem.m if active is None else int(np.sum(new_active != active))
        history["changes"].append(changes)
        history["primal"].append(float(max(violation.max(), 0.0)) / gap_scale(problem, u))
        history["active"].append(int(new_active.sum()))
        if opts["callback"] is not None:
            opts["callback"](iteration, u, lam)
        if active is not None and changes == 0:
            status = "converged"
            message = f"active set of {int(active.sum())} nodes repeated after {iteration - 1} steps"
            iteration -= 1
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
        u, lam = _saddle_point_solve(problem, active)
    return ContactSolution(method="pdas", u=u, lam=lam, status=status, message=message,
                           iterations=iteration, solve_time=time.perf_counter() - start,
                           history=history)


register(Method(name="pdas", function=solve, family="active set", exact=True,
                summary="primal-dual active set / semismooth Newton, exact when it converges",
                default_tol=1e-9, options=tuple(DEFAULTS)))
