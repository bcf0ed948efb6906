"""KKT certificates, active sets and comparisons: computed here, never by a solver.

For ``min ½uᵀKu − fᵀu  s.t.  Nu ≤ d`` with multipliers ``λ`` every residual is
relative, so that the same threshold means the same thing in any units.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from signorini.problem import ContactProblem, ContactSolution

#: normalised force and gap below which a node counts as touching with zero force
WEAK_TOL = 1e-6
#: forces are judged against max(‖λ‖∞, FORCE_FLOOR · ‖f‖∞): with no contact at all,
#: λ is round-off and relative measures against ‖λ‖∞ alone would be meaningless
FORCE_FLOOR = 1e-5


def _inf_norm(x: np.ndarray) -> float:
    return float(np.max(np.abs(x))) if x.size else 0.0


def _positive(x: float) -> float:
    return x if x > 0 else 1.0


def force_scale(problem: ContactProblem, lam: np.ndarray) -> float:
    """``max(‖λ‖∞, FORCE_FLOOR · ‖f‖∞)``: the force against which forces are judged."""
    return _positive(max(_inf_norm(lam), FORCE_FLOOR * _inf_norm(problem.f)))


def gap_scale(problem: ContactProblem, u: np.ndarray) -> float:
    """Length against which gaps are judged: ``max(‖Nu‖∞, ‖d‖∞, ‖u‖∞)``.

    ``‖u‖∞`` keeps the scale meaningful when the contact nodes neither move
    nor start apart (a block resting on the flat: ``d = 0``, ``Nu = 0``).
    """
    return _positive(max(_inf_norm(problem.N @ u), _inf_norm(problem.d), _inf_norm(u)))


@dataclass(frozen=True)
class Certificate:
    """Relative KKT residuals of a candidate solution ``(u, λ)``.

    - ``primal``: ``max((Nu − d)⁺) / max(‖Nu‖∞, ‖d‖∞, ‖u‖∞)``
    - ``stationarity``: ``‖Ku − f + Nᵀλ‖∞ / ‖Nᵀλ‖∞``.
      The contact forces set the scale, not ``‖f‖∞ + ‖Nᵀλ‖∞``: the lifted
      load ``f`` sits on dofs next to the prescribed boundary and can be
      hundreds of times the largest nodal contact force, and an imbalance
      that is small against ``f`` can still move λ by much more than the
      tolerance.
    - ``dual_sign``: ``max((−λ)⁺) / ‖λ‖∞``
    - ``complementarity``: ``max |λᵢ (Nu − d)ᵢ| / (‖λ‖∞ · max(‖Nu‖∞, ‖d‖∞, ‖u‖∞))``
    - ``natural``: ``max |min(λ̃ᵢ, g̃ᵢ)|`` with ``λ̃ = λ/‖λ‖∞`` and
      ``g̃ = (d − Nu)/max(‖Nu‖∞, ‖d‖∞, ‖u‖∞)``: the natural (min-map) residual.
      The product form above lets a node keep both a force and a gap of
      ``√residual``; this one is linear in both, so it bounds how far λ and
      the active set can be off (times the conditioning of ``W``).
    - ``duality_gap``: ``|J(u) − D(λ)| / max(|J(u)|, |D(λ)|)`` with ``J`` the
      energy and ``D`` the dual function, evaluated as ``L(u, λ) − ½ rᵀK⁻¹r``
      with ``r`` the stationarity residual (one factorisation of K, cached, or
      CG from 300k dofs: see :meth:`ContactProblem.inverse_energy`).

    Force norms are floored at ``FORCE_FLOOR · ‖f‖∞`` so that a problem with
    no contact (λ = 0 up to round-off) is judged against its loads.
    Residuals are ``inf`` when ``u`` or ``λ`` is not finite.
    """

    primal: float
    stationarity: float
    dual_sign: float
    complementarity: float
    natural: float
    duality_gap: float

    def worst(self) -> tuple[str, float]:
        """The largest residual and its name."""
        items = {k: v for k, v in asdict(self).items() if not np.isnan(v)}
        name = max(items, key=lambda k: items[k])
        return name, items[name]

    def as_dict(self) -> dict[str, float]:
        return asdict(self)


def certificate(problem: ContactProblem, solution: ContactSolution,
                duality_gap: bool = True) -> Certificate:
    """Relative KKT residuals of ``solution`` for ``problem`` (see :class:`Certificate`).

    The result is kept on the solution (for these same arrays, problem and
    options): judging a solution and then reporting it costs one evaluation.
    """
    key = (id(problem), id(solution.u), id(solution.lam), duality_gap)
    kept = getattr(solution, "_certificate", None)
    if kept is not None and kept[0] == key:
        return kept[1]
    cert = _certificate(problem, solution, duality_gap)
    solution._certificate = (key, cert)
    return cert


def _certificate(problem: ContactProblem, solution: ContactSolution,
                 duality_gap: bool) -> Certificate:
    u, lam = solution.u, solution.lam
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(lam))):
        inf = float("inf")
        return Certificate(inf, inf, inf, inf, inf, inf)
    violation = problem.N @ u - problem.d
    scale_gap = gap_scale(problem, u)
    NT_lam = problem.N.T @ lam
    floor = FORCE_FLOOR * _inf_norm(problem.f)
    lam_norm = force_scale(problem, lam)
    primal = max(float(np.max(violation, initial=0.0)), 0.0) / scale_gap
    residual = problem.K @ u - problem.f + NT_lam
    stationarity = _inf_norm(residual) / _positive(max(_inf_norm(NT_lam), floor))
    dual_sign = max(float(np.max(-lam, initial=0.0)), 0.0) / lam_norm + 0.0
    complementarity = _inf_norm(lam * violation) / (lam_norm * scale_gap)
    natural = _inf_norm(np.minimum(lam / lam_norm, -violation / scale_gap))
    gap = float("nan")
    if duality_gap:
        # D(λ⁺) = L(u, λ⁺) − ½ rᵀK⁻¹r with r = ∇ᵤL(u, λ⁺): the dual function through the
        # residual, so the gap −λ⁺ᵀ(Nu − d) + ½ rᵀK⁻¹r has no cancellation of large terms
        lam_plus = np.maximum(lam, 0.0)
        r = problem.K @ u - problem.f + problem.N.T @ lam_plus
        primal_obj = problem.energy(u)
        lagrangian = primal_obj + float(lam_plus @ violation)
        dual_obj = lagrangian - 0.5 * problem.inverse_energy(r)
        gap = abs(primal_obj - dual_obj) / _positive(max(abs(primal_obj), abs(dual_obj)))
    return Certificate(primal, stationarity, dual_sign, complementarity, natural, gap)


ACTIVE, WEAK, INACTIVE = "active", "weak", "inactive"


def classify(problem: ContactProblem, solution: ContactSolution,
             weak_tol: float = WEAK_TOL) -> np.ndarray:
    """Label each candidate ``active``, ``inactive`` or ``weak`` (weakly active).

    With ``λ̃ = λ/‖λ‖∞`` and ``g̃ = (d − Nu)⁺ / max(‖Nu‖∞, ‖d‖∞, ‖u‖∞)``: a node is
    weakly active when both are at most ``weak_tol`` (it touches with zero
    force, so its membership of the active set is not determined); otherwise
    it is active when ``λ̃ > g̃`` and inactive when not. For an exact solution
    one of the two is zero; for an inexact one the larger decides.
    """
    u, lam = solution.u, solution.lam
    lam_n = np.maximum(lam, 0.0) / force_scale(problem, lam)
    gap_n = np.maximum(problem.gap(u), 0.0) / gap_scale(problem, u)
    labels = np.where(lam_n > gap_n, ACTIVE, INACTIVE).astype(object)
    labels[(lam_n <= weak_tol) & (gap_n <= weak_tol)] = WEAK
    return labels


def active_set(problem: ContactProblem, solution: ContactSolution,
               weak_tol: float = WEAK_TOL) -> np.ndarray:
    """Boolean mask of the (strongly) active candidates."""
    return classify(problem, solution, weak_tol) == ACTIVE


@dataclass(frozen=True)
class Comparison:
    """How far two solutions of one problem are apart.

    ``u_rel`` and ``lam_rel`` are ∞-norm differences relative to the larger
    norm; ``misclassified`` counts nodes active in one and inactive in the
    other (weakly active nodes of either are left out and counted in ``weak``).
    """

    u_rel: float
    lam_rel: float
    misclassified: int
    weak: int

    @property
    def same_active_set(self) -> bool:
        return self.misclassified == 0

    def as_dict(self) -> dict[str, float | int]:
        return asdict(self)


def _rel_diff(a: np.ndarray, b: np.ndarray) -> float:
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        return float("inf")
    return _inf_norm(a - b) / _positive(max(_inf_norm(a), _inf_norm(b)))


def compare(problem: ContactProblem, first: ContactSolution, second: ContactSolution,
            weak_tol: float = WEAK_TOL) -> Comparison:
    """Compare two solutions: displacements, multipliers and active sets."""
    u_rel = _rel_diff(first.u, second.u)
    lam_rel = _rel_diff(first.lam, second.lam)
    if not np.isfinite(lam_rel) or not np.isfinite(u_rel):
        return Comparison(u_rel, lam_rel, problem.m, 0)
    a, b = classify(problem, first, weak_tol), classify(problem, second, weak_tol)
    weak = (a == WEAK) | (b == WEAK)
    misclassified = int(np.sum((a != b) & ~weak))
    return Comparison(u_rel, lam_rel, misclassified, int(np.sum(weak)))
