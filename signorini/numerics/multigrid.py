"""Algebraic multigrid for elasticity, and conjugate gradients with some dofs pinned.

A hierarchy is built once for an SPD matrix ``A`` (K with some dofs pinned: their rows and
columns replaced by ``s·I``, ``s`` the mean free diagonal) and then preconditions CG on systems
whose pinned set differs from ``A``'s in a few rows: each such row is a low-rank change, which
costs CG a few iterations, not a new hierarchy. Two hierarchies, one interface
(``apply(r) -> z``, ``backend``, ``setup_s``, ``levels``): pyamg's smoothed aggregation (Vaněk,
Mandel & Brezina 1996) on K's node blocks with the rigid-body modes as near-null space, here;
PETSc's GAMG in :mod:`signorini.solvers.amg_system`.

:func:`pinned_cg` is preconditioned CG on the free dofs only: the pinned dofs keep their
values and the preconditioner's output is zeroed on them (so the operator CG sees, ``P M P``
on the free subspace, stays SPD whatever pinned set the hierarchy was built for). Hierarchies
built and CG iterations are counted into the stage's work record
(:class:`signorini.numerics.factor.Work`).
"""

from __future__ import annotations

import os
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from functools import cache
from typing import Callable

import numpy as np
import scipy.sparse as sp

from signorini.numerics.factor import count

#: 3D models of at least this many free dofs are solved by multigrid (``auto`` picks pdas-amg when
#: load control precedes the method, and leaves a pending target load to it): their
#: factorisations fill in like n^(4/3)
AMG_FROM_DOFS = 50_000
#: CG restarts from the true residual when the recursive one says done but the true one does not
MAX_RESTARTS = 4
#: threads a large product ``K @ x`` is split over (scipy's runs in one and releases the GIL),
#: and the fewest entries worth splitting (below, starting the threads costs more than it saves)
THREADS = min(len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
              else os.cpu_count() or 1, 8)
THREADED_FROM = 1_000_000


def pinned_matrix(K: sp.csr_matrix, pinned: np.ndarray) -> sp.csr_matrix:
    """K with the ``pinned`` dofs' rows and columns made ``s·I`` (s: mean diagonal of the rest)."""
    K = sp.csr_matrix(K)
    diagonal = K.diagonal()
    free = ~pinned
    scale = float(np.mean(np.abs(diagonal[free]))) if free.any() else 1.0
    touched = pinned[K.indices]  # entries in a pinned column, then those in a pinned row
    rows = np.flatnonzero(pinned)
    lengths = K.indptr[rows + 1] - K.indptr[rows]
    at = np.repeat(K.indptr[rows] - np.cumsum(lengths) + lengths, lengths) + np.arange(lengths.sum())
    touched[at] = True
    data = np.where(touched, 0.0, K.data)
    on_diagonal = at[K.indices[at] == np.repeat(rows, lengths)]
    data[on_diagonal] = scale
    out = sp.csr_matrix((data, K.indices.copy(), K.indptr.copy()), shape=K.shape)
    if on_diagonal.size < rows.size:  # a pinned row without a diagonal entry
        out = out + sp.diags(np.where(pinned, scale, 0.0) - out.diagonal() * pinned)
    out.eliminate_zeros()
    out.sort_indices()
    return out


class PyamgHierarchy:
    """pyamg's smoothed aggregation of ``A`` (node blocks of ``block`` dofs, near-null ``modes``)."""

    backend = "pyamg"

    def __init__(self, A: sp.csr_matrix, modes: np.ndarray | None, block: int):
        import pyamg  # a default dependency, but 0.3-0.7 s to import: only when a solve needs it

        start = time.perf_counter()
        blocked = A.tobsr(blocksize=(block, block)) if block > 1 and A.shape[0] % block == 0 else A
        self._hierarchy = pyamg.smoothed_aggregation_solver(blocked, B=modes)
        self._cycle = self._hierarchy.aspreconditioner(cycle="V")
        self.levels = [level.A.shape[0] for level in self._hierarchy.levels]
        self.setup_s = time.perf_counter() - start
        count("hierarchies")

    def apply(self, r: np.ndarray) -> np.ndarray:
        return self._cycle.matvec(r)


class RowBlocks:
    """``K @ x`` for a vector x, by blocks of K's rows in threads (as many entries in each).

    Each block is a CSR matrix on K's own arrays (set as its attributes: scipy's constructor
    copies a slice of a much larger array) and each row's sum is scipy's own, so the product is
    K's to the bit; CG's products with a large K are most of its time besides the
    preconditioner's.
    """

    def __init__(self, K: sp.csr_matrix, threads: int | None = None):
        self.K, self.shape = K, K.shape
        parts = THREADS if threads is None else threads
        cuts = np.searchsorted(K.indptr, np.linspace(0, K.nnz, parts + 1)).clip(0, K.shape[0])
        cuts[0], cuts[-1] = 0, K.shape[0]
        self.blocks = []
        for first, last in zip(cuts[:-1], cuts[1:]):
            start, end = K.indptr[first], K.indptr[last]
            if last > first:
                rows = sp.csr_matrix((last - first, K.shape[1]), dtype=K.dtype)
                rows.data, rows.indices = K.data[start:end], K.indices[start:end]
                rows.indptr = K.indptr[first:last + 1] - start
                self.blocks.append((first, last, rows))

    def __matmul__(self, x: np.ndarray) -> np.ndarray:
        if np.ndim(x) != 1 or len(self.blocks) < 2:
            return self.K @ x
        out = np.empty(self.shape[0], dtype=np.result_type(self.K.dtype, x.dtype))

        def product(block) -> None:
            first, last, rows = block
            out[first:last] = rows @ x

        list(_threads().map(product, self.blocks))
        return out


