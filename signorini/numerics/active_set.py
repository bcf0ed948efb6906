"""The active-set systems of PDAS and of load control, on one factorisation backend.

``Ku + N_Aᵀλ_A = f, N_A u = d`` for one active set after another (:class:`ActiveSetSolver`):
where each row of N bounds one dof (:func:`selection_dofs`) the active dofs are pinned in a
factorisation of K's own sparsity (:class:`Pinning`, :class:`PinnedFactor`); otherwise the
scaled saddle-point matrix is (:class:`SaddlePoint`, which the certificate reuses too). The
backends are :mod:`signorini.numerics.factor`'s.
"""

from __future__ import annotations

import copy
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from signorini.numerics.factor import (CholmodFactor, Factor, PardisoFactor, cholmod_analysis, count,
                                       count_solves, factorize, resolve_backend, upper_csr)

__all__ = ["ActiveSetSolver", "PinnedFactor", "Pinning", "SaddlePoint", "selection_dofs"]


def selection_dofs(N: sp.csr_matrix) -> np.ndarray | None:
    """The dof of each row when every row of N has one nonzero on its own dof, else None: then
    each constraint bounds one dof (a flat obstacle, or dofs rotated into each node's normal
    frame) and an active set is a Dirichlet condition."""
    N = sp.csr_matrix(N, copy=True)
    N.eliminate_zeros()
    N.sort_indices()
    if not np.all(np.diff(N.indptr) == 1):
        return None
    dofs = N.indices.copy()
    return dofs if np.unique(dofs).size == dofs.size else None


