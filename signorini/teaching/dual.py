"""Duality made visible: the dual function, iteration histories and Uzawa paths.

For ``min ½uᵀKu − fᵀu  s.t.  Nu ≤ d`` the Lagrangian is

    L(u, λ) = ½uᵀKu − fᵀu + λᵀ(Nu − d),

minimised over u by ``u(λ) = K⁻¹(f − Nᵀλ)``. The dual function is its value there,

    D(λ) = L(u(λ), λ) = −½λᵀWλ + bᵀλ − ½fᵀK⁻¹f,   W = N K⁻¹ Nᵀ,   b = N K⁻¹ f − d,

concave, with gradient ``∇D(λ) = b − Wλ = N u(λ) − d`` (the penetration at u(λ)),
Lipschitz with constant ``λ_max(W)``. Weak duality: ``D(λ) ≤ J(u)`` for every
``λ ≥ 0`` and every *feasible* u; at the solution both are equal. Uzawa's method
is projected gradient ascent on D; PDAS solves the KKT system on a guessed
active set. This module evaluates D (densely, for problems small enough to
draw), records what a method does per iteration, and traces Uzawa's path.
It is the library side of the tutorials in ``docs/tutorials/``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from signorini.errors import InputError
from signorini.kkt import force_scale, gap_scale
from signorini.numerics.lcp import delassus, solve_lcp
from signorini.problem import ContactProblem, ContactSolution
from signorini.solvers.registry import solve

#: the dense dual builds W (m × m) by m back-solves: refuse larger problems
MAX_DENSE_CANDIDATES = 2000
#: the recorder keeps every iterate λ when there are at most this many candidates
MAX_RECORDED_MULTIPLIERS = 50


def lagrangian(problem: ContactProblem, u: np.ndarray, lam: np.ndarray) -> float:
    """``L(u, λ) = ½uᵀKu − fᵀu + λᵀ(Nu − d)``.

    At ``u = u(λ) = K⁻¹(f − Nᵀλ)`` this is the dual function ``D(λ)``.
    """
    u = np.asarray(u, dtype=float)
    lam = np.asarray(lam, dtype=float)
    return float(problem.energy(u) + lam @ (problem.N @ u - problem.d))


@dataclass(frozen=True)
class DenseDual:
    """The dual function written with the Delassus operator, for small m.

    ``D(λ) = −½λᵀWλ + bᵀλ + c`` with ``W = N K⁻¹ Nᵀ``, ``b = N K⁻¹ f − d`` and
    ``c = −½fᵀK⁻¹f`` (the unconstrained minimum of the energy, ``D(0)``).
    Its gradient ``b − Wλ`` is the penetration ``N u(λ) − d``; it is Lipschitz
    with constant ``λ_max(W)``, so projected gradient ascent with a fixed step
    ρ converges when ``0 < ρ < 2/λ_max(W)``.
    """

    W: np.ndarray
    b: np.ndarray
    constant: float

    @property
    def m(self) -> int:
        """Number of contact candidates."""
        return int(self.b.size)

    def __call__(self, lam: np.ndarray) -> np.ndarray | float:
        """``D(λ)`` for one ``λ`` of shape (m,) or a stack of shape (..., m)."""
        lam = np.asarray(lam, dtype=float)
        if lam.shape[-1:] != (self.m,):
            raise InputError(f"λ must have a last axis of length {self.m}, got shape {lam.shape}")
        values = -0.5 * np.einsum("...i,ij,...j->...", lam, self.W, lam) + lam @ self.b \
            + self.constant
        return float(values) if np.ndim(values) == 0 else values

    def gradient(self, lam: np.ndarray) -> np.ndarray:
        """``∇D(λ) = b − Wλ = N u(λ) − d`` (the penetration at ``u(λ)``)."""
        return self.b - np.asarray(lam, dtype=float) @ self.W

    @property
    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of W in increasing order (W is symmetric positive definite)."""
        return np.linalg.eigvalsh(self.W)

    @property
    def lipschitz(self) -> float:
        """``λ_max(W)``, the Lipschitz constant of ``∇D``."""
        return float(self.eigenvalues[-1])

    @property
    def step_bound(self) -> float:
        """``2/λ_max(W)``: Uzawa converges for every fixed step below it."""
        return 2.0 / self.lipschitz

    @property
    def condition_number(self) -> float:
        """``κ(W) = λ_max/λ_min``: Uzawa's iteration count grows like κ."""
        eig = self.eigenvalues
        return float(eig[-1] / eig[0])

    def maximiser(self) -> np.ndarray:
        """``argmax D(λ)`` over ``λ ≥ 0``: the contact forces (exact, dense active set)."""
        lam, _ = solve_lcp(self.W, self.b)
        return lam

    def unconstrained_maximiser(self) -> np.ndarray:
        """``W⁻¹b``: where D peaks without the sign constraint (it may have λᵢ < 0)."""
        return np.linalg.solve(self.W, self.b)


