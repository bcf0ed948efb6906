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

from itertools import combinations, product
from typing import Any

import numpy as np
import scipy.sparse as sp
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTri

from signorini.fem.topology import distinct_entities, sort_order

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
    and its volume: rows of the inverse of the edge matrix, by cross products (``np.cross``'s
    arithmetic, written into the gradients' array: no stacked copies)."""
    x = corner_coordinates(p, t)  # (3, 4, e)
    e1, e2, e3 = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]
    grads = np.empty((3, 4, t.shape[1]))
    for node, (a, b) in enumerate(((e2, e3), (e3, e1), (e1, e2)), start=1):  # det · ∇λ₁..₃
        for i in range(3):
            j, k = (i + 1) % 3, (i + 2) % 3
            np.multiply(a[j], b[k], out=grads[i, node])
            grads[i, node] -= a[k] * b[j]
    det = e1[0] * grads[0, 1]
    det += e1[1] * grads[1, 1]
    det += e1[2] * grads[2, 1]
    np.negative(grads[:, 1] + grads[:, 2] + grads[:, 3], out=grads[:, 0])
    grads /= det
    return grads, np.abs(det) / 6.0


def barycentric_gradients(p: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gradients (dim components, d + 1 nodes, elements) of each simplex's barycentric
    coordinates and its measure: :func:`triangle_gradients` or :func:`tetrahedron_gradients`."""
    if t.shape[0] != p.shape[0] + 1 or p.shape[0] not in (2, 3):
        raise ValueError(f"barycentric gradients: triangles or tetrahedra, got {t.shape[0]} "
                         f"corners in {p.shape[0]}D")
    return (triangle_gradients if p.shape[0] == 2 else tetrahedron_gradients)(p, t)


def node_pairs(t: np.ndarray, nodes: int,
               edges: tuple[np.ndarray, np.ndarray] | None = None
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """K's node-by-node pattern (CSR ``indptr``, ``indices``, sorted) of a simplex mesh
    (triangles or tetrahedra: k = 3 or 4 nodes each), where each entry of it sits, and each
    element's edges.

    Returns ``(indptr, indices, diagonal, upper, lower, edge_of)``: ``diagonal`` the entry
    (i, i) of each node, ``upper`` and ``lower`` the entries (low, high) and (high, low) of
    each edge, edges in the order of their (low, high), and ``edge_of`` (pairs, elements) the
    edge of each element's local node pair (a, b), a < b, in ``combinations`` order. The edges
    are ``edges`` (``(edges, edge_of)`` as returned, from :func:`mesh_edges`) when given, else
    found as the mesh's facets are (one sort of packed keys,
    :func:`~signorini.fem.topology.distinct_entities`); row i holds
    its lower entries, its diagonal, then its upper entries.
    """
    found = edges if edges is not None else \
        distinct_entities(t, combinations(range(t.shape[0]), 2), nodes)
    if found is None:
        raise ValueError(f"K's pattern: {nodes:,} nodes are too many to pack an edge in an int64")
    (edge_low, edge_high), edge_of = found[0].astype(np.int64), found[1]
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
    return indptr, indices, diagonal, upper, lower, edge_of


def mesh_edges(mesh: Any) -> tuple[np.ndarray, np.ndarray] | None:
    """The edges a simplex mesh already has, sorted lexicographically as :func:`node_pairs`
    finds them, and the edge of each element's local pair (a, b), a < b, in ``combinations``
    order: a triangle mesh's facets, a tetrahedral mesh's edges once scikit-fem or
    :func:`~signorini.fem.topology.with_edges` has found them; else None."""
    names = ("_facets", "_t2f") if mesh.t.shape[0] == 3 else ("_edges", "_t2e")
    if not all(hasattr(mesh, name) for name in names):
        return None
    edges, of = (getattr(mesh, name) for name in names)
    local = [sorted(pair) for pair in (mesh.elem.refdom.facets if mesh.t.shape[0] == 3
                                       else mesh.elem.refdom.edges)]
    rows = [local.index(list(pair)) for pair in combinations(range(mesh.t.shape[0]), 2)]
    return edges, of[rows]


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
    when axisymmetric) and that of (b, a) its transpose. Summed by ``bincount``
    over each edge of the mesh (:func:`node_pairs`), in element blocks of
    :data:`SIMPLEX_BLOCK` with the elements taken in the order of their lowest
    node, is only ``M = Σ V gₐ g_bᵀ`` of the pairs a < b (3 of 9 for a
    triangle, 6 of 16 for a tetrahedron), whose block is then
    ``λ M + μ Mᵀ + μ tr(M) I``; a node's own M is minus the sum of its edges'
    (``Σ_b g_b = 0`` on every simplex); the hoop terms are summed over every
    pair a ≤ b. Each (high, low) block is its (low, high) block's transpose and
    a node's own block is symmetric, so K is symmetric to the last bit. Entries
    that are exactly zero are dropped, as scikit-fem does; sums that cancel may
    leave a round-off entry where scikit-fem's leave none, or the reverse
    (timings in docs/speed.md, "Building large 3D models" and "2D assembly").
    """
    p, t = mesh.p, mesh.t
    dim, corners = p.shape[0], t.shape[0]
    if corners != dim + 1 or (axisymmetric and dim != 2):
        raise ValueError(f"simplex_stiffness needs triangles in 2D or tetrahedra in 3D (triangles "
                         f"when axisymmetric), got {corners}-node elements in {dim}D: assemble "
                         "them with scikit-fem")
    nodes, elements = p.shape[1], t.shape[1]
    # the elements in the order of their lowest node: what each sum reads and writes lies near
    order = sort_order(t.min(axis=0), nodes)
    t, edges = np.take(t, order, axis=1), mesh_edges(mesh)
    if edges is not None:
        edges = edges[0], np.take(edges[1], order, axis=1)
    indptr, indices, diagonal, upper, lower, edge_of = node_pairs(t, nodes, edges)
    count = upper.size
    first, second = np.array(list(combinations(range(corners), 2))).T
    # Σ V gₐ g_bᵀ of each edge's pairs met as (low, high), then of those met as (high, low)
    sums = np.zeros((dim, dim, 2 * count))
    if axisymmetric:  # the hoop terms of the same, then of each node's own pair
        own_pair = np.r_[first, :corners], np.r_[second, :corners]
        hoop_sums = np.zeros((dim, dim, 2 * count + nodes))
    for start in range(0, elements, SIMPLEX_BLOCK):
        block = t[:, start:start + SIMPLEX_BLOCK]
        grads, volume = barycentric_gradients(p, block)
        reverse = block[first] > block[second]  # the pair met as (high, low)
        where = (edge_of[:, start:start + SIMPLEX_BLOCK] + count * reverse).ravel()
        if axisymmetric:
            hoop = hoop_terms(p, block, grads, volume, own_pair, Lambda, Mu)
            volume = volume * p[0, block].mean(axis=0)  # ∫ r dA
            hoop_where = np.concatenate([where, 2 * count + block.ravel()])
            for (i, j), value in hoop.items():
                hoop_sums[i, j] += np.bincount(hoop_where, value, minlength=hoop_sums.shape[-1])
        scaled, paired = (grads * volume)[:, first], grads[:, second]  # V gₐ, g_b
        for i, j in product(range(dim), repeat=2):
            sums[i, j] += np.bincount(where, (scaled[i] * paired[j]).ravel(), minlength=2 * count)
    M = sums[..., :count] + sums[..., count:].swapaxes(0, 1)  # each edge's, as (low, high)
    # each node's own Σ V gₐ gₐᵀ is minus that of its edges (Σ_b g_b = 0 on every simplex),
    # made symmetric to the last bit
    low, high = np.take(indices, lower), np.take(indices, upper)
    ends = np.concatenate([low, high])
    D = np.empty((dim, dim, nodes))
    for i, j in product(range(dim), repeat=2):
        D[i, j] = D[j, i] if j < i else -np.bincount(ends, np.concatenate([M[i, j], M[j, i]]),
                                                     minlength=nodes)
    if axisymmetric:  # the hoop sums of each edge, as (low, high), and of each node's own pair
        M_hoop = hoop_sums[..., :count] + hoop_sums[..., count:2 * count].swapaxes(0, 1)
        D_hoop = hoop_sums[..., 2 * count:]
    traces = np.trace(M), np.trace(D)
    K = _csr_from_blocks(dim, nodes, indptr, indices, lambda i, j: (
        # the block is V (λ gₐ g_bᵀ + μ g_b gₐᵀ + μ (gₐ · g_b) I) summed: of each edge as
        # (low, high) at ``upper``, its transpose at ``lower``, and of each node at ``diagonal``
        [(upper, _block(Lambda, Mu, M, traces[0], i, j, M_hoop if axisymmetric else None)),
         (lower, _block(Lambda, Mu, M, traces[0], j, i, M_hoop if axisymmetric else None)),
         (diagonal, _block(Lambda, Mu, D, traces[1], i, j, D_hoop if axisymmetric else None))]))
    K.eliminate_zeros()  # the blocks' structural zeros (a pattern as scikit-fem's)
    return K


