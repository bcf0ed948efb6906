"""A simplex mesh's facets found by sorting one integer per facet, for scikit-fem to use.

scikit-fem finds a mesh's facets (``facets``, ``t2f``, ``f2t``) on first use
by ``np.unique(..., axis=1)`` over the sorted node triples, which sorts
columns lexicographically, and does it again for every new mesh object,
even one that only moved or scaled the nodes: a large part of building a
large 3D scene, which makes many meshes (docs/speed.md, "Building large 3D
models"). Here each facet's sorted nodes are packed into one int64 (node
indices below 2²¹ per component in 3D), so one stable ``argsort`` of a flat
array gives the same arrays in the same order: ``facets`` sorted
lexicographically, ``t2f`` its inverse, ``f2t`` the first and last element
of each facet in scikit-fem's own counting (``-1`` on the boundary).
:func:`with_topology` stores them where scikit-fem looks (its private
``_facets``, ``_t2f``, ``_f2t``; tests/test_topology.py holds them equal to
scikit-fem's own on every kind of mesh the scenes build, so that a change
of scikit-fem shows there), and :func:`moved` makes a mesh with new node
positions that keeps the old one's facets.
"""

from __future__ import annotations

from typing import Any

import numpy as np

#: the attributes scikit-fem computes lazily from the connectivity alone
TOPOLOGY = ("_facets", "_t2f", "_f2t")


def packed_keys(nodes: np.ndarray, count: int) -> np.ndarray | None:
    """One int64 per column of sorted node indices (k, m), ordered as the columns are
    lexicographically; None when ``count`` nodes do not fit."""
    k = nodes.shape[0]
    if float(count) ** k >= 2.0 ** 63:
        return None
    key = np.zeros(nodes.shape[1], dtype=np.int64)
    for row in nodes:
        key = key * count + row
    return key


def edge_keys(first: np.ndarray, second: np.ndarray, n: int) -> np.ndarray:
    """One integer per undirected edge ``(first[k], second[k])`` of a mesh of ``n`` nodes."""
    low, high = np.minimum(first, second), np.maximum(first, second)
    return low.astype(np.int64) * n + high


def sort_order(keys: np.ndarray, bound: int) -> np.ndarray:
    """``np.argsort(keys, kind="stable")`` of non-negative integer ``keys`` below ``bound``.

    When a key and its position fit in 63 bits together, by one sort of the
    values ``key · 2ᵇ + position`` (numpy's SIMD value sort, several times
    faster than an index sort); when its high and its low bits each fit with
    the position, by two such sorts (low bits, then high bits: a radix sort
    of two digits, each sort stable); else by ``argsort``.
    """
    shift = max(keys.size - 1, 1).bit_length()
    bits = max(bound - 1, 1).bit_length()
    if bits + shift <= 63:
        return np.sort((keys.astype(np.int64) << shift) | np.arange(keys.size)) & ((1 << shift) - 1)
    low = 63 - shift  # too long: sorted by its low bits, then stably by its high bits
    if low < 1 or bits - low + shift > 63:
        return np.argsort(keys, kind="stable")
    first = sort_order(keys & ((1 << low) - 1), 1 << low)
    return np.take(first, sort_order(np.take(keys >> low, first), 1 << (bits - low)))


#: compare-and-swap pairs that sort 2, 3 or 4 rows
NETWORKS = {2: ((0, 1),), 3: ((0, 1), (1, 2), (0, 1)),
            4: ((0, 1), (2, 3), (0, 2), (1, 3), (1, 2))}


