"""The qpsolvers backends as one table: what each needs, how a relative tolerance and an
iteration limit translate into its own option names, which options it accepts, and how its raw
status maps to :data:`signorini.problem.contact.STATUSES`. The method that runs them:
:mod:`signorini.solvers.qp`.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import numpy as np

from signorini.solvers import forms
from signorini.solvers.options import Option, declare
from signorini.solvers.qp_reports import (Reader, read_clarabel, read_cvxopt, read_ecos, read_found,
                                          read_gurobi, read_info, read_quadprog, read_scs,
                                          solve_clarabel)

__all__ = ["BACKENDS", "BACKEND_BY_NAME", "COMMON_TYPES", "DEFAULT_MAX_DENSE_DOFS",
           "Backend", "FAILED", "MAX_ITER"]

log = logging.getLogger(__name__)

#: dense backends refuse problems with more free dofs than this (option ``max_dense_dofs``)
DEFAULT_MAX_DENSE_DOFS = 3000

#: the options every ``qp-*`` method takes besides its backend's own (None: the backend's
#: default form and polish)
COMMON_TYPES = declare(Option("max_dense_dofs", "positive_count", DEFAULT_MAX_DENSE_DOFS),
                       Option("form", "choice", None, choices=(None, *forms.FORMS)),
                       Option("polish", "bool", None))



def kinds(**names: tuple[str, ...]) -> tuple[Option, ...]:
    """A backend's own options by kind (:data:`signorini.solvers.options.KINDS`), as its
    documentation gives them: ``kinds(positive=("eps_abs",), count=("max_iter",))``."""
    return tuple(Option(name, kind) for kind, group in names.items() for name in group)


CONVERGED, INACCURATE, MAX_ITER, INFEASIBLE, FAILED = (
    "converged", "inaccurate", "max_iter", "infeasible", "failed")


@dataclass(frozen=True)
class Backend:
    """One qpsolvers backend: its options, tolerance translation and status map.

    ``tolerance`` turns a relative KKT tolerance into backend options (one
    translation per backend); ``max_iter_option`` receives ``max_iter``. ``statuses``
    maps the backend's raw status string to one of ours (anything it does not
    list is ``failed``), or is a function doing so. ``read`` extracts the raw
    status from a :class:`qpsolvers.Solution` and the warnings it raised.
    ``fixed`` are settings always passed; ``nest`` rewrites the settings
    before the call (MOSEK takes its parameters inside one dict); ``form`` is
    the default formulation (:data:`signorini.solvers.forms.FORMS`), chosen by
    tools/formulations.py's measurements (docs/formulations.md); a default dual
    falls back to primal when it cannot be built (K singular, m > max_dense_dofs);
    ``polish`` is the default of the option ``polish`` (docs/crosscheck.md);
    ``prints`` says the backend writes to stdout from C whatever its verbosity
    (its calls then run with the process's output sent nowhere); ``call``
    solves the qpsolvers problem instead of :func:`qpsolvers.solve_problem`.
    """

    name: str
    label: str
    summary: str
    modules: tuple[str, ...]
    read: Reader
    statuses: Mapping[str, str] | Callable[[str], str]
    options: tuple[Option, ...] = ()
    tolerance: Callable[[float], dict[str, Any]] | None = None
    max_iter_option: str | None = None
    dense: bool = False
    extra: str = "backends"
    fixed: Mapping[str, Any] = field(default_factory=dict)
    nest: Callable[[dict[str, Any]], dict[str, Any]] | None = None
    form: str = "primal"
    polish: bool = False
    prints: bool = False
    call: Callable[..., Any] | None = None

    @property
    def method_name(self) -> str:
        return f"qp-{self.name}"

    @property
    def typed_options(self) -> dict[str, Option]:
        """Every option its method takes, by name, with its kind."""
        return {**declare(*self.options), **COMMON_TYPES}

    def settings(self, tol: float | None, max_iter: int | None) -> dict[str, Any]:
        """Backend options meaning "relative KKT tolerance ``tol``, at most ``max_iter``"."""
        out: dict[str, Any] = {}
        if tol is not None:
            if self.tolerance is None:
                log.info("%s has no tolerance to set: tol=%g is ignored", self.label, tol)
            else:
                out.update(self.tolerance(tol))
        if max_iter is not None:
            if self.max_iter_option is None:
                log.info("%s has no iteration limit: max_iter=%d is ignored", self.label, max_iter)
            else:
                out[self.max_iter_option] = int(max_iter)
        return out

    def status(self, raw: str) -> str:
        """Our status for the backend's raw status string."""
        if callable(self.statuses):
            return self.statuses(raw)
        return self.statuses.get(raw, FAILED)


def _scs_status(raw: str) -> str:
    """SCS says "solved (inaccurate - reached max_iters)" when it ran out of iterations."""
    if raw == "solved":
        return CONVERGED
    if raw.startswith("solved") and "max_iters" in raw:
        return MAX_ITER
    if raw.startswith("solved"):
        return INACCURATE
    return INFEASIBLE if raw == "infeasible" else FAILED


def _mosek_nest(settings: dict[str, Any]) -> dict[str, Any]:
    """MOSEK (through CVXOPT) takes its parameters as one dict keyed by ``mosek.*param``."""
    import mosek  # optional backend: only when MOSEK runs

    params = dict(settings.pop("mosek", {}))
    for name, value in settings.items():
        group = mosek.dparam if hasattr(mosek.dparam, name) else mosek.iparam
        params[getattr(group, name)] = value
    return {"mosek": params}


# --- translating a relative tolerance ------------------------------------------------------


def _each(*names: str, bounds: tuple[float, float] = (0.0, np.inf),
          **flags: Any) -> Callable[[float], dict[str, Any]]:
    """Set every option in ``names`` to ``tol`` (clipped to ``bounds``), plus fixed ``flags``."""
    def translate(tol: float) -> dict[str, Any]:
        value = float(np.clip(tol, *bounds))
        return {**{name: value for name in names}, **flags}
    return translate


#: Clarabel's gap tolerance is never asked below this, near double precision: a floor of 1e-12
#: still left a node on the wrong side of the zone (chosen from measurements, docs/crosscheck.md);
#: where it cannot get there it says ``AlmostSolved``, which is ``inaccurate``, and polish
#: finishes the job
CLARABEL_GAP_FLOOR = 1e-14


def _clarabel_tolerance(tol: float) -> dict[str, Any]:
    """Feasibility at ``tol``; the duality gap (and κ/τ) at ``tol²``, floored at 1e-14.

    An interior point's gap is the complementarity product ``Σ sᵢzᵢ``: a gap
    of ``tol`` leaves a node with both a force and a gap of order ``√tol``,
    which is what the certificate's (linear) natural residual saw in
    Clarabel's answers, with a node on the wrong side of the zone's edge
    (docs/crosscheck.md). With the gap at ``tol²``, floored at :data:`CLARABEL_GAP_FLOOR`,
    the active set comes out right on the validation cases, in every form, and on the large
    primal benchmarks (docs/crosscheck.md, docs/bench-forms.md).
    """
    gap = max(tol * tol, CLARABEL_GAP_FLOOR)
    return {"tol_feas": tol, "tol_gap_abs": gap, "tol_gap_rel": gap, "tol_ktratio": gap}


def _highs_tolerance(tol: float) -> dict[str, Any]:
    """HiGHS's QP solver regularises the Hessian by ``qp_regularization_value`` (1e-7).

    That bounds its stationarity error whatever the feasibility tolerances say,
    so the regularisation shrinks with ``tol`` (never above HiGHS's default).
    """
    value = max(tol, 1e-10)  # HiGHS refuses tolerances below 1e-10
    return {"primal_feasibility_tolerance": value, "dual_feasibility_tolerance": value,
            "qp_regularization_value": min(1e-7, 0.1 * tol)}


# --- the table ------------------------------------------------------------------------------

BACKENDS: tuple[Backend, ...] = (
    Backend(
        "osqp", "OSQP", "OSQP (ADMM, first-order) through qpsolvers", ("osqp",),
        read_info,
        {"solved": CONVERGED, "solved inaccurate": INACCURATE,
         "maximum iterations reached": MAX_ITER, "primal infeasible": INFEASIBLE},
        options=kinds(
            positive=("rho", "sigma", "delta", "adaptive_rho_tolerance", "eps_abs", "eps_rel",
                      "eps_prim_inf", "eps_dual_inf", "time_limit"),
            fraction=("adaptive_rho_fraction",), number=("alpha",),
            count=("scaling", "adaptive_rho_interval", "max_iter", "check_termination",
                   "polish_refine_iter"),
            bool=("adaptive_rho", "scaled_termination", "check_dualgap", "polishing",
                  "warm_starting"),
            text=("linsys_solver",)),
        # OSQP's own polishing finishes its answer on its active set: at a tolerance of 1e-8
        # its raw λ is otherwise first-order accurate only (docs/crosscheck.md)
        tolerance=_each("eps_abs", "eps_rel", "eps_prim_inf", polishing=True),
        max_iter_option="max_iter", extra="", fixed={"raise_error": False}, prints=True,
        form="dual",  # the primal form fails to converge where the dual does (docs/formulations.md)
        polish=True),  # raw answers of validation cases are inaccurate at 1e-8, polished ones not
    Backend(
        "clarabel", "Clarabel", "Clarabel (interior point) through qpsolvers", ("clarabel",),
        read_clarabel,
        {"Solved": CONVERGED, "AlmostSolved": INACCURATE, "MaxIterations": MAX_ITER,
         "PrimalInfeasible": INFEASIBLE},
        options=kinds(
            positive=("time_limit", "tol_gap_abs", "tol_gap_rel", "tol_feas", "tol_infeas_abs",
                      "tol_infeas_rel", "tol_ktratio", "reduced_tol_gap_abs",
                      "reduced_tol_gap_rel", "reduced_tol_feas", "reduced_tol_infeas_abs",
                      "reduced_tol_infeas_rel", "reduced_tol_ktratio", "equilibrate_min_scaling",
                      "equilibrate_max_scaling", "min_switch_step_length",
                      "min_terminate_step_length", "static_regularization_constant",
                      "static_regularization_proportional", "dynamic_regularization_eps",
                      "dynamic_regularization_delta", "iterative_refinement_reltol",
                      "iterative_refinement_abstol", "iterative_refinement_stop_ratio"),
            fraction=("max_step_fraction", "linesearch_backtrack_step"),
            count=("max_iter", "equilibrate_max_iter", "max_threads",
                   "iterative_refinement_max_iter"),
            bool=("equilibrate_enable", "static_regularization_enable",
                  "dynamic_regularization_enable", "iterative_refinement_enable",
                  "presolve_enable"),
            text=("direct_kkt_solver", "direct_solve_method")),
        tolerance=_clarabel_tolerance, max_iter_option="max_iter", extra="",
        call=solve_clarabel,  # qpsolvers drops the iteration count
        polish=True),  # polished, the validation cases end converged and exact at 1e-8
    Backend(
        "proxqp", "ProxQP", "ProxQP (proximal augmented Lagrangian) through qpsolvers",
        ("proxsuite",), read_info,
        {"PROXQP_SOLVED": CONVERGED, "PROXQP_MAX_ITER_REACHED": MAX_ITER,
         "PROXQP_PRIMAL_INFEASIBLE": INFEASIBLE},
        options=kinds(
            positive=("eps_abs", "eps_rel", "rho", "mu_eq", "mu_in", "eps_duality_gap_abs",
                      "eps_duality_gap_rel"),
            number=("default_H_eigenvalue_estimate",), count=("max_iter",),
            bool=("compute_preconditioner", "check_duality_gap", "primal_infeasibility_solving"),
            text=("initial_guess", "sparse_backend")),
        tolerance=_each("eps_abs", "eps_rel", "eps_duality_gap_abs", "eps_duality_gap_rel",
                        check_duality_gap=True),  # without the gap test it stops early
        max_iter_option="max_iter"),
    Backend(
        "piqp", "PIQP", "PIQP (proximal interior point) through qpsolvers", ("piqp",),
        read_info,
        {"PIQP_SOLVED": CONVERGED, "PIQP_MAX_ITER_REACHED": MAX_ITER,
         "PIQP_PRIMAL_INFEASIBLE": INFEASIBLE},
        options=kinds(
            positive=("rho_init", "delta_init", "eps_abs", "eps_rel", "eps_duality_gap_abs",
                      "eps_duality_gap_rel", "infeasibility_threshold", "reg_lower_limit",
                      "reg_finetune_lower_limit", "iterative_refinement_eps_abs",
                      "iterative_refinement_eps_rel", "iterative_refinement_min_improvement_rate",
                      "iterative_refinement_static_regularization_eps",
                      "iterative_refinement_static_regularization_rel"),
            fraction=("tau",),
            count=("reg_finetune_primal_update_threshold", "reg_finetune_dual_update_threshold",
                   "max_iter", "max_factor_retires", "preconditioner_iter",
                   "iterative_refinement_max_iter"),
            bool=("check_duality_gap", "preconditioner_scale_cost",
                  "iterative_refinement_always_enabled"),
            text=("kkt_solver",)),
        tolerance=_each("eps_abs", "eps_rel", "eps_duality_gap_abs", "eps_duality_gap_rel"),
        max_iter_option="max_iter"),
    Backend(
        "scs", "SCS", "SCS (ADMM on the conic form, first-order) through qpsolvers", ("scs",),
        read_scs, _scs_status,
        options=kinds(
            positive=("time_limit_secs", "eps_abs", "eps_rel", "eps_infeas", "scale", "rho_x"),
            number=("alpha",), count=("max_iters", "acceleration_interval"),
            integer=("acceleration_lookback",), bool=("normalize", "adaptive_scale"),
            text=("linear_solver", "write_data_filename", "log_csv_filename")),
        tolerance=_each("eps_abs", "eps_rel"), max_iter_option="max_iters"),
    Backend(
        "ecos", "ECOS", "ECOS (interior point on an SOCP reformulation) through qpsolvers",
        ("ecos",), read_ecos,
        {"OPTIMAL": CONVERGED, "OPTIMAL_INACC": INACCURATE, "MAXIT": MAX_ITER,
         "PINF": INFEASIBLE},
        options=kinds(
            positive=("feastol", "abstol", "reltol", "feastol_inacc", "abstol_inacc",
                      "reltol_inacc"),
            count=("max_iters", "nitref")),
        tolerance=_each("abstol", "reltol", "feastol"), max_iter_option="max_iters",
        dense=True,  # qpsolvers densifies P and G and takes a Cholesky factor of P
        form="dual"),  # so the m × m dual, as DAQP (docs/formulations.md)
    Backend(
        "highs", "HiGHS", "HiGHS (active set QP) through qpsolvers", ("highspy",),
        read_found("kOptimal", "not optimal (qpsolvers does not pass HiGHS's model status on)"),
        {"kOptimal": CONVERGED},
        options=kinds(
            positive=("primal_feasibility_tolerance", "dual_feasibility_tolerance",
                      "optimality_tolerance", "kkt_tolerance", "qp_regularization_value",
                      "time_limit"),
            number=("objective_bound",),
            count=("qp_iteration_limit", "qp_nullspace_limit", "threads", "random_seed"),
            text=("presolve", "solver")),
        tolerance=_highs_tolerance, max_iter_option="qp_iteration_limit",
        form="dual"),  # primal and shifted give a wrong answer or none (docs/formulations.md)
    Backend(
        "daqp", "DAQP", "DAQP (dual active set, dense) through qpsolvers", ("daqp",),
        read_found("exitflag > 0", "exitflag <= 0 (qpsolvers does not pass the flag on)"),
        {"exitflag > 0": CONVERGED},
        options=kinds(
            positive=("primal_tol", "dual_tol", "zero_tol", "pivot_tol", "progress_tol",
                      "cycle_tol", "eps_prox", "eta_prox", "sing_tol", "refactor_tol",
                      "time_limit"),
            number=("fval_bound",), count=("iter_limit", "eq_reduction")),
        tolerance=_each("primal_tol", "dual_tol"), max_iter_option="iter_limit", dense=True,
        form="dual"),  # dense: the m × m dual, not n × n
    Backend(
        "quadprog", "quadprog", "quadprog (Goldfarb-Idnani dual active set, dense) through "
        "qpsolvers", ("quadprog",), read_quadprog,
        {"solved": CONVERGED, "no solution": INFEASIBLE},
        dense=True, form="dual"),  # no tolerance or iteration limit to set; dual as DAQP
    Backend(
        "qpalm", "QPALM", "QPALM (proximal augmented Lagrangian) through qpsolvers", ("qpalm",),
        read_info,
        {"solved": CONVERGED, "maximum iterations reached": MAX_ITER,
         "primal infeasible": INFEASIBLE},
        options=kinds(
            positive=("eps_abs", "eps_rel", "eps_abs_in", "eps_rel_in", "rho", "eps_prim_inf",
                      "eps_dual_inf", "theta", "delta", "sigma_max", "sigma_init", "gamma_init",
                      "gamma_upd", "gamma_max", "time_limit"),
            fraction=("max_rank_update_fraction",), number=("dual_objective_limit",),
            count=("max_iter", "inner_max_iter", "scaling", "reset_newton_iter", "ordering",
                   "factorization_method", "max_rank_update"),
            bool=("proximal", "nonconvex", "warm_start", "enable_dual_termination")),
        tolerance=_each("eps_abs", "eps_rel"), max_iter_option="max_iter"),
    Backend(
        "cvxopt", "CVXOPT", "CVXOPT (interior point) through qpsolvers", ("cvxopt",),
        read_cvxopt, {"optimal": CONVERGED},
        options=kinds(
            positive=("abstol", "reltol", "feastol"), count=("maxiters", "refinement")),
        tolerance=_each("abstol", "reltol", "feastol"), max_iter_option="maxiters"),
    Backend(
        "gurobi", "Gurobi", "Gurobi (barrier) through qpsolvers", ("gurobipy",),
        read_gurobi,
        {"OPTIMAL": CONVERGED, "SUBOPTIMAL": INACCURATE, "ITERATION_LIMIT": MAX_ITER,
         "INFEASIBLE": INFEASIBLE},
        options=kinds(
            positive=("FeasibilityTol", "OptimalityTol", "BarConvTol", "PSDTol", "TimeLimit"),
            count=("IterationLimit", "BarIterLimit", "Method", "Threads", "Presolve",
                   "NumericFocus", "Crossover", "BarHomogeneous", "ScaleFlag")),
        tolerance=_each("FeasibilityTol", "OptimalityTol", "BarConvTol", bounds=(1e-9, 1e-2)),
        max_iter_option="BarIterLimit", extra="gurobi"),
    Backend(
        "mosek", "MOSEK", "MOSEK (interior point) through qpsolvers and CVXOPT",
        ("mosek", "cvxopt"), read_cvxopt,
        {"optimal": CONVERGED, "primal infeasible": INFEASIBLE},
        options=kinds(
            any=("mosek",)),
        tolerance=_each("intpnt_qo_tol_rel_gap", "intpnt_qo_tol_pfeas", "intpnt_qo_tol_dfeas"),
        max_iter_option="intpnt_max_iterations", nest=_mosek_nest, extra="mosek"),
)

BACKEND_BY_NAME: dict[str, Backend] = {backend.name: backend for backend in BACKENDS}
