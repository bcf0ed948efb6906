"""P1 stiffness matrices in closed form, vectorised: plane strain (triangles) and 3D (tetrahedra).

Both are the matrices scikit-fem's ``linear_elasticity`` assembles (tests hold
them to it), built from each simplex's constant strain without quadrature
points: several times faster at 10⁶ dofs, where assembly would otherwise
cost as much as the solve.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp


def plane_strain_stiffness(mesh: Any, Lambda: float, Mu: float) -> sp.csr_matrix:
    """The P1 plane-strain stiffness of a triangle mesh, dofs interleaved (2i, 2i + 1).

    Element by element ``Kₑ = Aₑ BₑᵀDBₑ`` with the constant strain matrix B
    and ``D = [[λ+2μ, λ, 0], [λ, λ+2μ, 0], [0, 0, μ]]`` (engineering shear):
    the matrix scikit-fem's ``linear_elasticity`` assembles, in one
    vectorised pass (several times faster at 10⁶ dofs).
    """
    p, t = mesh.p, mesh.t
    x, y = p[0, t], p[1, t]  # (3, elements)
    b = np.array([y[1] - y[2], y[2] - y[0], y[0] - y[1]])  # 2A ∂φ/∂x
    c = np.array([x[2] - x[1], x[0] - x[2], x[1] - x[0]])  # 2A ∂φ/∂y
    area2 = b[0] * c[1] - b[1] * c[0]
    B = np.zeros((t.shape[1], 3, 6))
    B[:, 0, 0::2], B[:, 1, 1::2] = b.T, c.T
    B[:, 2, 0::2], B[:, 2, 1::2] = c.T, b.T
    D = np.array([[Lambda + 2 * Mu, Lambda, 0.0], [Lambda, Lambda + 2 * Mu, 0.0], [0.0, 0.0, Mu]])
    Ke = np.einsum("eki,kl,elj->eij", B, D, B, optimize=True) / (2.0 * np.abs(area2))[:, None, None]
    dofs = np.empty((t.shape[1], 6), dtype=np.int64)
    dofs[:, 0::2], dofs[:, 1::2] = 2 * t.T, 2 * t.T + 1
    rows = np.broadcast_to(dofs[:, :, None], Ke.shape).ravel()
    cols = np.broadcast_to(dofs[:, None, :], Ke.shape).ravel()
    n = 2 * p.shape[1]
    return sp.coo_matrix((Ke.ravel(), (rows, cols)), shape=(n, n)).tocsr()


#: tetrahedra per vectorised block of :func:`solid_stiffness` (bounds its temporary memory)
TETRA_BLOCK = 500_000
#: the six edges of a tetrahedron, as pairs of its local nodes
TETRA_EDGES = ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))


def barycentric_gradients(p: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gradients (3 components, 4 nodes, elements) of each tetrahedron's barycentric coordinates
    and its volume: rows of the inverse of the edge matrix, by cross products."""
    x = p[:, t]  # (3, 4, e)
    e1, e2, e3 = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]
    rows = np.stack([np.cross(e2, e3, axis=0), np.cross(e3, e1, axis=0), np.cross(e1, e2, axis=0)],
                    axis=1)  # (3, 3, e): det · ∇λ₁..₃
    det = np.einsum("ie,ie->e", e1, rows[:, 0])
    grads = np.concatenate([-rows.sum(axis=1, keepdims=True), rows], axis=1) / det
    return grads, np.abs(det) / 6.0