@cache
def _threads() -> ThreadPoolExecutor:
    """The threads of :class:`RowBlocks`, started on first use."""
    return ThreadPoolExecutor(THREADS, thread_name_prefix="signorini-product")


def threaded(K: sp.csr_matrix) -> sp.csr_matrix | RowBlocks:
    """K, or its :class:`RowBlocks` when it is large enough and there are threads to use."""
    return RowBlocks(K) if THREADS > 1 and K.nnz >= THREADED_FROM else K


@dataclass
class CGResult:
    """What one pinned CG solve did: iterations, and its residual's norms at start and end."""

    iterations: int
    initial: float  # ‖r₀‖₂ on the free dofs
    final: float  # ‖r‖₂ on the free dofs (the true residual)
    final_inf: float  # ‖r‖∞ on the free dofs


class Bordered:
    """The SPD matrix ``[[K, −g], [−gᵀ, k]]`` (one more unknown, coupled through sparse ``g``)."""

    def __init__(self, K: sp.csr_matrix, g: np.ndarray, k: float):
        self.K, self.k = K, float(k)
        self.rows = np.flatnonzero(g)
        self.values = g[self.rows]
        self.shape = (K.shape[0] + 1, K.shape[0] + 1)

    def __matmul__(self, y: np.ndarray) -> np.ndarray:
        n = self.K.shape[0]
        out = np.empty(n + 1)
        out[:n] = self.K @ y[:n]
        out[self.rows] -= self.values * y[n]
        out[n] = self.k * y[n] - float(self.values @ y[self.rows])
        return out


def _inner(r: np.ndarray, z: np.ndarray) -> float:
    """``r · z``, infinite or NaN (and quiet) where the preconditioned residual overflowed."""
    with np.errstate(over="ignore", invalid="ignore"):
        return float(r @ z)


def pinned_cg(K: sp.csr_matrix, f: np.ndarray, x: np.ndarray, free: np.ndarray,
              precondition: Callable[[np.ndarray], np.ndarray],
              done: Callable[[float, float, float], bool], max_iter: int = 2000,
              weights: np.ndarray | None = None) -> CGResult:
    """Solve ``(K x)[free] = f[free]`` for ``x[free]`` in place, ``x[~free]`` held fixed.

    ``done(‖r‖₂, ‖r‖∞, ‖r₀‖₂)`` decides when to stop (an absolute target, an
    Eisenstat–Walker forcing term against the first residual, or both); it is
    checked on the recursive residual and confirmed on the true one (CG
    restarts from it at most :data:`MAX_RESTARTS` times). Preconditioned by
    ``precondition`` restricted to the free dofs (it returns a new array, which CG
    masks in place; ``K @`` likewise). ``weights`` (default one)
    scale the residual's entries in those norms (rows of other units).
    ``K`` may be anything with ``K @ x`` (e.g. :class:`Bordered`).
    """
    mask = free.astype(float)
    scaled = mask if weights is None else mask * weights

    def norms(r: np.ndarray) -> tuple[float, float]:
        w = r if weights is None else scaled * r
        return float(np.linalg.norm(w)), max(float(w.max(initial=0.0)), -float(w.min(initial=0.0)))

    r = mask * (f - K @ x)
    initial = norms(r)[0]
    iterations = 0
    for _ in range(MAX_RESTARTS + 1):
        if done(*norms(r), initial):
            break
        z = precondition(r)
        z *= mask
        p = z.copy()
        rz = _inner(r, z)
        if not 0 < rz < np.inf:  # nothing to correct, or a preconditioner that overflowed
            break
        while iterations < max_iter:  # in place where a product would only make a copy
            q = K @ p
            q *= mask
            curvature = float(p @ q)
            if not curvature > 0:  # breakdown: nothing left that the free dofs can change
                break
            alpha = rz / curvature
            x += alpha * p
            r -= alpha * q
            iterations += 1
            if done(*norms(r), initial):
                break
            z = precondition(r)
            z *= mask
            rz, rz_old = _inner(r, z), rz
            if not 0 < rz < np.inf:  # vanished: nothing left to correct; or overflowed
                break
            p *= rz / rz_old
            p += z
        r = mask * (f - K @ x)  # the true residual: confirm, or restart from it
        if iterations >= max_iter:
            break
    count("cg_iterations", iterations)
    return CGResult(iterations, initial, *norms(r))


__all__ = ["pinned_matrix", "PyamgHierarchy", "RowBlocks", "threaded", "CGResult", "Bordered",
           "pinned_cg", "AMG_FROM_DOFS"]
