"""Uzawa's algorithm, the source paper's method: projected gradient ascent on the dual.

With K factorised once, each iteration is one back-solve::

    u^k     = K⁻¹ (f − Nᵀ λ^k)
    λ^{k+1} = max(0, λ^k + ρ (N u^k − d))

The dual gradient ``N u − d`` is Lipschitz with constant ``λ_max(W)``, ``W = N K⁻¹ Nᵀ``; the
iteration converges iff ``0 < ρ < 2 / λ_max(W)``. By default ``ρ = step_fraction · 2 / λ_max``
with ``λ_max`` from power iteration. It stops when the relative primal infeasibility and
natural residual are below ``tol`` (stationarity and the sign of λ hold by construction), the
distance to the fixed point estimated from the observed contraction, ``‖Δλ‖ q / (1 − q)``, is
below ``DISTANCE_MARGIN · tol ‖λ‖`` (the paper's test on ``‖Δλ‖`` alone stops far from the
answer when the dual is ill-conditioned), and the KKT certificate, with the method's
factorisation and W, backs the answer at ``tol``. When it does not, the margin is halved and
the iteration goes on: the method stops certified, or at ``max_iter`` saying why.

With ``operator="delassus"`` (the default when m ≤ 2000) W is formed once by m back-solves
and each iteration costs a dense matvec instead of a back-solve; the iterates are the same.

With ``acceleration="nesterov"`` (the method ``uzawa-nesterov``) the step is taken from the
extrapolated point ``y = λ + β(λ − λ_prev)`` with FISTA's momentum and the gradient restart of
O'Donoghue & Candès (2015) (Kanno 2017 applies Nesterov's method to this dual); its step bound
is ``1/λ_max(W)``.

Option ``callback(iteration, λ, displacement)`` is called once per iteration with the
multipliers and a function ``λ ↦ u(λ)`` (one back-solve, paid by the callback that calls it).
"""

from __future__ import annotations

import functools
import time
from typing import Any

import numpy as np

from signorini.certification.inverse import WithDelassus
from signorini.certification.kkt import certificate, shortfall
from signorini.numerics.factor import factorize
from signorini.numerics.lcp import delassus, delassus_max_eigenvalue
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.solvers.base import Method, acceptance
from signorini.solvers.options import Option, declare, per_candidate, resolved, take_options

DEFAULTS = declare(
    Option("rho", "positive", in_units=True), Option("step_fraction", "positive", 0.9),
    Option("lam0", "vector", in_units=True),
    Option("divergence_factor", "positive", 1e8),
    Option("operator", "choice", "auto", choices=("auto", "delassus", "backsolve")),
    Option("callback", "callable", in_units=True),
    Option("acceleration", "choice", "none", choices=("none", "nesterov")))
#: the accelerated variant: FISTA's momentum needs ρ ≤ 1/λ_max(W), half the plain bound
NESTEROV_DEFAULTS = {**DEFAULTS, "step_fraction": Option("step_fraction", "positive", 0.5),
                     "acceleration": Option("acceleration", "choice", "nesterov",
                                            choices=("none", "nesterov"))}
DELASSUS_MAX_CANDIDATES = 2000
RATE_WINDOW = 20
#: stop when the estimated distance to the fixed point is below this fraction of tol ‖λ‖ (at 1
#: the forward error of λ lands just above tol: docs/certificate.md)
DISTANCE_MARGIN = 0.5


def dual_residuals(problem: ContactProblem, gap_violation: np.ndarray, Nu: np.ndarray,
                   lam: np.ndarray, u_norm: float) -> tuple[float, float]:
    """Relative primal infeasibility and natural residual (as in :mod:`signorini.certification.kkt`)."""
    scale = max(float(np.max(np.abs(Nu))), float(np.max(np.abs(problem.d))), u_norm) or 1.0
    lam_norm = float(np.max(np.abs(lam))) or 1.0
    primal = float(max(gap_violation.max(), 0.0)) / scale
    natural = float(np.max(np.abs(np.minimum(lam / lam_norm, -gap_violation / scale))))
    return primal, natural


def _distance_estimate(steps: list[float]) -> float:
    """``‖Δλ‖ q / (1 − q)`` with q the mean contraction of the last steps (inf if not contracting)."""
    if len(steps) <= RATE_WINDOW or steps[-1] == 0.0:
        return 0.0 if steps and steps[-1] == 0.0 else float("inf")
    earlier = steps[-1 - RATE_WINDOW]
    if earlier <= 0.0:
        return float("inf")
    q = (steps[-1] / earlier) ** (1.0 / RATE_WINDOW)
    return steps[-1] * q / (1.0 - q) if q < 1.0 else float("inf")


