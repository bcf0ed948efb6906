"""What the certificate computes with K⁻¹: the forward error of the contact force (one Newton
correction on the active set) and the duality gap, on a factorisation the method already holds.

**The forward error.**
On an active set A the exact answer ``(u*, λ*)`` (``λ* = 0`` off A) solves the
saddle-point system ``M [u*; λ*_A] = [f; d_A]`` with::

    M = [ K    N_Aᵀ ]
        [ N_A  0    ]

For a candidate ``(u, λ)`` let ``λ̄`` be λ on A and 0 off it, and the residuals
``r = K u − f + N_Aᵀ λ̄_A`` and ``g = N_A u − d_A``. Then, exactly,
``(u*, λ*) = (u, λ̄) + (δu, δλ)`` with ``M [δu; δλ_A] = −[r; g]``: the error of λ is
``λ − λ* = (λ − λ̄) − δλ``. This is what a stationarity residual scaled by the load
cannot give: ``‖δλ‖ ≤ ‖M⁻¹‖ ‖(r, g)‖``, and ``‖M⁻¹‖`` (through the Delassus operator
``N_A K⁻¹ N_Aᵀ`` on A) can be large where ‖f‖ is huge and λ small — a nearly
incompressible body pushed by a prescribed displacement has a lifted load 10¹¹ times
its contact forces, so a residual of 10⁻⁵‖f‖ says nothing about λ.

The correction is computed in double precision, so it is itself only as good as
the residual ``(r, g)`` is above round-off and ``M`` is conditioned. A second Newton
step from ``(u, λ̄) + δ`` measures that: where double precision resolves the answer
on A, the second step is much smaller than the first; where it does not, both are
of the size of the noise. ``floor = ‖δλ₂‖∞ / ‖λ‖`` is what double precision can
vouch for on this system; the certificate vouches for λ to ``max(force, floor)``.

Cost: no factorisation. ``M`` is solved by the factorisation the method holds
(:class:`~signorini.numerics.active_set.PinnedFactor` or any object with its
interface: ``matrix``, ``fixed``, ``solve``), or the problem's cached one of K.
A factorisation with the dofs of A pinned solves M in one back-solve; each row in
which its pinned set and A differ costs one more back-solve (a bordered Schur
complement, as for the duality gap), and a plain factorisation of K costs
``|A|`` back-solves for the Delassus operator on A (``N_A K⁻¹ N_Aᵀ``); then one
back-solve per Newton step, when the bordering's solved columns fit in
:data:`BLOCK_FLOATS` floats and are kept (the border's correction is then a product),
else two. Beyond :data:`MAX_BORDER` such rows the estimate is not made (NaN).

A solve by an iterative method (an object with ``exact = False``: conjugate gradients
stopped at a relative residual) gives the first step to that residual, which is what
the force error needs; a second step would measure where the iteration stopped, not
double precision, so it is not taken and the floor is NaN.

**The duality gap.** ``J(u) − D(λ̂)`` bounds how far the energy of ``u`` is above the optimum
(:func:`primal_dual_gap`): one back-solve of the method's own factorisation when its matrix is
this problem's K (:func:`same_matrix`) and its pinned dofs are rows of N (:func:`pinned_rows`),
else ``½ rᵀK⁻¹r`` from the problem's own factorisation.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.sparse as sp

from signorini.numerics.active_set import selection_dofs

#: the certificate borders a factorisation with at most this many rows (back-solves) to reach
#: the active set's system; beyond, the forward error is not estimated
MAX_BORDER = 1000
#: floats of right-hand sides solved at once while bordering (bounds the memory: 160 MB)
BLOCK_FLOATS = 20_000_000


@dataclass(frozen=True)
class ForwardError:
    """The Newton correction on the active set, relative to ``scale`` (forces) and ‖u‖∞.

    ``force``: ``‖λ − λ*‖∞ / scale`` with ``λ* = λ̄ + δλ₁`` (the first step);
    ``displacement``: ``‖δu₁‖∞ / ‖u‖∞``; ``floor``: ``‖δλ₂‖∞ / scale``, the second
    step (how far double precision resolves λ on this system); ``back_solves`` what
    it cost. NaN when not estimated.
    """

    force: float
    displacement: float
    floor: float
    back_solves: int

    @classmethod
    def unknown(cls) -> "ForwardError":
        nan = float("nan")
        return cls(nan, nan, nan, 0)


class Counted:
    """A factorisation's ``solve`` that counts its right-hand sides."""

    def __init__(self, factor):
        self.factor, self.count = factor, 0

    def __call__(self, rhs: np.ndarray) -> np.ndarray:
        self.count += 1 if rhs.ndim == 1 else rhs.shape[1]
        return self.factor.solve(rhs)


