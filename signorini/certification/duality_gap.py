"""The duality gap of an answer, exactly, on a factorisation of K the method already holds.

The certificate (:mod:`signorini.certification.kkt`) bounds how far the energy of ``u`` is above
the optimum by ``J(u) − D(λ̂)`` (:func:`primal_dual_gap`): one back-solve of the method's own
factorisation when its matrix is this problem's K (:func:`same_matrix`) and its pinned dofs are
rows of N (:func:`pinned_rows`), else ``½ rᵀK⁻¹r`` from the problem's own factorisation. The
factorisations on offer to one certificate (the method's, the problem's cached one) are wrapped
once (:class:`Offers`), and each remembers what it solved (:class:`Remembering`) so that the
forward error's back-solve and the gap's, of opposite right-hand sides, cost one.
"""

from __future__ import annotations

import numpy as np

from signorini.numerics.active_set import selection_dofs
from signorini.problem.contact import ContactProblem, ContactSolution

#: a factorisation offered to the certificate is one of the problem's K when ``K x`` by both
#: agrees to this (relative, for a fixed random x: the two sum in different orders)
SAME_MATRIX_RTOL = 1e-12
#: pinned nodes whose best force is negative (round-off on a node touching with no force) are
#: released, a back-solve each; beyond this many the certificate gives up on the method's
#: factorisation and takes the problem's own way to K⁻¹
MAX_RELEASED = 16
#: right-hand sides a factorisation offered to the certificate remembers (see :class:`Remembering`)
REMEMBERED_SOLVES = 3


class Remembering:
    """A factorisation offered to one certificate, which remembers what it was asked.

    The forward error's first Newton step and the duality gap can solve the same system with
    opposite right-hand sides (the method's pinned set is the active set and λ is zero off
    it): a solve is linear and exactly odd in floating point, so a right-hand side that is
    minus one already solved gets minus that answer instead of a second solve — the numbers
    a second solve gives. Its pinned rows (:func:`pinned_rows`) are found once.
    """

    def __init__(self, problem: ContactProblem, factor):
        self.factor, self.solved = factor, []
        self.pinned = pinned_rows(problem, factor)

    def __getattr__(self, name: str):
        return getattr(self.factor, name)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        rhs = np.asarray(rhs)
        if rhs.ndim == 1:
            for asked, answer in self.solved:
                if np.array_equal(asked, -rhs):
                    return -answer
        answer = self.factor.solve(rhs)
        if rhs.ndim == 1:
            self.solved = [(rhs.copy(), answer.copy())] + self.solved[:REMEMBERED_SOLVES - 1]
        return answer


class Offers:
    """The factorisations on offer to one certificate — the method's, then the problem's cached
    one — each wrapped once in :class:`Remembering`."""

    def __init__(self, problem: ContactProblem, solution: ContactSolution):
        self.problem, self.solution, self.wrapped = problem, solution, {}

    def wrap(self, factor) -> Remembering:
        if id(factor) not in self.wrapped:
            self.wrapped[id(factor)] = (factor, Remembering(self.problem, factor))
        return self.wrapped[id(factor)][1]

    def __call__(self) -> list[Remembering]:
        return [self.wrap(f) for f in (self.solution.factor, self.problem.cached_factor)
                if f is not None]