def dense_dual(problem: ContactProblem, *,
               max_candidates: int = MAX_DENSE_CANDIDATES) -> DenseDual:
    """The dual function of ``problem`` as ``−½λᵀWλ + bᵀλ − ½fᵀK⁻¹f``.

    ``W = N K⁻¹ Nᵀ`` is formed by m back-solves with the problem's cached
    factorisation of K.

    Raises
    ------
    InputError
        The problem has more than ``max_candidates`` contact candidates
        (W is dense, m × m).
    """
    if problem.m > max_candidates:
        raise InputError(f"dense_dual: {problem.m} contact candidates exceed max_candidates="
                         f"{max_candidates} (W is a dense m × m matrix): evaluate "
                         "problem.dual_objective(λ) point by point instead")
    factor = problem.factor()
    W = delassus(problem.N, factor)
    free = factor.solve(problem.f)
    return DenseDual(W=W, b=problem.N @ free - problem.d, constant=float(-0.5 * problem.f @ free))


@dataclass(frozen=True)
class Objectives:
    """Primal objective ``J(u) = ½uᵀKu − fᵀu`` and dual objective ``D(λ)`` of one pair.

    ``gap = J(u) − D(λ)`` is ≥ 0 when u is feasible and λ ≥ 0 (weak duality) and
    0 at the solution.
    """

    primal: float
    dual: float

    @property
    def gap(self) -> float:
        return self.primal - self.dual


def objectives(problem: ContactProblem, u: np.ndarray, lam: np.ndarray) -> Objectives:
    """``J(u)`` and ``D(λ)`` of any pair, e.g. the final point of a QP solver.

    ``D`` is evaluated at ``λ`` itself (one back-solve with the cached factor
    of K), not at ``u``: for a pair that is not a Lagrangian minimiser the two
    numbers are independent.
    """
    return Objectives(problem.energy(np.asarray(u, dtype=float)),
                      problem.dual_objective(np.asarray(lam, dtype=float)))


@dataclass(frozen=True)
class IterationHistory:
    """What a method did, iteration by iteration (arrays of length k, one entry per call).

    Attributes
    ----------
    iteration : the method's iteration numbers.
    primal : ``J(u_k) = ½u_kᵀKu_k − fᵀu_k``.
    dual : ``D(λ_k) = L(u_k, λ_k)`` (u_k minimises the Lagrangian for λ_k).
    primal_infeasibility : ``max((Nu_k − d)⁺) / max(‖Nu_k‖∞, ‖d‖∞, ‖u_k‖∞)``.
    dual_infeasibility : ``max((−λ_k)⁺) / ‖λ_k‖∞`` (a negative, i.e. pulling, contact force).
    stationarity : ``‖Ku_k − f + Nᵀλ_k‖∞ / max(‖f‖∞, ‖Nᵀλ_k‖∞)``: zero when u_k = u(λ_k).
    active : (k, m) booleans, ``λ_k > 0``: the nodes carrying a contact force.
    multipliers : (k, m) iterates λ_k, or None when they were not kept.
    """

    iteration: np.ndarray
    primal: np.ndarray
    dual: np.ndarray
    primal_infeasibility: np.ndarray
    dual_infeasibility: np.ndarray
    stationarity: np.ndarray
    active: np.ndarray
    multipliers: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.iteration.size)

    @property
    def gap(self) -> np.ndarray:
        """``J(u_k) − D(λ_k) = λ_kᵀ(d − Nu_k)``: negative while u_k penetrates where λ_k pushes."""
        return self.primal - self.dual

    def misclassified(self, final_active: np.ndarray) -> np.ndarray:
        """Per iteration, how many nodes differ from ``final_active`` (a boolean mask)."""
        return np.sum(self.active != np.asarray(final_active, dtype=bool), axis=1)

    def active_set_found_at(self, final_active: np.ndarray) -> int | None:
        """The first iteration from which the active set equals ``final_active`` for good.

        None when the last recorded active set still differs.
        """
        wrong = self.misclassified(final_active) > 0
        if wrong.size == 0 or wrong[-1]:
            return None
        last_wrong = np.nonzero(wrong)[0]
        first_right = 0 if last_wrong.size == 0 else int(last_wrong[-1]) + 1
        return int(self.iteration[first_right])