class ActiveSetSolver:
    """Solutions of ``Ku + N_Aᵀλ_A = f, N_A u = d`` (``λ`` zero off A), active set after active set.

    When each row of N bounds one dof the active dofs are pinned (:class:`PinnedFactor`, on one
    :class:`Pinning`); otherwise the saddle-point matrix is factorised
    (:class:`SaddlePoint`). ``factor`` is the factorisation
    the last solve used, for the certificate to reuse; it is let go before the next one is
    made, so that two never live at once.
    """

    def __init__(self, K: sp.csr_matrix, N: sp.csr_matrix, backend: str | None = None):
        self.K = K if sp.issparse(K) else sp.csr_matrix(K)
        self.N = sp.csr_matrix(N, copy=True)
        self.N.eliminate_zeros()
        self.n, self.m = self.K.shape[0], self.N.shape[0]
        self.backend = resolve_backend(backend, self.n, self.K.nnz)
        self._dofs = selection_dofs(self.N)
        self._coef = self.N.data if self._dofs is not None else None
        self._pinning: Pinning | None = None  # made at the first pinning (CHOLMOD's analysis)
        self.factor: Factor | PinnedFactor | None = None
        self.saddle_point: SaddlePoint | None = None

    def pins(self, active: np.ndarray, factor: object) -> bool:
        """``factor`` is a :class:`PinnedFactor` of this K (or of a copy: a method's view) with
        exactly the dofs of ``active`` pinned."""
        return (self._dofs is not None and isinstance(factor, PinnedFactor)
                and (factor.matrix is self.K or factor.matrix.shape == self.K.shape
                     and (factor.matrix != self.K).nnz == 0)
                and np.array_equal(np.sort(factor.fixed), np.sort(self._dofs[active])))

    def solve(self, active: np.ndarray, f: np.ndarray, d: np.ndarray,
              factor: PinnedFactor | SaddlePoint | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``(u, λ)`` on ``active`` for load ``f`` (n or n × k) and gaps ``d`` (m or m × k).

        ``factor``, a factorisation of this very system (see :meth:`pins`, or a
        :class:`SaddlePoint` on this K, N and active set; for instance the last one
        a method made on the same active set), is reused: the solve then costs
        back-solves only.
        """
        active = np.asarray(active, dtype=bool)
        f, d = np.asarray(f, float), np.asarray(d, float)
        lam = np.zeros((self.m,) + f.shape[1:])
        if self._dofs is not None:
            fixed = self._dofs[active]
            coef = self._coef[active] if f.ndim == 1 else self._coef[active][:, None]
            rhs = np.array(f)
            rhs[fixed] = d[active] / coef
            if factor is None or not self.pins(active, factor):
                self.factor = None  # let go before the next one is made
                if self._pinning is None:
                    self._pinning = Pinning(self.K, self.backend)
                factor = PinnedFactor(self.K, fixed, self.backend, self._pinning)
            self.factor = factor
            u = factor.solve(rhs)
            lam[active] = (f[fixed] - factor.fixed_rows(u)) / coef
            return u, lam
        self.factor = None
        N_A = self.N[active]
        if N_A.shape[0] == 0:
            self.factor = factorize(self.K, self.backend)
            return self.factor.solve(f), lam
        if self.saddle_point is None or not np.array_equal(self.saddle_point.active, active):
            self.saddle_point = None  # let go before the next one is made
            given = isinstance(factor, SaddlePoint) and factor.stiffness == 1.0 \
                and factor.on(self.K, self.N, active)
            self.saddle_point = factor if given else SaddlePoint(self.K, self.N, active)
        self.factor = self.saddle_point  # the certificate's, on the final active set
        u, lam[active] = self.saddle_point.solve(f, d[active])
        return u, lam


class Pinning:
    """Factors of K with some dofs pinned, in the layout the backend reads, made without copying K.

    A pinned dof's row and column are replaced by the identity's, so every set of pinned dofs
    gives a matrix of K's sparsity pattern: the layout is cut once (K's upper triangle in CSR
    for PARDISO, all of K in CSC otherwise) and each pinning only rewrites its values;
    CHOLMOD's symbolic analysis (the ordering) is computed once too (docs/speed.md, §4).
    """

    def __init__(self, K: sp.spmatrix, backend: str = "cholmod"):
        self.K = K  # kept by reference: the certificate recognises its problem's K
        self.n = K.shape[0]
        self.backend = backend
        if backend == "pardiso":
            layout = upper_csr(K)
        else:
            layout = sp.csc_matrix(K, copy=not sp.isspmatrix_csc(K) or not K.has_sorted_indices)
            layout.sort_indices()
        self._layout = layout
        self._major = np.repeat(np.arange(self.n), np.diff(layout.indptr))
        self._diagonal = (self._major == layout.indices).astype(float)
        self._symbolic = cholmod_analysis(layout) if backend == "cholmod" else None

    def matrix(self, fixed: np.ndarray) -> sp.csc_matrix | sp.csr_matrix:
        """K (its upper triangle in CSR for PARDISO) with the ``fixed`` dofs' rows and columns
        made the identity's (same pattern)."""
        layout = self._layout
        pinned = np.zeros(self.n, dtype=bool)
        pinned[fixed] = True
        touched = pinned[self._major] | pinned[layout.indices]
        data = np.where(touched, self._diagonal, layout.data)
        return type(layout)((data, layout.indices, layout.indptr), shape=layout.shape)

    def factor(self, fixed: np.ndarray) -> Factor:
        """The backend's factor of K with the ``fixed`` dofs' rows and columns made the identity's."""
        matrix = self.matrix(fixed)
        if self.backend == "cholmod":
            return CholmodFactor(matrix, self._symbolic)
        if self.backend == "pardiso":
            return PardisoFactor(self.K, upper=matrix)
        return Factor(matrix)


def _columns(K: sp.spmatrix, dofs: np.ndarray) -> sp.spmatrix:
    """``K[:, dofs]`` of a symmetric K, sliced along its storage's fast axis."""
    return K[dofs].T if K.format == "csr" else sp.csc_matrix(K)[:, dofs]


