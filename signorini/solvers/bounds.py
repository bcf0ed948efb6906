"""The contact QP as a bound-constrained QP, for solvers that only take bounds.

Every row of N is the normal gap of one contact node: it touches only that
node's dofs. Rotating each contact node's free dofs into a frame whose first
axis is the row's direction (a Householder reflection per node, identity
elsewhere) turns ``N u ≤ d`` into one bound on one unknown per row:
``u = T v``, ``(N T)ᵢ = aᵢ e_jᵢ`` and ``aᵢ v_jᵢ ≤ dᵢ``. The frame is exact per
node, so curved obstacles are no harder than flat ones.

The unknowns are the whole dof vector, node by node as scikit-fem numbers
them (``dim`` dofs per node): prescribed dofs stay in as decoupled identity
rows fixed by equal bounds (at 0: ``f`` already holds their lift). That keeps
the node blocks whole, which PETSc's block matrices and an algebraic
multigrid's rigid-body modes need. The multiplier of row ``i`` is the
reaction on its bound, ``λᵢ = (f' − K' v)_jᵢ / aᵢ``, the same ``λ`` as
``K u − f + Nᵀλ = 0`` in the original frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from signorini.errors import SignoriniError
from signorini.problem.contact import ContactProblem

#: a row entry below this fraction of the row's largest is round-off, not a coupling
ROUND_OFF = 1e-13


class NoBoundForm(SignoriniError):
    """The constraints are not one bound each in any rotation (two rows share a dof)."""

    #: the status a solver reports for it
    status = "failed"


class InfeasibleBounds(NoBoundForm):
    """A contact row without a free dof starts penetrating: nothing can satisfy it."""

    status = "infeasible"


@dataclass
class BoundForm:
    """``min ½ vᵀ K v − fᵀ v`` subject to ``lower ≤ v ≤ upper`` (rotated, full dof vector)."""

    K: sp.csr_matrix
    f: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    #: the orthogonal rotation: the free-dof displacement is ``(T v)[free_dofs]``
    T: sp.csr_matrix
    free_dofs: np.ndarray
    #: per contact row: the bounded unknown and its coefficient ``aᵢ`` in ``aᵢ v_j ≤ dᵢ``
    bound_index: np.ndarray
    bound_coef: np.ndarray
    #: dofs per node (the block size)
    block: int
    #: (dim, nodes) reference coordinates, for rigid-body modes (None without a mesh)
    coordinates: np.ndarray | None

    @property
    def n(self) -> int:
        return self.K.shape[0]

    def displacement(self, v: np.ndarray) -> np.ndarray:
        """The free-dof displacement ``u`` of the problem from the rotated unknowns."""
        return (self.T @ v)[self.free_dofs]

    def multipliers(self, v: np.ndarray) -> np.ndarray:
        """The contact forces: the reactions on the bounds, ``(f − K v)_j / a``, never negative.

        A row without a free dof (``bound_index`` −1) bounds nothing and carries no force.
        """
        bounded = self.bound_index >= 0
        lam = np.zeros(self.bound_index.size)
        gradient = self.f - self.K @ v
        lam[bounded] = gradient[self.bound_index[bounded]] / self.bound_coef[bounded]
        return np.maximum(lam, 0.0)

    def rigid_modes(self) -> np.ndarray | None:
        """Rigid-body displacements of the mesh in the rotated unknowns, orthonormal columns.

        3 modes in 2D (two translations, one rotation), 6 in 3D; the
        near-null space an algebraic multigrid needs for elasticity.
        """
        if self.coordinates is None or self.block not in (2, 3):
            return None
        dim, count = self.coordinates.shape
        x = self.coordinates - self.coordinates.mean(axis=1, keepdims=True)
        modes = [np.tile(np.eye(dim)[axis], count) for axis in range(dim)]  # the translations
        for i, j in [(0, 1)] if dim == 2 else [(0, 1), (1, 2), (2, 0)]:  # the rotations
            mode = np.zeros((count, dim))
            mode[:, i], mode[:, j] = -x[j], x[i]
            modes.append(mode.ravel())
        q, _ = np.linalg.qr(self.T.T @ np.column_stack(modes))
        return q


def _node_blocks(problem: ContactProblem) -> tuple[int, np.ndarray | None]:
    """Dofs per node and the reference coordinates, from the mesh when there is one."""
    mesh = problem.model.mesh
    n_full = problem.model.dofs()[0]
    if mesh is not None and mesh.p.shape[0] * mesh.p.shape[1] == n_full:
        return mesh.p.shape[0], np.asarray(mesh.p, dtype=float)
    return 1, None


def _householder(row: np.ndarray) -> np.ndarray:
    """An orthogonal Q (symmetric) whose first column is ``row / |row|``."""
    k = row.size
    unit = row / np.linalg.norm(row)
    w = unit.copy()
    w[0] -= 1.0
    if np.linalg.norm(w) < 1e-14:
        return np.eye(k)
    return np.eye(k) - 2.0 * np.outer(w, w) / (w @ w)


def _with_identity_rows(K: sp.csr_matrix, free: np.ndarray, n_full: int) -> sp.csr_matrix:
    """K (over the sorted ``free`` dofs) placed in the full dof vector, identity rows elsewhere."""
    is_free = np.zeros(n_full, dtype=bool)
    is_free[free] = True
    others = np.flatnonzero(~is_free)
    at = K.indptr[np.searchsorted(free, others)]  # each other row's entry goes before these
    indices = np.insert(free.astype(K.indices.dtype)[K.indices], at, others)
    data = np.insert(K.data, at, 1.0)
    counts = np.ones(n_full, dtype=np.int64)
    counts[free] = np.diff(K.indptr)
    indptr = np.concatenate([[0], np.cumsum(counts)]).astype(K.indptr.dtype)
    out = sp.csr_matrix((data, indices, indptr), shape=(n_full, n_full))
    out.has_sorted_indices = bool(K.has_sorted_indices)
    return out


def bound_form(problem: ContactProblem) -> BoundForm:
    """Rotate each contact node's free dofs so that every contact row becomes a bound.

    Raises :class:`NoBoundForm` when two rows share a dof (two obstacles
    acting on one node, or general linear constraints): such a problem has
    no bound form. A row over several nodes' dofs is rotated as one block.
    """
    block, coordinates = _node_blocks(problem)
    n_full, free = problem.model.dofs()
    embed = sp.csr_matrix((np.ones(free.size), (free, np.arange(free.size))),
                          shape=(n_full, problem.n))
    N = sp.csr_matrix(embed @ problem.N.T).T.tocsr()  # rows over the full dof vector
    N.sum_duplicates()
    owner = np.full(n_full, -1)
    rows_i, rows_j, rows_v = [np.arange(n_full)], [np.arange(n_full)], [np.ones(n_full)]
    keep = np.ones(n_full, dtype=bool)
    empty = np.diff(N.indptr) == 0
    if np.any(empty & (problem.d < 0)):
        rows = np.nonzero(empty & (problem.d < 0))[0]
        raise InfeasibleBounds(f"contact candidate(s) {tuple(rows[:5].tolist())} have every dof "
                               "prescribed and start inside the obstacle: the problem is infeasible")
    for i in range(N.shape[0]):
        cols = N.indices[N.indptr[i]:N.indptr[i + 1]]
        vals = N.data[N.indptr[i]:N.indptr[i + 1]]
        if cols.size == 0:
            continue
        big = np.abs(vals) > ROUND_OFF * np.abs(vals).max()
        cols, vals = cols[big], vals[big]
        if np.any(owner[cols] >= 0):
            other = int(owner[cols][owner[cols] >= 0][0])
            raise NoBoundForm(f"contact rows {other} and {i} share a dof, so the constraints "
                              "are not bounds in any frame: use pdas or a qp-* method")
        owner[cols] = i
        if cols.size == 1:
            continue
        order = np.argsort(cols)
        cols, vals = cols[order], vals[order]
        Q = _householder(vals)
        keep[cols] = False
        rows_i.append(np.repeat(cols, cols.size))
        rows_j.append(np.tile(cols, cols.size))
        rows_v.append(Q.ravel())
    rows_i[0], rows_j[0], rows_v[0] = rows_i[0][keep], rows_j[0][keep], rows_v[0][keep]
    T = sp.csr_matrix((np.concatenate(rows_v), (np.concatenate(rows_i), np.concatenate(rows_j))),
                      shape=(n_full, n_full))
    rotated = (N @ T).tocsr()
    rotated.data[np.abs(rotated.data) <= ROUND_OFF * np.abs(rotated.data).max(initial=0.0)] = 0.0
    rotated.eliminate_zeros()
    counts = np.diff(rotated.indptr)
    if np.any(counts[~empty] != 1):
        raise NoBoundForm("a contact row does not reduce to one bound after rotation")
    index, coef = np.full(N.shape[0], -1), np.ones(N.shape[0])
    index[~empty], coef[~empty] = rotated.indices, rotated.data
    prescribed = np.ones(n_full, dtype=bool)
    prescribed[free] = False
    K_full = _with_identity_rows(sp.csr_matrix(problem.K), free, n_full)
    if len(rows_v) > 1:  # some node is rotated (else T is the identity)
        K_full = (T.T @ K_full @ T).tocsr()
    lower = np.where(prescribed, 0.0, -np.inf)
    upper = np.where(prescribed, 0.0, np.inf)
    limit = problem.d / coef
    up, down = ~empty & (coef > 0), ~empty & (coef < 0)
    upper[index[up]], lower[index[down]] = limit[up], limit[down]
    return BoundForm(K=K_full, f=T.T @ (embed @ problem.f), lower=lower,
                     upper=upper, T=T, free_dofs=free, bound_index=index, bound_coef=coef,
                     block=block, coordinates=coordinates)


__all__ = ["NoBoundForm", "InfeasibleBounds", "BoundForm", "bound_form"]
