"""Clarabel called on a :class:`qpsolvers.Problem` directly, keeping what qpsolvers drops.

qpsolvers hands Clarabel the problem and returns a :class:`qpsolvers.Solution`
without the iteration count; this call builds the same conic problem
(``P``'s upper triangle, ``Gx + s = h`` with ``s`` in the non-negative cone,
a lower bound ``x ≥ lb`` as the rows ``−x + s = −lb``) and returns the same
kind of solution with ``extras["iterations"]``.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import scipy.sparse as sp

__all__ = ["solve_problem"]


def solve_problem(qp: Any, **settings: Any) -> Any:
    """Clarabel's answer to ``min ½xᵀPx + qᵀx  s.t.  Gx ≤ h`` (or ``x ≥ lb``) as qpsolvers
    gives it (``x``, ``z`` or ``z_box``, ``found``), with its status and iterations in ``extras``."""
    import clarabel  # optional backend: only when qp-clarabel runs
    import qpsolvers

    start = time.perf_counter()
    P, q, G, h, _, _, lb, _ = qp.unpack()
    bounds = G is None
    if bounds:  # x ≥ lb as −x ≤ −lb
        G, h = -sp.identity(q.size, format="csc"), -np.asarray(lb, dtype=float)
    options = clarabel.DefaultSettings()
    options.verbose = False
    for name, value in settings.items():
        setattr(options, name, value)
    solver = clarabel.DefaultSolver(sp.triu(sp.csc_matrix(P), format="csc"), np.asarray(q, float),
                                    sp.csc_matrix(G), np.asarray(h, float),
                                    [clarabel.NonnegativeConeT(h.size)], options)
    built = time.perf_counter()
    result = solver.solve()
    solution = qpsolvers.Solution(qp)
    solution.x = np.array(result.x)
    z = np.array(result.z)
    solution.z, solution.z_box = (np.empty(0), -z) if bounds else (z, np.empty(0))
    solution.found = result.status == clarabel.SolverStatus.Solved
    solution.extras = {"status": result.status, "iterations": int(result.iterations),
                       "solve_time": result.solve_time}
    solution.build_time, solution.solve_time = built - start, time.perf_counter() - built
    return solution
