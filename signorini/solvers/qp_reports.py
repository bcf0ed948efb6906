"""What a qpsolvers backend reported: its raw status, iterations and other facts.

One reader per backend (or family of backends) takes the :class:`qpsolvers.Solution` and the
warnings the run raised, and returns a :class:`Report`; the backend table
(:mod:`signorini.solvers.qp_backends`) names which reader each backend uses. Clarabel is
called directly (:func:`solve_clarabel`) so that its iteration count is kept.
"""

from __future__ import annotations

import time
from typing import Any, Callable, NamedTuple

import numpy as np
import scipy.sparse as sp


class Report(NamedTuple):
    """What a backend said about its run: raw status, iterations, other facts."""

    raw_status: str
    iterations: int | None = None
    details: dict[str, Any] = {}


Reader = Callable[[Any, list[str]], Report]


def read_info(solution: Any, caught: list[str]) -> Report:
    """OSQP, ProxQP, PIQP, QPALM: ``extras["info"]`` with ``status`` and ``iter``."""
    info = solution.extras["info"]
    status = info.status
    raw = getattr(status, "name", None) or str(status)
    details = {}
    if hasattr(info, "status_polish"):  # OSQP: polishing can fail silently (osqp#790)
        details["polish_status"] = int(info.status_polish)
    return Report(raw, int(info.iter), details)


def read_clarabel(solution: Any, caught: list[str]) -> Report:
    """Clarabel's status, and its iterations when the call kept them (qpsolvers drops them)."""
    iterations = solution.extras.get("iterations")
    return Report(str(solution.extras["status"]), None if iterations is None else int(iterations))


def read_scs(solution: Any, caught: list[str]) -> Report:
    info = solution.extras
    return Report(str(info["status"]), int(info["iter"]), {"status_val": int(info["status_val"])})


ECOS_FLAGS = {0: "OPTIMAL", 1: "PINF", 2: "DINF", 10: "OPTIMAL_INACC", 11: "PINF_INACC",
               12: "DINF_INACC", -1: "MAXIT", -2: "NUMERICS", -3: "OUTCONE", -4: "SIGINT",
               -7: "FATAL"}


def read_ecos(solution: Any, caught: list[str]) -> Report:
    info = solution.extras
    flag = int(info["exitFlag"])
    return Report(ECOS_FLAGS.get(flag, f"exitFlag {flag}"), int(info["iter"]),
                  {"exit_flag": flag, "infostring": info.get("infostring", "")})


def read_found(ok: str, not_ok: str) -> Reader:
    """Backends whose status qpsolvers does not pass on: only ``found`` is known."""
    def read(solution: Any, caught: list[str]) -> Report:
        return Report(ok if solution.found else not_ok)
    return read


def read_quadprog(solution: Any, caught: list[str]) -> Report:
    if solution.found:
        return Report("solved", int(solution.extras["iterations"][0]))
    # qpsolvers swallows quadprog's "constraints are inconsistent, no solution"
    # silently and warns about every other ValueError
    complaints = [c for c in caught if "quadprog raised" in c]
    return Report(complaints[0] if complaints else "no solution")


def read_cvxopt(solution: Any, caught: list[str]) -> Report:
    res = solution.extras
    iterations = res.get("iterations")
    return Report(str(res.get("status")), None if iterations is None else int(iterations))


GUROBI_CODES = {1: "LOADED", 2: "OPTIMAL", 3: "INFEASIBLE", 4: "INF_OR_UNBD", 5: "UNBOUNDED",
                 6: "CUTOFF", 7: "ITERATION_LIMIT", 8: "NODE_LIMIT", 9: "TIME_LIMIT",
                 10: "SOLUTION_LIMIT", 11: "INTERRUPTED", 12: "NUMERIC", 13: "SUBOPTIMAL",
                 14: "INPROGRESS", 15: "USER_OBJ_LIMIT", 16: "WORK_LIMIT", 17: "MEM_LIMIT"}


def read_gurobi(solution: Any, caught: list[str]) -> Report:
    code = int(solution.extras["status"])
    return Report(GUROBI_CODES.get(code, f"status {code}"), None, {"status_code": code})


def solve_clarabel(qp: Any, **settings: Any) -> Any:
    """Clarabel's answer to ``min ½xᵀPx + qᵀx  s.t.  Gx ≤ h`` (or ``x ≥ lb``, as the rows
    ``−x + s = −lb``), called on the :class:`qpsolvers.Problem` directly and returned as
    qpsolvers gives it (``x``, ``z`` or ``z_box``, ``found``), with its status and iterations
    (which qpsolvers drops) in ``extras``."""
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


__all__ = ["Report", "read_info", "read_clarabel", "read_scs", "read_ecos", "read_found",
           "read_quadprog", "read_cvxopt", "read_gurobi", "solve_clarabel", "Reader"]