def _blocks(solved: Callable[[np.ndarray], np.ndarray], k: int, n: int,
            reduce: Callable[[np.ndarray], np.ndarray]) -> tuple[np.ndarray, np.ndarray | None]:
    """``reduce(solved(j))`` stacked over blocks ``j`` of ``range(k)`` (bounded memory), and the
    solved columns themselves when they fit in one block (else None)."""
    block = max(1, min(k, BLOCK_FLOATS // max(n, 1)))
    if k <= block:
        columns = solved(np.arange(k)) if k else np.zeros((n, 0))
        return (reduce(columns) if k else np.zeros((0, 0))), columns
    parts = [reduce(solved(np.arange(start, min(start + block, k))))
             for start in range(0, k, block)]
    return np.hstack(parts), None


def _unit_solutions(solve: Callable, dofs: np.ndarray, n: int) -> np.ndarray:
    """The factor's solutions for a unit on each of ``dofs`` (n × |dofs|): those its owner kept
    (``kept``: dof → (solution for a value c there, c), as the contact-zone solver keeps its
    band's columns) read back, the others solved in one call."""
    kept = getattr(solve.factor, "kept", None) or {}
    out = np.empty((n, dofs.size))
    fresh = np.array([dof not in kept for dof in dofs], dtype=bool)
    if fresh.any():
        units = np.zeros((n, int(fresh.sum())))
        units[dofs[fresh], np.arange(units.shape[1])] = 1.0
        out[:, fresh] = solve(units)
    for column in np.flatnonzero(~fresh):
        solution, value = kept[dofs[column]]
        out[:, column] = solution / value
    return out


def _inverse(S: np.ndarray) -> np.ndarray | None:
    """``S⁻¹`` of a small dense border, or None when S is singular (rows of N on the active
    set that are zero, repeated or dependent: their forces are not unique)."""
    try:
        inverse = np.linalg.inv(S)
    except np.linalg.LinAlgError:
        return None
    return inverse if np.all(np.isfinite(inverse)) else None


def _pinned_system(K: sp.spmatrix, solve: Callable, fixed: np.ndarray, dofs: np.ndarray,
                   coef: np.ndarray):
    """``M⁻¹`` on the rows ``dofs`` (coefficients ``coef``) from a factor pinning ``fixed``.

    The factor gives x with ``x[fixed] = rhs[fixed]`` and ``(K x)[free] = rhs[free]``.
    M pins ``dofs`` instead: the dofs it pins beyond the factor's (P) take a load ρ
    that brings them to their value, those the factor pins beyond M's (Q) a value y
    that frees their load — one back-solve per dof of P and Q, once, none for a dof whose
    solution the factor's owner kept (:func:`_unit_solutions`).
    """
    n = K.shape[0]
    P = np.setdiff1d(dofs, fixed)
    Q = np.setdiff1d(fixed, dofs)
    border = np.concatenate([Q, P])
    k = border.size

    K = sp.csr_matrix(K)
    K_Q, K_rows = K[Q], K[dofs]  # the rows of K x it reads, not all of K x
    B, Z = _blocks(lambda j: _unit_solutions(solve, border[j], n), k, n,
                   lambda Z: np.vstack([K_Q @ Z, Z[P]]))
    lu = _inverse(B) if k else None  # k ≤ MAX_BORDER, dense and small
    if k and lu is None:
        return None, k

    def apply(r: np.ndarray, g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        value = np.zeros(n)
        value[dofs] = -g / coef
        rhs = -r.copy()
        rhs[fixed] = value[fixed]
        x = solve(rhs)
        if k:
            miss = np.concatenate([-r[Q] - K_Q @ x, value[P] - x[P]])
            if Z is None:
                rhs[border] += lu @ miss
                x = solve(rhs)
            else:  # the border's columns were kept: the correction is a product, not a solve
                x = x + Z @ (lu @ miss)
        return x, (-r[dofs] - K_rows @ x) / coef

    return apply, k


class WithDelassus:
    """A plain factorisation of K offered with the Delassus operator ``W = N K⁻¹ Nᵀ`` it made.

    The forward error then reads ``N_A K⁻¹ N_Aᵀ`` from W (no back-solves for it).
    """

    fixed = np.zeros(0, dtype=int)

    def __init__(self, factor, N: sp.csr_matrix, W: np.ndarray):
        self.factor, self.matrix, self.N, self.delassus = factor, factor.matrix, N, W

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self.factor.solve(b)


def _schur_system(K: sp.spmatrix, solve: Callable, N: sp.csr_matrix, rows: np.ndarray):
    """``M⁻¹`` from a plain factorisation of K, through ``S = N_A K⁻¹ N_Aᵀ`` (|A| back-solves,
    none when the factorisation comes with the Delassus operator of N, as :class:`WithDelassus`
    and a wrapper of one do)."""
    N_A = N[rows]
    NT = sp.csc_matrix(N_A.T)
    k = N_A.shape[0]
    offered, Z = solve.factor, None
    if getattr(offered, "delassus", None) is not None and offered.N.shape == N.shape \
            and (offered.N != N).nnz == 0:
        S = offered.delassus[np.ix_(rows, rows)]
    else:
        S, Z = _blocks(lambda j: solve(NT[:, j].toarray()), k, K.shape[0], lambda Z: N_A @ Z)
    lu = _inverse(S) if k else None
    if k and lu is None:  # dependent active rows: λ on them is not unique
        return None, k

    def apply(r: np.ndarray, g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x0 = solve(-r)
        if not k:
            return x0, np.zeros(0)
        mu = lu @ (N_A @ x0 + g)
        if Z is None:
            return solve(-r - NT @ mu), mu
        return x0 - Z @ mu, mu  # K⁻¹ N_Aᵀ was kept: no second solve

    return apply, k


def newton_system(K: sp.spmatrix, N: sp.csr_matrix, rows: np.ndarray, solve: Counted):
    """``(r, g) ↦ M⁻¹(−r, −g)`` on the rows ``rows`` by the factorisation behind ``solve``
    (pinned or plain); None when it cannot (more than :data:`MAX_BORDER` rows to border, rows
    that are dependent, or a pinned factorisation while the rows of N do not each bound one dof)."""
    if getattr(solve.factor, "newton", None) is not None:  # the active set's own system
        return solve.factor.newton(solve)
    fixed = np.asarray(solve.factor.fixed, dtype=int)
    if not fixed.size:
        return _schur_system(K, solve, N, rows)[0] if rows.size <= MAX_BORDER else None
    dofs = selection_dofs(N)
    if dofs is None or np.unique(dofs[rows]).size < rows.size \
            or np.setxor1d(dofs[rows], fixed).size > MAX_BORDER:
        return None
    return _pinned_system(K, solve, fixed, dofs[rows], np.asarray(N[rows, dofs[rows]]).ravel())[0]


def forward_error(K: sp.spmatrix, f: np.ndarray, N: sp.csr_matrix, d: np.ndarray, u: np.ndarray,
                  lam: np.ndarray, active: np.ndarray, factor, scale: float,
                  Ku: np.ndarray | None = None) -> ForwardError:
    """Two Newton steps on the active set ``active`` from ``(u, λ)`` with ``factor`` (see module;
    one when ``factor`` is an iterative solve).

    ``factor`` is a factorisation of K (plain or pinned on rows of N that bound
    one dof each); ``scale`` the force λ's error is measured against; ``Ku`` is K u when
    the caller has it.
    """
    solve = Counted(factor)
    rows = np.flatnonzero(active)
    apply = newton_system(K, N, rows, solve)
    if apply is None:
        return ForwardError.unknown()
    N_A, d_A = N[rows], d[rows]
    lam_bar = np.zeros_like(lam)
    lam_bar[rows] = lam[rows]

    def residuals(x, mu, Kx=None):
        return (K @ x if Kx is None else Kx) - f + N_A.T @ mu, N_A @ x - d_A

    du, dlam = apply(*residuals(u, lam_bar[rows], Ku))
    u1, lam1 = u + du, lam_bar[rows] + dlam
    floor = float("nan")
    if getattr(factor, "exact", True):  # an iterative solve's second step measures its own stop
        _, dlam2 = apply(*residuals(u1, lam1))
        floor = float(np.max(np.abs(dlam2), initial=0.0)) / scale
    corrected = lam_bar.copy()
    corrected[rows] = lam1
    u_norm = float(np.max(np.abs(u1), initial=0.0)) or 1.0
    force = float(np.max(np.abs(lam - corrected), initial=0.0)) / scale
    return ForwardError(force, float(np.max(np.abs(du), initial=0.0)) / u_norm, floor, solve.count)


# -- the duality gap ---------------------------------------------------------------------------

#: a factorisation offered to the certificate is one of the problem's K when ``K x`` by both
#: agrees to this (relative, for a fixed random x: the two sum in different orders)
SAME_MATRIX_RTOL = 1e-12
#: pinned nodes whose best force is negative (round-off on a node touching with no force) are
#: released, a back-solve each; beyond this many the certificate gives up on the method's
#: factorisation and takes the problem's own way to K⁻¹
MAX_RELEASED = 16

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
        pinned = factor.pinned if hasattr(factor, "pinned") else pinned_rows(problem, factor)
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


__all__ = ["MAX_BORDER", "MAX_RELEASED", "SAME_MATRIX_RTOL", "Counted", "ForwardError", "WithDelassus",
           "forward_error", "newton_system", "pinned_rows", "primal_dual_gap", "same_matrix"]
