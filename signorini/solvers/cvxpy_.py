"""The contact QP written as a cvxpy model (read as the maths is written; cross-checks).

``minimise ½ xᵀKx − fᵀx  subject to  N x ≤ d`` with ``K`` symmetrised, or the
same in the other formulations of :mod:`signorini.solvers.forms` (option
``form``: ``shifted`` in ``u − K⁻¹f``, ``dual`` over ``λ ≥ 0``). cvxpy's
``dual_value`` of the constraint ``G @ x <= h`` of a minimisation is the
multiplier ``λ ≥ 0`` of the Lagrangian ``½xᵀPx + qᵀx + λᵀ(Gx − h)``, so
``λ = dual_value`` with no sign change (the tests check it for every solver).

Build time is model construction plus canonicalisation
(:meth:`cvxpy.Problem.get_problem_data`); solve time is the solver call plus
unpacking the result.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from signorini.errors import InputError, SolverError
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.solvers import forms
from signorini.solvers.base import Method
from signorini.solvers.options import Option, take_options
from signorini.solvers.qp_backends import BACKEND_BY_NAME, COMMON_TYPES

METHOD = "cvxpy"
DEFAULT_SOLVER = "CLARABEL"
#: measured by tools/formulations.py (docs/formulations.md): no form wins clearly with Clarabel
DEFAULT_FORM = "primal"
#: polished by default: with Clarabel's gap at tol² every validation case then ends converged
#: and exact at tol 1e-8 (docs/crosscheck.md); raw, 3 of 8 end inaccurate
DEFAULT_POLISH = True
#: the options, by kind (the solver is checked against cvxpy's installed ones when it runs)
TYPED_OPTIONS = {"solver": Option("solver", "text", DEFAULT_SOLVER), **COMMON_TYPES}

#: cvxpy status → ours (anything else is ``failed``)
STATUS_MAP = {"optimal": "converged", "optimal_inaccurate": "inaccurate",
              "infeasible": "infeasible", "user_limit": "max_iter"}

#: cvxpy solvers that use the same option names as the qpsolvers backend of the same
#: name, so one tolerance translation serves both (MOSEK's cvxpy interface differs)
_SHARED_TRANSLATION = ("CLARABEL", "OSQP", "SCS", "ECOS", "PIQP", "PROXQP", "DAQP", "HIGHS",
                       "QPALM", "CVXOPT", "GUROBI")

#: solvers that refuse or mishandle a plain continuous QP
_NOT_FOR_QP = ("ECOS_BB",)  # branch and bound for mixed-integer problems


def qp_solvers() -> list[str]:
    """Installed cvxpy solvers that accept a convex QP (natively or as an SOCP)."""
    import cvxpy as cp  # optional backend, 0.6 s to import: only when a cvxpy method runs
    from cvxpy.constraints import SOC
    from cvxpy.reductions.solvers import defines

    def takes_second_order_cones(name: str) -> bool:
        conic = defines.SOLVER_MAP_CONIC.get(name)
        return conic is not None and SOC in conic.SUPPORTED_CONSTRAINTS

    return [name for name in cp.installed_solvers() if name not in _NOT_FOR_QP
            and (name in defines.SOLVER_MAP_QP or takes_second_order_cones(name))]


def solver_options(solver: str, tol: float | None, max_iter: int | None) -> dict[str, Any]:
    """cvxpy ``solver_opts`` for a relative tolerance and an iteration limit.

    The translation is the one of :mod:`signorini.solvers.qp` for the backend of
    the same name; ``tol=None`` and ``max_iter=None`` leave cvxpy's defaults.
    """
    # (cvxpy's ProxQP interface builds dense matrices by default; its "sparse"
    # backend fails with proxsuite 0.8 in cvxpy 1.9.3, so it is left alone)
    if tol is None and max_iter is None:
        return {}
    if solver not in _SHARED_TRANSLATION:
        raise InputError(
            f"method 'cvxpy' cannot translate tol/max_iter for solver {solver!r}: "
            f"leave them unset or use one of {', '.join(_SHARED_TRANSLATION)}")
    backend = BACKEND_BY_NAME[solver.lower()]
    return backend.settings(tol, max_iter)


def _check_solver(solver: Any) -> str:
    available = qp_solvers()
    name = str(solver).upper()
    if name not in available:
        raise InputError(
            f"option solver={solver!r} of method 'cvxpy' is not an installed cvxpy solver "
            f"for QPs; installed: {', '.join(available)}")
    return name


def solve_cvxpy(problem: ContactProblem, *, tol: float | None = None, max_iter: int | None = None,
          **options: Any) -> ContactSolution:
    """Solve ``min ½uᵀKu − fᵀu  s.t.  Nu ≤ d`` as a cvxpy model.

    ``tol`` and ``max_iter`` are translated into the chosen solver's options (None: cvxpy's
    defaults). Options: ``solver`` (an installed cvxpy solver that accepts a QP, default
    ``"CLARABEL"``); ``form``, ``polish`` and ``max_dense_dofs`` as for the ``qp-*`` methods
    (:mod:`signorini.solvers.forms`; default ``form="primal"``, ``polish=True``). The answer:
    ``u = x.value``, ``λ = constraint.dual_value``; ``extras["raw_status"]`` is cvxpy's status.
    """
    options = take_options(METHOD, options, TYPED_OPTIONS)
    form, note = forms.resolve(METHOD, problem, options["form"], DEFAULT_FORM,
                               options["max_dense_dofs"])
    polishing = DEFAULT_POLISH if options["polish"] is None else options["polish"]
    import cvxpy as cp  # as above

    solver = _check_solver(options["solver"])
    opts = solver_options(solver, tol, max_iter)

    start = time.perf_counter()
    qp = forms.formulate(problem, form, fallback=options["form"] is None)
    x = cp.Variable(qp.q.size)
    contact = x >= 0 if qp.bounds else qp.G @ x <= qp.h
    model = cp.Problem(cp.Minimize(0.5 * cp.quad_form(x, qp.P, assume_PSD=True) + qp.q @ x),
                       [contact])
    with forms.warned(f"cvxpy/{solver}") as caught:
        try:
            data, chain, inverse_data = model.get_problem_data(solver, solver_opts=opts)
        except Exception as exc:
            raise SolverError(f"cvxpy could not compile the QP for {solver}: {exc}") from exc
        build_time = time.perf_counter() - start
        solver_error = False
        try:
            raw = chain.solve_via_data(model, data, warm_start=False, verbose=False,
                                       solver_opts=opts)
            model.unpack_results(raw, chain, inverse_data)
        except cp.error.SolverError:  # how cvxpy reports its status "solver_error"
            solver_error = True
        except Exception as exc:
            raise SolverError(f"cvxpy/{solver} raised {type(exc).__name__}: {exc}") from exc
        solve_time = time.perf_counter() - start - build_time
    if solver_error:
        return ContactSolution.failure(
            METHOD, problem, "failed", f"cvxpy/{solver}: solver_error",
            build_time=build_time, solve_time=solve_time,
            extras={"raw_status": "solver_error", "solver": solver, "backend_warnings": caught})
    raw_status = str(model.status)
    status = STATUS_MAP.get(raw_status, "failed")
    iterations = model.solver_stats.num_iters if model.solver_stats is not None else None
    z = None if qp.bounds or contact.dual_value is None else np.reshape(contact.dual_value, problem.m)
    return forms.solution_from(problem, qp, METHOD, status, x.value, z,
                               said_by=f"cvxpy/{solver}: {raw_status}",
                               extras={"raw_status": raw_status, "solver": solver,
                                       "backend_warnings": caught},
                               note=note, iterations=iterations, build_time=build_time,
                               solve_time=solve_time, tol=tol, polishing=polishing)


METHODS = (
    Method(name=METHOD, function=solve_cvxpy,
           summary="the QP as a cvxpy model (Clarabel by default; option solver)",
           requires=("cvxpy",), extra="", family="cvxpy", exact=False,
           typed_options=TYPED_OPTIONS),
)


__all__ = ["qp_solvers", "solver_options", "solve_cvxpy", "METHODS"]
