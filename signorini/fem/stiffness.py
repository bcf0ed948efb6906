"""P1 stiffness matrices in closed form, vectorised: plane strain and axisymmetric (triangles),
3D (tetrahedra).

They are the matrices scikit-fem assembles from ``linear_elasticity`` and
:func:`~signorini.fem.assembly.axisymmetric_elasticity` (tests hold them to it,
pattern included), built from each simplex's constant strain
without quadrature points and summed straight into K's pattern, which comes
from the mesh's edges: several times faster at 10⁶ dofs, where assembly would
otherwise cost as much as the solve.
"""

from __future__ import annotations

from itertools import combinations
from typing import Any

import numpy as np
import scipy.sparse as sp
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTri

#: the quadrature order scikit-fem's basis takes for P1 (twice the degree): the axisymmetric
#: hoop term ∫ φₐ φ_b / r is no polynomial, and :func:`hoop_terms` integrates it with that rule
HOOP_ORDER = 2
#: simplices per vectorised block of :func:`simplex_stiffness` (bounds its temporary memory)
SIMPLEX_BLOCK = 500_000


def triangle_gradients(p: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gradients (2 components, 3 nodes, elements) of each triangle's barycentric coordinates
    and its area: ``∇λₐ = (y_b − y_c, x_c − x_b) / 2A`` for (a, b, c) in cyclic order."""
    x, y = p[0, t], p[1, t]  # (3, e)
    det = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0])  # 2A, signed
    grads = np.array([[y[1] - y[2], y[2] - y[0], y[0] - y[1]],
                      [x[2] - x[1], x[0] - x[2], x[1] - x[0]]]) / det
    return grads, 0.5 * np.abs(det)


def corner_coordinates(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    """``p[:, t]`` (dim, corners, elements), laid out in memory as fancy indexing lays it out
    (component fastest), gathered by ``np.take`` over the rows of ``pᵀ``: several times faster
    on large meshes. The layout matters: ``einsum`` sums in an order that depends on it."""
    return np.take(np.ascontiguousarray(p.T), t, axis=0).transpose(2, 0, 1)


def tetrahedron_gradients(p: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gradients (3 components, 4 nodes, elements) of each tetrahedron's barycentric coordinates
    and its volume: rows of the inverse of the edge matrix, by cross products."""
    x = corner_coordinates(p, t)  # (3, 4, e)
    e1, e2, e3 = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]
    rows = np.stack([np.cross(e2, e3, axis=0), np.cross(e3, e1, axis=0), np.cross(e1, e2, axis=0)],
                    axis=1)  # (3, 3, e): det · ∇λ₁..₃
    det = np.einsum("ie,ie->e", e1, rows[:, 0])
    grads = np.concatenate([-rows.sum(axis=1, keepdims=True), rows], axis=1) / det
    return grads, np.abs(det) / 6.0