class PinnedFactor:
    """Solutions of K u = f with the ``fixed`` dofs prescribed: ``solve(rhs)`` takes their
    values from ``rhs[fixed]`` and the load on the other dofs from the rest of ``rhs``.

    The pinned matrix of a :class:`Pinning` is factorised; ``matrix`` is K itself (unpinned).
    With no dof fixed it solves as a :class:`Factor` of K does.
    """

    def __init__(self, K: sp.spmatrix, fixed: np.ndarray, backend: str | None = None,
                 pinning: Pinning | None = None):
        self.n = K.shape[0]
        self.fixed = np.asarray(fixed, dtype=int)
        if pinning is None:
            pinning = Pinning(K, resolve_backend(backend, self.n, K.nnz))
        self.backend = pinning.backend
        self.matrix = pinning.K
        self._coupling = _columns(pinning.K, self.fixed)
        self._factor = pinning.factor(self.fixed).solve
        #: by dof, (the solution for a value c on that free dof, c), kept by its solver
        self.kept: dict[int, tuple[np.ndarray, float]] = {}

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """u with ``u[fixed] = rhs[fixed]`` and ``(K u)[free] = rhs[free]``."""
        rhs = np.array(rhs, dtype=float)
        values = rhs[self.fixed]
        rhs -= self._coupling @ values
        rhs[self.fixed] = values
        return self._factor(rhs)

    def fixed_rows(self, u: np.ndarray) -> np.ndarray:
        """``(K u)[fixed]`` (for u of length n, or n × k), from the columns :meth:`solve` uses."""
        return self._coupling.T @ u


def _singular_said(N_A: sp.spmatrix, rows: np.ndarray, exc: Exception) -> str:
    """Why the saddle-point system of the active rows ``rows`` of N is singular, and what to do."""
    seen: dict[bytes, int] = {}
    N_A = sp.csr_matrix(N_A)
    N_A.sort_indices()
    for k in range(N_A.shape[0]):
        row = slice(N_A.indptr[k], N_A.indptr[k + 1])
        key = N_A.indices[row].tobytes() + N_A.data[row].tobytes()
        if key in seen:
            return (f"rows {rows[seen[key]]} and {rows[k]} of N are the same constraint, both active: "
                    "the multipliers are not unique and the active-set system is singular; keep one "
                    "of them (with the smaller d), or solve with condensed, uzawa or a QP backend")
        seen[key] = k
    return (f"the active-set system is singular ({exc}): the active rows of N are linearly "
            "dependent, or K is singular where they leave u free")


class SaddlePoint:
    """The factorised saddle-point matrix ``[K N_Aᵀ; N_A 0]`` of one active set (LU).

    An active-set method whose rows do not each bound one dof (two bodies' rows on the master's
    dofs, obstacles that meet) solves this system at each step. Its constraint rows are scaled
    by ``s = mean |diag K|``, so that both blocks are of one size in any units (``λ = s μ``).
    ``matrix`` is K and ``N`` the rows of all candidates, so that the certificate knows whose
    system it is; :meth:`in_units` the same factorisation for ``k K`` (a problem whose view a
    method solved). The factorisation of the final active set also serves the certificate
    (:mod:`signorini.certification.kkt`), which would otherwise factorise K once more and solve
    it |A| times for ``N_A K⁻¹ N_Aᵀ``:

    - the forward error's Newton steps on A are solves of this very matrix (:meth:`newton`:
      one back-solve a step);
    - the duality gap's dual point: with ``r = Ku − f + N_Rᵀλ⁺_R`` (R the rows off A), one
      solve gives ``e`` and ``λ̂_A`` with ``Ke − N_Aᵀλ̂_A = r``, ``N_A e = N_A u − d_A``;
      ``v = u − e`` minimises ``L(·, λ̂)`` on ``N_A v = d_A``, λ̂_A maximises the dual function
      over the rows of A with the others at λ⁺, and exactly
      ``J(u) − D(λ̂) = λ̂ᵀ(d − Nu) + ½ eᵀKe`` (:meth:`gap`), a bound when λ̂_A ≥ 0.
    """

    def __init__(self, K: sp.spmatrix, N: sp.spmatrix, active: np.ndarray):
        self.matrix, self.N, self.active, self.n = K, N, active.copy(), K.shape[0]
        N_A = N[active]
        self.scale = float(np.mean(np.abs(K.diagonal()))) or 1.0
        system = sp.bmat([[K, self.scale * N_A.T], [self.scale * N_A, None]], format="csc")
        count("factorisations")
        try:
            self._lu, self.stiffness = spla.splu(system), 1.0
        except RuntimeError as exc:  # SuperLU: "Factor is exactly singular"
            raise ArithmeticError(_singular_said(N_A, np.flatnonzero(active), exc)) from None

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