class IterationRecorder:
    """Plugs into the ``callback`` option of ``uzawa`` and ``pdas`` and records each iterate.

    For every iterate ``(u_k, λ_k)`` it stores the primal objective
    ``J(u_k) = ½u_kᵀKu_k − fᵀu_k``, the dual objective ``D(λ_k) = L(u_k, λ_k)``,
    their gap ``J − D = λ_kᵀ(d − Nu_k)``, the relative primal and dual
    infeasibilities, the active set ``{i : λ_k,i > 0}`` and, for small m,
    ``λ_k`` itself. Both methods hand over a Lagrangian minimiser
    ``u_k = K⁻¹(f − Nᵀλ_k)`` (Uzawa by construction, PDAS because its
    saddle-point system is ``Ku + N_Aᵀλ_A = f``), so ``L(u_k, λ_k)`` is the dual
    function; ``stationarity`` records how exactly that holds.

    Examples
    --------
    >>> recorder = IterationRecorder(problem)
    >>> solution = solve(problem, "uzawa", callback=recorder.uzawa_callback)
    >>> history = recorder.history()
    """

    def __init__(self, problem: ContactProblem, *, keep_multipliers: bool | None = None):
        self.problem = problem
        self.keep_multipliers = (problem.m <= MAX_RECORDED_MULTIPLIERS
                                 if keep_multipliers is None else bool(keep_multipliers))
        self._rows: dict[str, list[Any]] = {name: [] for name in (
            "iteration", "primal", "dual", "primal_infeasibility", "dual_infeasibility",
            "stationarity", "active", "multipliers")}

    def record(self, iteration: int, u: np.ndarray, lam: np.ndarray) -> None:
        """Record one iterate; ``u`` must minimise the Lagrangian for ``lam``."""
        problem = self.problem
        u = np.asarray(u, dtype=float)
        lam = np.array(lam, dtype=float)
        NT_lam = problem.N.T @ lam
        violation = problem.N @ u - problem.d
        residual = problem.K @ u - problem.f + NT_lam
        stationarity_scale = max(float(np.max(np.abs(problem.f), initial=0.0)),
                                 float(np.max(np.abs(NT_lam), initial=0.0))) or 1.0
        rows = self._rows
        rows["iteration"].append(int(iteration))
        rows["primal"].append(problem.energy(u))
        rows["dual"].append(lagrangian(problem, u, lam))
        rows["primal_infeasibility"].append(
            max(float(np.max(violation, initial=0.0)), 0.0) / gap_scale(problem, u))
        rows["dual_infeasibility"].append(
            max(float(np.max(-lam, initial=0.0)), 0.0) / force_scale(problem, lam) + 0.0)
        rows["stationarity"].append(float(np.max(np.abs(residual), initial=0.0)) / stationarity_scale)
        rows["active"].append(lam > 0)
        if self.keep_multipliers:
            rows["multipliers"].append(lam)

    def uzawa_callback(self, iteration: int, lam: np.ndarray,
                       displacement: Callable[[np.ndarray], np.ndarray]) -> None:
        """The ``callback`` of ``uzawa``: ``callback(iteration, λ, λ ↦ u(λ))`` (one back-solve)."""
        self.record(iteration, displacement(lam), lam)

    def pdas_callback(self, iteration: int, u: np.ndarray, lam: np.ndarray) -> None:
        """The ``callback`` of ``pdas``: ``callback(iteration, u, λ)``."""
        self.record(iteration, u, lam)

    def history(self) -> IterationHistory:
        """Everything recorded so far, as arrays."""
        rows, m = self._rows, self.problem.m
        return IterationHistory(
            iteration=np.asarray(rows["iteration"], dtype=int),
            primal=np.asarray(rows["primal"], dtype=float),
            dual=np.asarray(rows["dual"], dtype=float),
            primal_infeasibility=np.asarray(rows["primal_infeasibility"], dtype=float),
            dual_infeasibility=np.asarray(rows["dual_infeasibility"], dtype=float),
            stationarity=np.asarray(rows["stationarity"], dtype=float),
            active=np.asarray(rows["active"], dtype=bool).reshape(-1, m),
            multipliers=(np.asarray(rows["multipliers"], dtype=float).reshape(-1, m)
                         if self.keep_multipliers else None))


#: the methods that accept a ``callback`` option, and the recorder's matching method
_CALLBACKS = {"uzawa": "uzawa_callback", "pdas": "pdas_callback"}


