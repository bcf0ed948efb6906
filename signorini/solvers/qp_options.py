"""The kinds of the QP backends' own options (:mod:`signorini.solvers.qp`), checked before a run.

Each backend option a ``qp-*`` method passes through to qpsolvers is declared here by kind
(:class:`signorini.solvers.options.Option`), so that ``--opt time_limit=-1`` or
``--opt eps_abs=abc`` is refused with one line before the problem reaches the backend. The
kinds follow each backend's documentation.
"""

from __future__ import annotations

from signorini.solvers.options import Option

POSITIVE = (
    # tolerances
    "eps_abs", "eps_rel", "eps_prim_inf", "eps_dual_inf", "eps_infeas", "eps_abs_in", "eps_rel_in",
    "eps_duality_gap_abs", "eps_duality_gap_rel", "eps_prox", "tol_gap_abs", "tol_gap_rel",
    "tol_feas", "tol_infeas_abs", "tol_infeas_rel", "tol_ktratio", "reduced_tol_gap_abs",
    "reduced_tol_gap_rel", "reduced_tol_feas", "reduced_tol_infeas_abs", "reduced_tol_infeas_rel",
    "reduced_tol_ktratio", "iterative_refinement_reltol", "iterative_refinement_abstol",
    "iterative_refinement_eps_abs", "iterative_refinement_eps_rel",
    "iterative_refinement_static_regularization_eps",
    "iterative_refinement_static_regularization_rel", "feastol", "abstol", "reltol",
    "feastol_inacc", "abstol_inacc", "reltol_inacc", "primal_feasibility_tolerance",
    "dual_feasibility_tolerance", "optimality_tolerance", "kkt_tolerance", "primal_tol",
    "dual_tol", "zero_tol", "pivot_tol", "progress_tol", "cycle_tol", "sing_tol", "refactor_tol",
    "FeasibilityTol", "OptimalityTol", "BarConvTol", "PSDTol", "adaptive_rho_tolerance",
    "infeasibility_threshold",
    # time limits (seconds)
    "time_limit", "time_limit_secs", "TimeLimit",
    # penalties, steps and scalings
    "rho", "sigma", "delta", "rho_init", "delta_init", "mu_eq", "mu_in", "rho_x", "scale",
    "theta", "sigma_max", "sigma_init", "gamma_init", "gamma_upd", "gamma_max", "eta_prox",
    "equilibrate_min_scaling", "equilibrate_max_scaling", "static_regularization_constant",
    "static_regularization_proportional", "dynamic_regularization_eps",
    "dynamic_regularization_delta", "iterative_refinement_stop_ratio", "reg_lower_limit",
    "reg_finetune_lower_limit", "qp_regularization_value", "min_switch_step_length",
    "min_terminate_step_length", "iterative_refinement_min_improvement_rate",
)
FRACTION = ("max_step_fraction", "linesearch_backtrack_step", "tau", "adaptive_rho_fraction",
            "max_rank_update_fraction")
#: any finite number: bounds on objectives, an eigenvalue estimate, OSQP's relaxation α ∈ (0, 2)
NUMBER = ("fval_bound", "objective_bound", "dual_objective_limit",
          "default_H_eigenvalue_estimate", "alpha")
COUNT = (
    "max_iter", "max_iters", "maxiters", "iter_limit", "IterationLimit", "BarIterLimit",
    "qp_iteration_limit", "qp_nullspace_limit", "inner_max_iter", "polish_refine_iter",
    "adaptive_rho_interval", "check_termination", "scaling", "equilibrate_max_iter",
    "iterative_refinement_max_iter", "preconditioner_iter", "max_factor_retires",
    "acceleration_interval", "nitref", "refinement", "max_threads", "threads", "Threads",
    "reset_newton_iter", "max_rank_update", "random_seed", "reg_finetune_primal_update_threshold",
    "reg_finetune_dual_update_threshold", "ordering", "factorization_method", "Method",
    "Presolve", "NumericFocus", "Crossover", "BarHomogeneous", "ScaleFlag", "eq_reduction",
)
#: SCS's Anderson lookback: negative values select type-I acceleration
INTEGER_ANY_SIGN = ("acceleration_lookback",)
BOOL = (
    "adaptive_rho", "check_dualgap", "scaled_termination", "warm_starting", "polishing",
    "check_duality_gap", "compute_preconditioner", "equilibrate_enable",
    "iterative_refinement_enable", "static_regularization_enable",
    "dynamic_regularization_enable", "presolve_enable", "iterative_refinement_always_enabled",
    "preconditioner_scale_cost", "normalize", "adaptive_scale", "proximal", "nonconvex",
    "warm_start", "enable_dual_termination", "primal_infeasibility_solving",
)
TEXT = ("linsys_solver", "direct_kkt_solver", "direct_solve_method", "kkt_solver",
        "linear_solver", "sparse_backend", "initial_guess", "solver", "presolve",
        "write_data_filename", "log_csv_filename")
#: MOSEK's parameters travel as one dict (qpsolvers' ``mosek=``), checked by MOSEK itself
ANY = ("mosek",)


def _kinds() -> dict[str, Option]:
    table: dict[str, Option] = {}
    for kind, names in (("positive", POSITIVE), ("fraction", FRACTION), ("number", NUMBER),
                        ("count", COUNT), ("integer", INTEGER_ANY_SIGN), ("bool", BOOL),
                        ("text", TEXT), ("any", ANY)):
        for name in names:
            if name in table:
                raise ValueError(f"QP option {name} declared twice")
            table[name] = Option(name, kind)
    return table


#: every backend option by name (names shared by backends mean the same kind in each)
BACKEND_OPTIONS: dict[str, Option] = _kinds()


def typed(names: tuple[str, ...], common: dict[str, Option]) -> dict[str, Option]:
    """The declared options of one backend: its own ``names`` and the options all share."""
    return {**{name: BACKEND_OPTIONS[name] for name in names}, **common}