def node_pair_slots(t: np.ndarray, nodes: int) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                       np.ndarray]:
    """K's node-by-node pattern (CSR ``indptr``, ``indices``) of a tetrahedral mesh, the slot
    in it of each element's node pair (16, e) — row 4a + b for local nodes a, b — and each
    slot's mirror (the slot of (j, i) for that of (i, j)).

    Found from the mesh's edges (one sort of six integers per element, then one of the pattern's
    own entries) rather than by sorting all sixteen pairs of every element.
    """
    first = np.concatenate([t[i] for i, _ in TETRA_EDGES]).astype(np.int64)
    second = np.concatenate([t[j] for _, j in TETRA_EDGES]).astype(np.int64)
    low, high = np.minimum(first, second), np.maximum(first, second)
    edges, edge_of = np.unique(low * nodes + high, return_inverse=True)
    edge_low, edge_high = np.divmod(edges, nodes)
    count = edges.size
    rows = np.concatenate([np.arange(nodes), edge_low, edge_high])  # diagonal, upper, lower
    cols = np.concatenate([np.arange(nodes), edge_high, edge_low])
    order = np.argsort(rows * nodes + cols)
    position = np.empty(order.size, dtype=np.int64)
    position[order] = np.arange(order.size)
    indptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=nodes))])
    indices = cols[order]
    mirror = np.empty(order.size, dtype=np.int64)
    upper, lower = position[nodes:nodes + count], position[nodes + count:]
    mirror[position[:nodes]], mirror[upper], mirror[lower] = position[:nodes], lower, upper
    elements = t.shape[1]
    edge_of = edge_of.reshape(6, elements)
    slot = np.empty((16, elements), dtype=np.int64)
    for a in range(4):
        slot[5 * a] = position[t[a]]  # the diagonal block of node a
    for k, (a, b) in enumerate(TETRA_EDGES):
        is_upper = t[a] < t[b]  # (a, b) is (low, high): the upper entry
        up, down = upper[edge_of[k]], lower[edge_of[k]]
        slot[4 * a + b] = np.where(is_upper, up, down)
        slot[4 * b + a] = np.where(is_upper, down, up)
    return indptr, indices, slot, mirror


#: the local node pairs (a, b) with a ≤ b: K's blocks for b < a are their transposes
TETRA_PAIRS = np.array([(a, b) for a in range(4) for b in range(a, 4)]).T


def solid_stiffness(mesh: Any, Lambda: float, Mu: float) -> sp.csr_matrix:
    """The P1 stiffness of a tetrahedral mesh, dofs interleaved (3i, 3i + 1, 3i + 2).

    The matrix scikit-fem's ``linear_elasticity`` assembles, in closed form:
    with the constant gradients gₐ of the barycentric coordinates and the
    volume V, the 3 × 3 block coupling nodes a and b is
    ``V (λ gₐ g_bᵀ + μ g_b gₐᵀ + μ (gₐ · g_b) I)`` and that of (b, a) its
    transpose: the ten pairs a ≤ b of each element are summed into K's
    node-by-node pattern (:func:`node_pair_slots`) by ``bincount``, in
    element blocks of :data:`TETRA_BLOCK`, and each off-diagonal block then
    gets its mirror's transpose: ten blocks computed per element instead of
    sixteen (timings in docs/speed.md, "Building large 3D models").
    """
    p, t = mesh.p, mesh.t
    nodes, elements = p.shape[1], t.shape[1]
    indptr, indices, slot, mirror = node_pair_slots(t, nodes)
    first, second = TETRA_PAIRS
    half = np.zeros((3, 3, indices.size))
    for start in range(0, elements, TETRA_BLOCK):
        grads, volume = barycentric_gradients(p, t[:, start:start + TETRA_BLOCK])
        scaled = (grads * volume)[:, first].reshape(3, -1)  # V gₐ over (pair, element)
        paired = grads[:, second].reshape(3, -1)  # g_b
        where = np.ascontiguousarray(slot[4 * first + second, start:start + TETRA_BLOCK]).ravel()
        shear = Mu * np.einsum("ip,ip->p", scaled, paired)
        for i in range(3):
            for j in range(i, 3):
                ij, ji = scaled[i] * paired[j], scaled[j] * paired[i]
                half[i, j] += np.bincount(where, Lambda * ij + Mu * ji + (shear if i == j else 0.0),
                                          minlength=indices.size)
                if i != j:
                    half[j, i] += np.bincount(where, Lambda * ji + Mu * ij, minlength=indices.size)
    blocks = np.empty((indices.size, 3, 3))
    on_diagonal = mirror == np.arange(mirror.size)
    for i in range(3):
        for j in range(3):
            mirrored = half[j, i][mirror]
            mirrored[on_diagonal] = 0.0  # a node's own block is symmetric and summed once
            blocks[:, i, j] = half[i, j] + mirrored
    K = sp.bsr_matrix((blocks, indices, indptr), shape=(3 * nodes, 3 * nodes)).tocsr()
    K.eliminate_zeros()  # the blocks' structural zeros (a pattern as scikit-fem's)
    return K