def barycentric_gradients(p: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gradients (dim components, d + 1 nodes, elements) of each simplex's barycentric
    coordinates and its measure: :func:`triangle_gradients` or :func:`tetrahedron_gradients`."""
    if t.shape[0] != p.shape[0] + 1 or p.shape[0] not in (2, 3):
        raise ValueError(f"barycentric gradients: triangles or tetrahedra, got {t.shape[0]} "
                         f"corners in {p.shape[0]}D")
    return (triangle_gradients if p.shape[0] == 2 else tetrahedron_gradients)(p, t)


def sort_order(keys: np.ndarray, bound: int) -> np.ndarray:
    """``np.argsort(keys, kind="stable")`` of non-negative integer ``keys`` below ``bound``.

    When a key and its position fit in 63 bits together, by one sort of the
    values ``key · 2ᵇ + position`` (numpy's SIMD value sort, several times
    faster than an index sort); else by ``argsort``.
    """
    shift = max(keys.size - 1, 1).bit_length()
    if max(bound - 1, 1).bit_length() + shift > 63:
        return np.argsort(keys, kind="stable")
    return np.sort((keys.astype(np.int64) << shift) | np.arange(keys.size)) & ((1 << shift) - 1)


def node_pair_slots(t: np.ndarray, nodes: int) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                       np.ndarray]:
    """K's node-by-node pattern (CSR ``indptr``, ``indices``, sorted) of a simplex mesh
    (triangles or tetrahedra: k = 3 or 4 nodes each), the slot in it of each element's node
    pair (k², e) — row k·a + b for local nodes a, b — and each slot's mirror (the slot of
    (j, i) for that of (i, j)).

    Found from the mesh's edges: one sort of an integer key per edge of every element gives
    the edges (low, high) in order, which is the order of the upper entries; one sort of the
    edges by their high end gives the lower ones. Row i holds its lower entries, its diagonal,
    then its upper entries.
    """
    corners, elements = t.shape
    edges_local = list(combinations(range(corners), 2))
    first = np.concatenate([t[a] for a, _ in edges_local]).astype(np.int64)
    second = np.concatenate([t[b] for _, b in edges_local]).astype(np.int64)
    keys = np.minimum(first, second) * nodes + np.maximum(first, second)
    order = sort_order(keys, nodes * nodes)
    sorted_keys = np.take(keys, order)
    is_new = np.ones(keys.size, dtype=bool)
    is_new[1:] = sorted_keys[1:] != sorted_keys[:-1]
    edge_of = np.empty(keys.size, dtype=np.int64)
    edge_of[order] = np.cumsum(is_new) - 1
    edge_low, edge_high = np.divmod(sorted_keys[is_new], nodes)
    count = edge_low.size
    above, below = np.bincount(edge_low, minlength=nodes), np.bincount(edge_high, minlength=nodes)
    indptr = np.concatenate([[0], np.cumsum(below + 1 + above)])
    diagonal = indptr[:-1] + below
    before_low, before_high = np.cumsum(above) - above, np.cumsum(below) - below
    upper = (np.take(diagonal, edge_low) + 1 + np.arange(count)
             - np.take(before_low, edge_low))
    by_high = sort_order(edge_high, nodes)
    lower = np.empty(count, dtype=np.int64)
    high = np.take(edge_high, by_high)
    lower[by_high] = np.take(indptr, high) + np.arange(count) - np.take(before_high, high)
    indices = np.empty(indptr[-1], dtype=np.int64)
    indices[diagonal], indices[upper], indices[lower] = np.arange(nodes), edge_high, edge_low
    mirror = np.empty(indptr[-1], dtype=np.int64)
    mirror[diagonal], mirror[upper], mirror[lower] = diagonal, lower, upper
    edge_of = edge_of.reshape(len(edges_local), elements)
    slot = np.empty((corners * corners, elements), dtype=np.int64)
    for a in range(corners):
        slot[(corners + 1) * a] = np.take(diagonal, t[a])
    for k, (a, b) in enumerate(edges_local):
        is_upper = t[a] < t[b]  # (a, b) is (low, high): the upper entry
        up, down = np.take(upper, edge_of[k]), np.take(lower, edge_of[k])
        slot[corners * a + b] = np.where(is_upper, up, down)
        slot[corners * b + a] = np.where(is_upper, down, up)
    return indptr, indices, slot, mirror


def hoop_terms(p: np.ndarray, t: np.ndarray, grads: np.ndarray, area: np.ndarray,
               pairs: tuple[np.ndarray, np.ndarray], Lambda: float,
               Mu: float) -> dict[tuple[int, int], np.ndarray]:
    """What the hoop strain ``u_r / r`` adds to entry (i, j) of the block of each node pair
    (a, b) in ``pairs`` of each triangle, over (pair, element), per radian.

    With ``tr ε = div u + u_r / r`` and the weight r, the block gains
    ``λ (A/3) (δᵢ₀ g_bⱼ + δⱼ₀ gₐᵢ)`` (``∫ φ = A/3``) and, on (r, r),
    ``(λ + 2μ) ∫ φₐ φ_b / r``, integrated with scikit-fem's rule of order
    :data:`HOOP_ORDER` (its quadrature points lie inside, where r > 0).
    """
    first, second = pairs
    points, weights = get_quadrature(RefTri, HOOP_ORDER)
    shape = np.array([1.0 - points[0] - points[1], points[0], points[1]])  # φₐ at the points
    radius = shape.T @ p[0, t]  # (points, elements)
    hoop = np.einsum("pq,qe->pe", shape[first] * shape[second], weights[:, None] / radius)
    hoop *= 2.0 * area  # |det J|
    third = Lambda * area / 3.0
    g_a, g_b = grads[:, first], grads[:, second]  # (2, pairs, elements)
    return {(0, 0): ((Lambda + 2.0 * Mu) * hoop + third * (g_a[0] + g_b[0])).ravel(),
            (0, 1): (third * g_b[1]).ravel(), (1, 0): (third * g_a[1]).ravel()}


def simplex_stiffness(mesh: Any, Lambda: float, Mu: float,
                      axisymmetric: bool = False) -> sp.csr_matrix:
    """The P1 stiffness of a triangle mesh (plane strain, or axisymmetric per radian in the
    meridian half-plane (r, z)) or of a tetrahedral one, dofs interleaved by node (dim·i + c).

    The matrix scikit-fem assembles, in closed form: with the constant
    gradients gₐ of the barycentric coordinates and the element's measure V
    (area or volume; ``A r̄`` with the mean radius r̄ when axisymmetric), the
    dim × dim block coupling nodes a and b is
    ``V (λ gₐ g_bᵀ + μ g_b gₐᵀ + μ (gₐ · g_b) I)`` (plus :func:`hoop_terms`
    when axisymmetric) and that of (b, a) its transpose: the pairs a ≤ b of
    each element (6 of 9 for a triangle, 10 of 16 for a tetrahedron) are
    summed into K's node-by-node pattern (:func:`node_pair_slots`) by
    ``bincount``, in element blocks of :data:`SIMPLEX_BLOCK`, and each
    off-diagonal block then gets its mirror's transpose (K is symmetric to the
    last bit). Entries that are exactly zero are dropped, as scikit-fem does
    (timings in docs/speed.md, "Building large 3D models" and "2D assembly").
    """
    p, t = mesh.p, mesh.t
    dim, corners = p.shape[0], t.shape[0]
    if corners != dim + 1 or (axisymmetric and dim != 2):
        raise ValueError(f"simplex_stiffness needs triangles in 2D or tetrahedra in 3D (triangles "
                         f"when axisymmetric), got {corners}-node elements in {dim}D: assemble "
                         "them with scikit-fem")
    nodes, elements = p.shape[1], t.shape[1]
    indptr, indices, slot, mirror = node_pair_slots(t, nodes)
    first, second = np.triu_indices(corners)
    half = np.zeros((dim, dim, indices.size))
    for start in range(0, elements, SIMPLEX_BLOCK):
        block = t[:, start:start + SIMPLEX_BLOCK]
        grads, volume = barycentric_gradients(p, block)
        extra = {}
        if axisymmetric:
            extra = hoop_terms(p, block, grads, volume, (first, second), Lambda, Mu)
            volume = volume * p[0, block].mean(axis=0)  # ∫ r dA
        scaled = (grads * volume)[:, first].reshape(dim, -1)  # V gₐ over (pair, element)
        paired = grads[:, second].reshape(dim, -1)  # g_b
        where = np.ascontiguousarray(slot[corners * first + second, start:start + SIMPLEX_BLOCK])
        where = where.ravel()
        shear = Mu * np.einsum("ip,ip->p", scaled, paired)
        for i in range(dim):
            for j in range(i, dim):
                ij, ji = scaled[i] * paired[j], scaled[j] * paired[i]
                entries = ([(i, i, Lambda * ij + Mu * ji + shear)] if i == j else
                           [(i, j, Lambda * ij + Mu * ji), (j, i, Lambda * ji + Mu * ij)])
                for row, col, value in entries:
                    if (row, col) in extra:
                        value += extra[row, col]
                    half[row, col] += np.bincount(where, value, minlength=indices.size)
    blocks = np.empty((indices.size, dim, dim))
    on_diagonal = mirror == np.arange(mirror.size)
    for i in range(dim):
        for j in range(dim):
            mirrored = np.take(half[j, i], mirror)
            mirrored[on_diagonal] = 0.0  # a node's own block is symmetric and summed once
            blocks[:, i, j] = half[i, j] + mirrored
    for i, j in combinations(range(dim), 2):  # a node's own block, symmetric to the last bit
        blocks[on_diagonal, j, i] = blocks[on_diagonal, i, j]
    K = sp.bsr_matrix((blocks, indices, indptr), shape=(dim * nodes, dim * nodes)).tocsr()
    K.eliminate_zeros()  # the blocks' structural zeros (a pattern as scikit-fem's)
    return K


#: the stiffness of a triangle mesh in plane strain, per unit thickness
plane_strain_stiffness = simplex_stiffness
#: the stiffness of a tetrahedral mesh
solid_stiffness = simplex_stiffness