def _block(Lambda: float, Mu: float, summed: np.ndarray, trace: np.ndarray, i: int, j: int,
           hoop: np.ndarray | None) -> np.ndarray:
    """Entry (i, j) of ``λ S + μ Sᵀ + μ tr(S) I`` (plus the hoop sums) over the last axis of the
    summed ``S`` (dim, dim, ·)."""
    value = Lambda * summed[i, j] + Mu * summed[j, i]
    if i == j:
        value += Mu * trace
    if hoop is not None:
        value += hoop[i, j]
    return value


def _csr_from_blocks(dim: int, nodes: int, indptr: np.ndarray, indices: np.ndarray,
                     entries) -> sp.csr_matrix:
    """The dof matrix (dofs dim·i + c) of a node pattern (``indptr``, ``indices``, sorted) whose
    dim × dim blocks ``entries(c, c')`` gives entry by entry, as (pattern positions, values)
    pairs: written straight into CSR, no block matrix. Entry (c, c') of the q-th block of node
    row i sits at ``dim·(dim·indptr[i] + q) + c·dim·len(i) + c'``, ``len(i)`` the blocks of
    row i; for one (c, c') those positions increase along the pattern."""
    lengths = np.diff(indptr)
    row_of = np.repeat(np.arange(nodes), lengths)
    corner = dim * (np.arange(indices.size) + (dim - 1) * np.take(indptr, row_of))
    stride = dim * np.take(lengths, row_of)
    size = dim * dim * indices.size
    kind = np.int32 if max(size, dim * nodes) < 2 ** 31 else np.int64
    data, columns = np.empty(size), np.empty(size, dtype=kind)
    value = np.empty(indices.size)
    for c, c_ in product(range(dim), repeat=2):
        for where, part in entries(c, c_):
            value[where] = part
        slots = corner + (c * stride + c_)
        data[slots] = value
        columns[slots] = dim * indices + c_
    starts = dim * dim * indptr[:-1, None] + dim * np.arange(dim) * lengths[:, None]
    K = sp.csr_matrix((data, columns, np.append(starts.ravel(), size).astype(kind)),
                      shape=(dim * nodes, dim * nodes))
    K.has_sorted_indices = True  # within a row: the pattern's sorted nodes, c' fastest
    return K


__all__ = ["triangle_gradients", "corner_coordinates", "tetrahedron_gradients",
           "barycentric_gradients", "node_pairs", "mesh_edges", "hoop_terms", "simplex_stiffness"]