def _two_step_cycle(new_lam: np.ndarray, lam_prev: np.ndarray, steps: list[float]) -> bool:
    """True when λ comes back to where it was two steps ago while still taking big steps.

    Beyond the step bound the projection can keep λ bounded: it bounces
    between two points instead of growing (on Hertz's cylinder, where W has
    no negative entry, this is what happens), so divergence by size alone is
    never seen.
    """
    if len(steps) < 10 or steps[-1] == 0.0:
        return False
    size = float(np.max(np.abs(new_lam))) or 1.0
    back = float(np.max(np.abs(new_lam - lam_prev)))
    return back <= 1e-10 * size and steps[-1] > 1e-6 * size and steps[-2] > 1e-6 * size


def _operator(problem: ContactProblem, factor, choice: str):
    """The operator choice, ``λ ↦ N K⁻¹ (f − Nᵀλ)`` and ``x ↦ W x`` (None with back-solves)."""
    if choice == "auto":
        choice = "delassus" if problem.m <= DELASSUS_MAX_CANDIDATES else "backsolve"
    if choice == "backsolve":
        def normal_displacement(lam):
            return problem.N @ factor.solve(problem.f - problem.N.T @ lam)
        return choice, normal_displacement, None
    W = delassus(problem.N, factor)
    free = problem.N @ factor.solve(problem.f)
    return choice, (lambda lam: free - W @ lam), W


def _uncertified(problem: ContactProblem, lam: np.ndarray, u: np.ndarray, factor,
                 W: np.ndarray | None, tol: float) -> str | None:
    """Why the certificate (:func:`signorini.certification.kkt.certificate`, with this factorisation and W)
    does not back ``(u, λ)`` at ``tol``; None when it does."""
    offered = factor if W is None else WithDelassus(factor, problem.N, W)
    candidate = ContactSolution("uzawa", u, lam, "converged", factor=offered)
    return shortfall(certificate(problem, candidate), acceptance(tol))