def sorted_columns(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each column of ``keys`` (2 to 4 rows) sorted, ``np.sort(keys, axis=0)``, and whether
    sorting it took an odd permutation: a sorting network, each swap one transposition (a few
    element-wise passes, many times faster than a sort along the short axis)."""
    rows = [row.copy() for row in keys]
    odd = np.zeros(keys.shape[1], dtype=bool)
    for i, j in NETWORKS[len(rows)]:
        swap = rows[i] > rows[j]
        rows[i], rows[j] = np.where(swap, rows[j], rows[i]), np.where(swap, rows[i], rows[j])
        odd ^= swap
    return np.array(rows), odd


def distinct_entities(t: np.ndarray, local_entities, count: int):
    """The distinct sorted node tuples of the sub-simplices ``local_entities`` of each element
    of ``t`` (edges or facets), ordered lexicographically, each element's index into them
    (entities, elements), and the sort that found them: ``(entities, inverse, order, starts)``;
    None when ``count`` nodes do not pack into one int64 per entity."""
    local = [list(f) for f in local_entities]
    corners, _ = sorted_columns(np.hstack([t[f] for f in local]))  # (nodes, per_element · ne)
    key = packed_keys(corners, count)
    if key is None:
        return None
    order = sort_order(key, count ** corners.shape[0])
    ordered = np.take(key, order)
    new = np.ones(ordered.size, dtype=bool)
    new[1:] = ordered[1:] != ordered[:-1]
    starts = np.nonzero(new)[0]
    inverse = np.empty(ordered.size, dtype=np.int64)
    inverse[order] = np.cumsum(new) - 1
    entities = np.ascontiguousarray(np.take(corners, np.take(order, starts), axis=1))
    return entities, inverse.reshape(len(local), t.shape[1]), order, starts


def facet_topology(t: np.ndarray, local_facets, count: int):
    """``(facets, t2f, f2t)`` of the connectivity ``t`` (scikit-fem's layout), or None when the
    node count is too large to pack (scikit-fem then computes them itself)."""
    found = distinct_entities(t, local_facets, count)
    if found is None:
        return None
    facets, t2f, order, starts = found
    ends = np.append(starts[1:], order.size) - 1
    element = order % t.shape[1]  # the flat index of a facet is (local facet, element)
    f2t = np.empty((2, starts.size), dtype=np.int32)
    f2t[0] = np.take(element, starts)
    f2t[1] = np.where(ends > starts, np.take(element, ends), -1)
    return facets, t2f, f2t


def with_edges(mesh: Any) -> Any:
    """``mesh`` with its edges (scikit-fem's ``edges`` and ``t2e``, what its uniform
    refinement of tetrahedra reads) found here by one sort of packed keys, as the facets are
    (:func:`facet_topology`), if scikit-fem has not found them yet: the same arrays."""
    edges = getattr(mesh.elem.refdom, "edges", None)
    if edges is None or hasattr(mesh, "_edges") or mesh.t.shape[0] != mesh.p.shape[0] + 1:
        return mesh
    found = distinct_entities(mesh.t, edges, mesh.p.shape[1])
    if found is not None:
        object.__setattr__(mesh, "_edges", found[0])
        object.__setattr__(mesh, "_t2e", found[1])
    return mesh


def with_topology(mesh: Any) -> Any:
    """``mesh`` with its facets computed here if scikit-fem has not yet (simplices only)."""
    if all(hasattr(mesh, name) for name in TOPOLOGY) or mesh.t.shape[0] != mesh.p.shape[0] + 1:
        return mesh
    found = facet_topology(mesh.t, mesh.elem.refdom.facets, mesh.p.shape[1])
    if found is not None:
        for name, value in zip(TOPOLOGY, found):
            object.__setattr__(mesh, name, value)
    return mesh


def moved(mesh: Any, p: np.ndarray) -> Any:
    """A mesh of ``mesh``'s type with nodes at ``p`` and the same elements, sharing its facets."""
    new = type(mesh)(np.ascontiguousarray(p), mesh.t)
    with_topology(mesh)
    for name in TOPOLOGY:
        if hasattr(mesh, name):
            object.__setattr__(new, name, getattr(mesh, name))
    return new


def outward_normals(mesh: Any, facets: np.ndarray, unit: bool = True) -> np.ndarray:
    """The normals (dim, k) of the boundary ``facets`` (edges in 2D, triangles in 3D) pointing
    out of the body: of unit length, or (``unit=False``) as long as the edge (twice the
    triangle's area)."""
    mesh = with_topology(mesh)
    p, ends = mesh.p, mesh.facets[:, facets]
    if p.shape[0] == 2:
        tangent = p[:, ends[1]] - p[:, ends[0]]
        normal = np.array([tangent[1], -tangent[0]])
    else:
        normal = np.cross(p[:, ends[1]] - p[:, ends[0]], p[:, ends[2]] - p[:, ends[0]], axis=0)
    inside = p[:, mesh.t[:, mesh.f2t[0, facets]]].mean(axis=1)
    normal = normal * np.sign(np.einsum("ij,ij->j", normal, p[:, ends].mean(axis=1) - inside))
    return normal / np.linalg.norm(normal, axis=0) if unit else normal


def facets_on(mesh: Any, nodes: np.ndarray) -> np.ndarray:
    """The boundary facets whose ends are all among ``nodes`` (triangles or tetrahedra)."""
    boundary = with_topology(mesh).boundary_facets()
    inside = np.isin(mesh.facets[:, boundary], nodes).all(axis=0)
    return boundary[inside]


__all__ = ["packed_keys", "edge_keys", "distinct_entities", "sort_order", "sorted_columns", "facet_topology",
           "with_edges", "with_topology", "moved", "facets_on", "outward_normals", "TOPOLOGY"]