def primal_dual_gap(problem: ContactProblem, u: np.ndarray, lam: np.ndarray, factors=(),
                Ku: np.ndarray | None = None) -> float:
    """``J(u) − D(λ̂)``: how far the energy of ``u`` can be above the optimum, exactly.

    ``D(μ) = min_v L(v, μ)`` is the dual function; for any ``μ ≥ 0``,
    ``D(μ) ≤ J* ≤ J(u)``. The dual point is ``λ̂ = λ⁺`` with its entries on
    the *pinned* rows ``C`` of a factorisation of K the method already holds
    (:class:`~signorini.numerics.active_set.PinnedFactor`: each such row bounds
    one dof, pinned; a plain factorisation of K pins none) replaced by their
    best values, those that maximise ``D`` over ``λ_C`` with the others fixed.
    Then, with ``r = Ku − f + N_Rᵀλ_R⁺`` (the stationarity residual without
    the pinned rows' forces), one back-solve of the pinned factorisation gives
    ``e`` with ``(Ke)_free = r_free`` and ``e_C = (N_C u − d_C)/n_C``;
    ``v = u − e`` minimises ``L(·, λ̂)`` with ``N_C v = d_C``, and
    ``λ̂_C = (Ke − r)_C / n_C``, so exactly::

        J(u) − D(λ̂) = λ̂ᵀ(d − Nu) + ½ eᵀKe.

    With nothing pinned this is the textbook ``λ⁺ᵀ(d − Nu) + ½ rᵀK⁻¹r``;
    pinning only ever tightens it (``D(λ̂) ≥ D(λ⁺)``). It is a bound when
    ``λ̂_C ≥ 0``; a pinned node whose best force is negative (round-off on a
    node touching with no force) is released, its row rejoining the others
    with force ``λ⁺``, and the identity evaluated again on the factorisation
    with those dofs freed by a Schur complement (one back-solve each; at most
    :data:`MAX_RELEASED`).

    ``factors`` are the factorisations on offer, tried in turn; one is used
    only when its matrix is this problem's K (``K x`` agrees for a random x)
    and its pinned dofs are rows of N that bound one dof each: the
    certificate trusts a method's linear algebra on the same K, never its
    numbers. With none usable, ``½ rᵀK⁻¹r`` comes from
    :meth:`ContactProblem.inverse_energy` (a factorisation of K, cached; from
    300k dofs Jacobi-preconditioned CG).
    """
    lam_plus = np.maximum(lam, 0.0)
    Ku = problem.K @ u if Ku is None else Ku
    for factor in factors:
        pinned = factor.pinned if isinstance(factor, Remembering) else pinned_rows(problem, factor)
        gap = None if pinned is None else _gap_on(problem, u, lam_plus, Ku, factor, *pinned)
        if getattr(factor, "on", None) and factor.on(problem.K, problem.N):  # a saddle point's
            gap = factor.gap(problem.K, problem.f, problem.N, problem.d, u, lam_plus, Ku)
        if gap is not None:
            return gap
    r = Ku - problem.f + problem.N.T @ lam_plus
    return float(lam_plus @ (problem.d - problem.N @ u)) + 0.5 * problem.inverse_energy(r)


def pinned_rows(problem: ContactProblem, factor) -> tuple[np.ndarray, np.ndarray] | None:
    """``(rows C, their coefficients n_C)`` of ``factor``'s pinned dofs, or None when unusable."""
    if getattr(factor, "fixed", None) is None or not same_matrix(problem.K, factor.matrix):
        return None
    fixed = np.asarray(factor.fixed, dtype=int)
    if fixed.size == 0:
        return fixed, np.zeros(0)
    dofs = selection_dofs(problem.N)
    if dofs is None:
        return None
    row_of = np.full(problem.n, -1)
    row_of[dofs] = np.arange(problem.m)
    rows = row_of[fixed]
    return None if np.any(rows < 0) else (rows, np.asarray(problem.N[rows, fixed]).ravel())


def same_matrix(K, other) -> bool:
    """``other`` is ``K`` up to summation order (see :data:`SAME_MATRIX_RTOL`)."""
    if other is K:
        return True
    if other is None or getattr(other, "shape", None) != K.shape or other.nnz != K.nnz:
        return False
    x = np.random.default_rng(0).uniform(0.5, 1.5, K.shape[0])
    y = K @ x
    scale = float(np.max(np.abs(y), initial=0.0)) or 1.0
    return bool(np.max(np.abs(y - other @ x), initial=0.0) <= SAME_MATRIX_RTOL * scale)


def _gap_on(problem: ContactProblem, u: np.ndarray, lam_plus: np.ndarray, Ku: np.ndarray,
            factor, rows: np.ndarray, coef: np.ndarray) -> float | None:
    """:func:`primal_dual_gap` on ``factor`` with its pinned ``rows``; None when it gives up."""
    fixed, K = factor.fixed, problem.K
    released = np.zeros(rows.size, dtype=bool)
    while True:
        held = rows[~released]
        lam_hat = lam_plus.copy()
        lam_hat[held] = 0.0
        r = Ku - problem.f + problem.N.T @ lam_hat
        rhs = r.copy()
        rhs[fixed] = np.where(released, 0.0, (problem.N[rows] @ u - problem.d[rows]) / coef)
        e = factor.solve(rhs)
        if released.any():  # the released dofs are free again: a Schur complement on them
            dofs = fixed[released]
            unit = np.zeros((problem.n, dofs.size))
            unit[dofs, np.arange(dofs.size)] = 1.0
            Z = factor.solve(unit)
            e += Z @ np.linalg.solve((K @ Z)[dofs], r[dofs] - (K @ e)[dofs])
        Ke = K @ e
        lam_hat[held] = (Ke - r)[fixed[~released]] / coef[~released]
        pulling = np.zeros(rows.size, dtype=bool)
        pulling[~released] = lam_hat[held] < 0
        if not pulling.any():
            return float(lam_hat @ (problem.d - problem.N @ u)) + 0.5 * float(e @ Ke)
        released |= pulling
        if released.sum() > MAX_RELEASED:
            return None


__all__ = ["MAX_RELEASED", "Offers", "REMEMBERED_SOLVES", "Remembering", "SAME_MATRIX_RTOL",
           "pinned_rows", "primal_dual_gap", "same_matrix"]