# a step beyond the bound grows λ until it overflows: the loop reads the non-finite λ as
# diverged and says why, so NumPy's overflow warnings would only repeat it
@np.errstate(over="ignore", invalid="ignore")
def uzawa(problem: ContactProblem, *, tol: float | None = None, max_iter: int | None = None,
          _name: str = "uzawa", _defaults: dict[str, Any] = DEFAULTS,
          **options: Any) -> ContactSolution:
    """The paper's Uzawa iteration with one factorisation of K (optionally accelerated)."""
    opts = take_options(_name, options, _defaults)
    accelerated = opts["acceleration"] == "nesterov"
    tol, max_iter = resolved(_name, "dual", tol, max_iter)
    start = time.perf_counter()
    factor = factorize(problem.K)
    choice, normal_displacement, W = _operator(problem, factor, opts["operator"])
    apply_W = None if W is None else (lambda x: W @ x)

    def displacement(lam: np.ndarray) -> np.ndarray:
        return factor.solve(problem.f - problem.N.T @ lam)

    lam_max, power_steps = delassus_max_eigenvalue(problem.N, factor, apply_W=apply_W)
    # ρ (force per length), λ₀ and λ_max(W) (length per force) are given and reported in the
    # problem's own units; the method runs on the dimensionless problem, ρ in units of ``own``
    own = problem.scales.force / problem.scales.displacement
    if opts["rho"] is not None:
        rho = opts["rho"] / own
    else:
        rho = opts["step_fraction"] * 2.0 / lam_max
    divergence_factor = opts["divergence_factor"]
    build_time = time.perf_counter() - start
    lam0 = per_candidate(_name, "lam0", opts["lam0"], problem.m)
    lam = np.zeros(problem.m) if lam0 is None else np.maximum(lam0, 0) / problem.scales.force
    history: dict[str, list[float]] = {"primal": [], "natural": [], "step": []}
    status, message = "max_iter", f"not converged after {max_iter} iterations"
    limit = None
    iteration = 0
    u_norm = float(np.max(np.abs(displacement(lam))))  # refreshed before convergence is declared
    lam_prev, Nu_prev, momentum, restarts = lam, None, 1.0, 0
    margin, doubt = DISTANCE_MARGIN, None  # the stop estimate's margin, what the certificate said
    for iteration in range(1, max_iter + 1):
        Nu = normal_displacement(lam)
        violation = Nu - problem.d
        primal, natural = dual_residuals(problem, violation, Nu, lam, u_norm)
        kkt = max(primal, natural)
        lam_norm = float(np.max(lam)) or 1.0
        if kkt <= tol and _distance_estimate(history["step"]) <= margin * tol * lam_norm:
            u_norm = float(np.max(np.abs(displacement(lam))))
            primal, natural = dual_residuals(problem, violation, Nu, lam, u_norm)
            kkt = max(primal, natural)
        history["primal"].append(primal)
        history["natural"].append(natural)
        if opts["callback"] is not None:
            opts["callback"](iteration, lam, displacement)
        if kkt <= tol and _distance_estimate(history["step"]) <= margin * tol * lam_norm:
            doubt = _uncertified(problem, lam, displacement(lam), factor, W, tol)
            if doubt is None:
                status, message = "converged", f"KKT residual {kkt:.1e} ≤ {tol:.0e} ({choice} operator)"
                break
            if history["step"] and history["step"][-1] == 0.0:  # λ no longer moves: say why
                status, message = "inaccurate", f"λ stopped moving uncertified: {doubt}"
                break
            margin /= 2  # the estimate of the distance was short: ask it for more
        if accelerated and Nu_prev is not None:
            # FISTA: a projected gradient step from y = λ + β(λ − λ_prev); N u(y) is affine in y
            next_momentum = 0.5 * (1.0 + np.sqrt(1.0 + 4.0 * momentum ** 2))
            beta = (momentum - 1.0) / next_momentum
            y = lam + beta * (lam - lam_prev)
            new_lam = np.maximum(0.0, y + rho * (Nu + beta * (Nu - Nu_prev) - problem.d))
            momentum = next_momentum
            if float((y - new_lam) @ (new_lam - lam)) > 0.0:  # gradient restart (O'Donoghue–Candès)
                momentum, restarts = 1.0, restarts + 1
        else:
            new_lam = np.maximum(0.0, lam + rho * violation)
        history["step"].append(float(np.max(np.abs(new_lam - lam))))
        if not accelerated and _two_step_cycle(new_lam, lam_prev, history["step"]):
            status = "diverged"
            message = (f"stalled in a two-step cycle at iteration {iteration} (λ returns to the "
                       f"same value every other step): ρ = {rho * own:.3g} is beyond the bound "
                       f"2/λ_max(W) = {2 * own / lam_max:.3g}; lower rho or step_fraction")
            lam_prev, Nu_prev, lam = lam, Nu, new_lam
            break
        lam_prev, Nu_prev, lam = lam, Nu, new_lam
        size = float(np.max(lam))
        if limit is None and size > 0:
            limit = divergence_factor * size
        if not np.isfinite(size) or (limit is not None and size > limit):
            status = "diverged"
            why = (f"ρ = {rho * own:.3g} exceeds 2/λ_max(W) = {2 * own / lam_max:.3g}; lower "
                   "rho or step_fraction" if rho * lam_max >= 2.0 else
                   f"ρ = {rho * own:.3g} is within the step bound, so the dual is unbounded: no u "
                   "satisfies N u ≤ d (the constraints are infeasible); check N and d")
            message = (f"|λ| grew beyond {divergence_factor:.0e} × its first value at "
                       f"iteration {iteration}: {why}")
            break
    # the step bounds: FISTA needs ρ ≤ 1/λ_max(W), plain Uzawa ρ < 2/λ_max(W)
    bound = 1.0 if accelerated else 2.0
    beyond = rho * lam_max > bound * (1 + 1e-9) if accelerated else rho * lam_max >= bound
    if status == "max_iter" and doubt is not None:
        message += f"; its own stopping test held but the certificate did not: {doubt}"
    if status == "max_iter" and beyond:
        message += (f"; ρ·λ_max(W) = {rho * lam_max:.2f} {'>' if accelerated else '≥'} {bound:g}, "
                    "beyond the convergence bound: lower rho or step_fraction")
    u = displacement(lam)
    return ContactSolution(
        method=_name, u=u, lam=lam, status=status, message=message, iterations=iteration,
        build_time=build_time, solve_time=time.perf_counter() - start - build_time,
        history=history, factor=factor,
        extras={"rho": rho * own, "lambda_max": lam_max / own, "power_steps": power_steps,
                "rho_over_bound": rho * lam_max / 2.0, "operator": choice,
                "acceleration": opts["acceleration"], "restarts": restarts})


METHODS = (
    Method(name="uzawa", function=uzawa, family="dual", exact=False,
           summary="the paper's Uzawa iteration: projected gradient ascent on the dual",
           typed_options=DEFAULTS),
    Method(name="uzawa-nesterov", family="dual", exact=False,
           function=functools.partial(uzawa, _name="uzawa-nesterov", _defaults=NESTEROV_DEFAULTS),
           summary="accelerated Uzawa: FISTA momentum with gradient restart, ρ = 1/λ_max(W)",
           typed_options=NESTEROV_DEFAULTS),
)


__all__ = ["dual_residuals", "uzawa", "METHODS"]
