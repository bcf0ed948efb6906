"""The condensed (dual) problem on the contact candidates.

With ``W = N K⁻¹ Nᵀ`` (the Delassus operator, m × m SPD) and
``b = N K⁻¹ f − d``, the gap of the candidates is ``g(λ) = Wλ − b`` and the
contact forces solve the linear complementarity problem

    λ ≥ 0,   Wλ − b ≥ 0,   λᵢ (Wλ − b)ᵢ = 0,

i.e. the bound-constrained QP ``min ½λᵀWλ − bᵀλ`` over ``λ ≥ 0``.
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp


#: the dense right-hand sides of one block of back-solves are kept to about this many bytes: the
#: backends copy them several times (PARDISO: ~4), so a wide block can cost several times the
#: memory of the factorisation itself (chosen from measurements, docs/calibration.md)
BLOCK_BYTES = 8e6


def delassus(N: sp.csr_matrix, factor, block: int | None = None) -> np.ndarray:
    """``W = N K⁻¹ Nᵀ`` by back-solves on blocks of ``block`` columns of ``Nᵀ``.

    Only W (m × m) is kept, never the n × m matrix ``K⁻¹Nᵀ``, which for a
    large or 3D model would dwarf the factorisation; ``block`` (default: as
    many columns as fit in :data:`BLOCK_BYTES`, 8 to 128) bounds the dense
    right-hand sides in flight.
    """
    m, n = N.shape
    if block is None:
        block = int(np.clip(BLOCK_BYTES // (8 * max(n, 1)), 8, 128))
    NT = sp.csc_matrix(N.T)
    W = np.empty((m, m))
    for first in range(0, m, block):
        last = min(first + block, m)
        W[:, first:last] = N @ factor.solve(NT[:, first:last].toarray())
    return 0.5 * (W + W.T)


def forces_on(W: np.ndarray, b: np.ndarray, active: np.ndarray) -> np.ndarray:
    """λ with ``W_AA λ_A = b_A`` on the active set A and zero off it (b: m, or m × k)."""
    lam = np.zeros(np.shape(b))
    if active.any():
        with warnings.catch_warnings():  # dependent rows make W_AA singular: the certificate judges λ
            warnings.simplefilter("ignore", sla.LinAlgWarning)
            lam[active] = sla.solve(W[np.ix_(active, active)], b[active], assume_a="pos")
    return lam


def _slack(lam: np.ndarray, gap: np.ndarray, b: np.ndarray) -> float:
    """How far ``(λ, g)`` is from ``λ ≥ 0, g ≥ 0``, relative to ``‖λ‖∞`` and ``‖b‖∞``."""
    def worst(x: np.ndarray, scale: float) -> float:
        return float(np.max(-x, initial=0.0)) / (scale if scale > 0 else 1.0)

    return max(worst(lam, float(np.max(np.abs(lam), initial=0.0))),
               worst(gap, float(np.max(np.abs(b), initial=0.0))))


class StillChanging(ArithmeticError):
    """The LCP's active set still changed after its step limit; ``lam`` is the last iterate."""

    def __init__(self, message: str, lam: np.ndarray):
        super().__init__(message)
        self.lam = lam


def solve_lcp(W: np.ndarray, b: np.ndarray, max_iter: int = 200,
              lam0: np.ndarray | None = None, tol: float = 0.0) -> tuple[np.ndarray, int]:
    """Primal-dual active set on ``min ½λᵀWλ − bᵀλ, λ ≥ 0``.

    The active set is ``A = {i : λᵢ − gᵢ > 0}`` with ``g = Wλ − b``; on A the
    gap is closed (``W_AA λ_A = b_A``), off A the force is zero. Stops when A
    repeats, or sooner when the answer on A meets the other conditions to
    ``tol`` (no force below ``−tol·‖λ‖∞``, no gap below ``−tol·‖b‖∞``: A
    repeating is this test at ``tol = 0``); returns ``(λ, iterations)``, or
    raises :class:`StillChanging` (an ``ArithmeticError`` with the last λ) when the active set
    keeps changing for ``max_iter`` steps.
    """
    m = len(b)
    lam = np.zeros(m) if lam0 is None else np.maximum(lam0, 0.0)
    active = None
    seen: set[bytes] = set()
    for iteration in range(1, max_iter + 1):
        gap = W @ lam - b
        new_active = (lam - gap) > 0
        if active is not None and (np.array_equal(new_active, active) or _slack(
                lam, gap, b) <= tol):
            return lam, iteration - 1
        if new_active.tobytes() in seen:
            lam, steps = least_index_lcp(W, b)
            return lam, iteration + steps
        seen.add(new_active.tobytes())
        active = new_active
        lam = forces_on(W, b, active)
    raise StillChanging(f"active set still changing after {max_iter} PDAS steps", lam)


def least_index_lcp(W: np.ndarray, b: np.ndarray, max_iter: int = 100_000) -> tuple[np.ndarray, int]:
    """Murty's least-index principal pivoting for ``λ ≥ 0, Wλ − b ≥ 0, λ·(Wλ − b) = 0``.

    Starting from the empty active set, each step flips the lowest-numbered
    node that breaks a condition (a negative force on the active set, or a
    negative gap off it). It terminates for every P-matrix, SPD W included
    (Murty 1974), though it may take many steps; it is the fallback when
    PDAS cycles.
    """
    m = len(b)
    active = np.zeros(m, dtype=bool)
    for step in range(1, max_iter + 1):
        lam = forces_on(W, b, active)
        gap = W @ lam - b
        force_tol = 1e-13 * max(float(np.max(np.abs(lam))), 1e-300)
        gap_tol = 1e-13 * max(float(np.max(np.abs(b))), 1e-300)
        wrong = np.nonzero((active & (lam < -force_tol)) | (~active & (gap < -gap_tol)))[0]
        if wrong.size == 0:
            return np.maximum(lam, 0.0), step
        active[wrong[0]] = ~active[wrong[0]]
    raise ArithmeticError(f"least-index pivoting did not finish in {max_iter} steps")


def delassus_max_eigenvalue(N: sp.csr_matrix, factor, rtol: float = 1e-6, max_iter: int = 500,
                            seed: int = 0, apply_W=None) -> tuple[float, int]:
    """``λ_max(W)`` of ``W = N K⁻¹ Nᵀ`` by power iteration.

    Each step applies W once: by one back-solve, or by ``apply_W`` when W is
    at hand. Returns the Rayleigh-quotient estimate (a lower bound of the
    true value) and the number of steps; stops when it changes by less than
    ``rtol``.
    """
    if apply_W is None:
        def apply_W(x):
            return N @ factor.solve(N.T @ x)
    rng = np.random.default_rng(seed)
    x = rng.standard_normal(N.shape[0])
    x /= np.linalg.norm(x)
    estimate = 0.0
    for step in range(1, max_iter + 1):
        y = apply_W(x)
        new_estimate, size = float(x @ y), float(np.linalg.norm(y))
        if abs(new_estimate - estimate) <= rtol * abs(new_estimate) or not 0.0 < size < np.inf:
            return new_estimate, step  # settled, or W x is zero or not finite: nothing to iterate
        x = y / size
        estimate = new_estimate
    return estimate, max_iter


__all__ = ["StillChanging", "delassus", "forces_on", "solve_lcp", "least_index_lcp", "delassus_max_eigenvalue",
           "BLOCK_BYTES"]