def solve_recorded(problem: ContactProblem, method: str, *, tol: float | None = None,
                   max_iter: int | None = None, keep_multipliers: bool | None = None,
                   **options: Any) -> tuple[ContactSolution, IterationHistory]:
    """Solve with ``uzawa`` or ``pdas`` and record every iterate (see :class:`IterationRecorder`).

    Runs :func:`signorini.solvers.registry.solve` (so the status is judged by
    the KKT certificate) with the recorder as the method's ``callback``.

    Raises
    ------
    InputError
        ``method`` has no ``callback`` option (QP backends report only their final point).
    """
    if method not in _CALLBACKS:
        raise InputError(f"solve_recorded: method {method!r} cannot report its iterates; "
                         f"choose one of {', '.join(sorted(_CALLBACKS))} (for a QP solver "
                         "use objectives(problem, solution.u, solution.lam) on its final point)")
    if "callback" in options:
        raise InputError("solve_recorded sets the callback itself: drop the option 'callback'")
    recorder = IterationRecorder(problem, keep_multipliers=keep_multipliers)
    solution = solve(problem, method, tol=tol, max_iter=max_iter,
                     callback=getattr(recorder, _CALLBACKS[method]), **options)
    return solution, recorder.history()


@dataclass(frozen=True)
class UzawaPath:
    """The iterates of Uzawa's method ``λ_{k+1} = max(0, λ_k + ρ(Nu(λ_k) − d))``.

    Attributes
    ----------
    rho : the fixed step ρ.
    lambda_max : ``λ_max(W)``, exact (dense eigenvalues of W).
    multipliers : (k + 1, m) the iterates ``λ_0 … λ_k``.
    trial : (k, m) the unprojected points ``λ_j + ρ(Nu(λ_j) − d)``; where one has a
        negative entry, the projection ``max(0, ·)`` moved it back onto ``λ ≥ 0``.
    status, message : what the ``uzawa`` method reported.
    """

    rho: float
    lambda_max: float
    multipliers: np.ndarray
    trial: np.ndarray
    status: str
    message: str = ""
    extras: dict[str, Any] = field(default_factory=dict)

    @property
    def step_bound(self) -> float:
        """``2/λ_max(W)``."""
        return 2.0 / self.lambda_max

    @property
    def step_ratio(self) -> float:
        """``ρ / (2/λ_max)``: below 1 the iteration converges."""
        return self.rho / self.step_bound

    @property
    def projected(self) -> np.ndarray:
        """Per step, whether the projection onto ``λ ≥ 0`` changed the trial point."""
        return np.any(self.trial < 0, axis=1)

    def distance(self, target: np.ndarray) -> np.ndarray:
        """``‖λ_k − target‖₂`` for every iterate."""
        return np.linalg.norm(self.multipliers - np.asarray(target, dtype=float), axis=1)


def uzawa_path(problem: ContactProblem, rho: float | None = None, *,
               step_ratio: float | None = None, iterations: int = 50,
               lam0: np.ndarray | None = None, tol: float = 1e-12) -> UzawaPath:
    """Trace Uzawa's iterates on a small problem for one fixed step.

    Give either ``rho`` or ``step_ratio = ρ·λ_max(W)/2`` (so 1 is the
    convergence bound ``ρ = 2/λ_max``). Runs the package's ``uzawa`` method
    with that step for at most ``iterations`` steps from ``lam0`` (default
    0), recording each iterate through its callback; the path stops early
    when the method converges to ``tol`` or reports divergence.

    Raises
    ------
    InputError
        Neither or both of ``rho`` and ``step_ratio`` given, or not positive;
        too many candidates for the dense ``λ_max``.
    """
    if (rho is None) == (step_ratio is None):
        raise InputError("uzawa_path: give exactly one of rho and step_ratio")
    lambda_max = dense_dual(problem).lipschitz
    if rho is None:
        if not (np.isfinite(step_ratio) and step_ratio > 0):
            raise InputError(f"uzawa_path: step_ratio={step_ratio!r} must be a positive number")
        rho = float(step_ratio) * 2.0 / lambda_max
    if not (np.isfinite(rho) and rho > 0):
        raise InputError(f"uzawa_path: rho={rho!r} must be a positive number")
    iterates: list[np.ndarray] = []
    trials: list[np.ndarray] = []

    def callback(iteration: int, lam: np.ndarray, displacement) -> None:
        lam = np.array(lam, dtype=float)
        iterates.append(lam)
        trials.append(lam + rho * (problem.N @ displacement(lam) - problem.d))

    options: dict[str, Any] = {"rho": float(rho), "callback": callback}
    if lam0 is not None:
        options["lam0"] = np.asarray(lam0, dtype=float)
    solution = solve(problem, "uzawa", tol=tol, max_iter=iterations, **options)
    if solution.status != "converged" and np.all(np.isfinite(solution.lam)):
        iterates.append(np.array(solution.lam, dtype=float))  # the last step, not seen by the callback
    trial = np.asarray(trials, dtype=float).reshape(-1, problem.m)[:max(len(iterates) - 1, 0)]
    return UzawaPath(rho=float(rho), lambda_max=lambda_max,
                     multipliers=np.asarray(iterates, dtype=float).reshape(-1, problem.m),
                     trial=trial, status=solution.status, message=solution.message,
                     extras={"iterations": solution.iterations})
