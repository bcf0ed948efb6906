"""The saddle-point system of one active set, ``[K N_Aᵀ; N_A 0]``, factorised once (LU).

An active-set method whose rows do not each bound one dof (two bodies' rows on
the master's dofs, obstacles that meet) solves this system at each step. The
factorisation of the final active set also serves the certificate
(:mod:`signorini.certification.kkt`), which would otherwise factorise K once more and solve
it |A| times for the Delassus operator ``N_A K⁻¹ N_Aᵀ``:

- the forward error's Newton steps on A are solves of this very matrix
  (:meth:`SaddlePoint.newton`: one back-solve a step);
- the duality gap's dual point: with ``r = Ku − f + N_Rᵀλ⁺_R`` (R the rows off A),
  one solve gives ``e`` and ``λ̂_A`` with ``Ke − N_Aᵀλ̂_A = r``, ``N_A e = N_A u − d_A``;
  ``v = u − e`` minimises ``L(·, λ̂)`` on ``N_A v = d_A``, λ̂_A maximises the dual
  function over the rows of A with the others at λ⁺, and exactly
  ``J(u) − D(λ̂) = λ̂ᵀ(d − Nu) + ½ eᵀKe`` (:meth:`SaddlePoint.gap`), a bound when λ̂_A ≥ 0.
"""

from __future__ import annotations

import copy
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from signorini.numerics.work import count, count_solves

__all__ = ["SaddlePoint"]


class SaddlePoint:
    """The factorised saddle-point matrix ``[K N_Aᵀ; N_A 0]`` of one active set (LU).

    Its constraint rows are scaled by ``s = mean |diag K|``, so that both blocks
    are of one size in any units (``λ = s μ``). ``matrix`` is K and ``N`` the rows
    of all candidates, so that the certificate knows whose system it is;
    :meth:`in_units` the same factorisation for ``k K`` (a problem whose view a method solved).
    """

    def __init__(self, K: sp.spmatrix, N: sp.spmatrix, active: np.ndarray):
        self.matrix, self.N, self.active, self.n = K, N, active.copy(), K.shape[0]
        N_A = N[active]
        self.scale = float(np.mean(np.abs(K.diagonal()))) or 1.0
        system = sp.bmat([[K, self.scale * N_A.T], [self.scale * N_A, None]], format="csc")
        count("factorisations")
        self._lu, self.stiffness = spla.splu(system), 1.0

    def solve(self, f: np.ndarray, d_A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(u, λ_A)`` with ``K u + N_Aᵀ λ_A = f`` and ``N_A u = d_A`` (n × k, |A| × k alike)."""
        k = self.stiffness
        solution = self._lu.solve(count_solves(np.concatenate([np.asarray(f) / k, self.scale * d_A])))
        return solution[:self.n], k * self.scale * solution[self.n:]

    def in_units(self, K: Any, stiffness: float) -> "SaddlePoint":
        """The same factorisation as the system of ``K = stiffness × this K`` (one LU shared)."""
        other = copy.copy(self)
        other.matrix, other.stiffness = K, self.stiffness * stiffness
        return other

    def on(self, K: Any, N: Any, active: np.ndarray | None = None) -> bool:
        """This is the system of stiffness ``K`` and rows ``N`` (on the active set ``active``)."""
        same = [(K, self.matrix), (N, self.N)]
        return (active is None or np.array_equal(self.active, active)) and all(
            a is b or (a.shape == b.shape and (a != b).nnz == 0) for a, b in same)

    def newton(self, counter: Any = None) -> Callable[[np.ndarray, np.ndarray],
                                                      tuple[np.ndarray, np.ndarray]]:
        """``(r, g) ↦ M⁻¹(−r, −g)``: a Newton step on the active set, one back-solve (added to
        ``counter.count`` when given)."""
        def step(r: np.ndarray, g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            if counter is not None:
                counter.count += 1
            return self.solve(-r, -g)
        return step

    def gap(self, K: Any, f: np.ndarray, N: Any, d: np.ndarray, u: np.ndarray,
            lam_plus: np.ndarray, Ku: np.ndarray) -> float | None:
        """``J(u) − D(λ̂)`` with λ̂_A the best forces on the active set (module); None when one of
        them is negative (λ̂ is then no dual point)."""
        rows = np.flatnonzero(self.active)
        lam_hat = lam_plus.copy()
        lam_hat[rows] = 0.0
        r = Ku - f + N.T @ lam_hat
        e, minus = self.solve(r, N[rows] @ u - d[rows])
        if np.any(minus > 0):
            return None
        lam_hat[rows] = -minus
        return float(lam_hat @ (d - N @ u)) + 0.5 * float(e @ (K @ e))
