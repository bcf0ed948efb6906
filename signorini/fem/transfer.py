"""P1 fields from a mesh to its refinement: every new node is the midpoint of an old edge.

Uniform refinement (:func:`signorini.scenes.meshing.refine_uniformly`) and
scikit-fem's conforming ``MeshTri.refined(marked)`` both add nodes at edge
midpoints after the old ones, so a P1 field moves to the finer mesh by
averaging each new node's two parents. Nodes later moved onto a curved
boundary keep that average (the coarse field carried along with the node).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree


def edge_keys(first: np.ndarray, second: np.ndarray, n: int) -> np.ndarray:
    """One integer per undirected edge ``(first[k], second[k])`` of a mesh of ``n`` nodes."""
    low, high = np.minimum(first, second), np.maximum(first, second)
    return low.astype(np.int64) * n + high


def uniform_parents(t: np.ndarray, n: int) -> np.ndarray:
    """(2, edges) parents of the nodes uniform refinement adds: edge k in sorted key order
    becomes node ``n + k`` (as :func:`signorini.scenes.meshing.refine_uniformly` numbers them)."""
    pairs = [(i, j) for i in range(t.shape[0]) for j in range(i + 1, t.shape[0])]
    edges = np.unique(np.concatenate([edge_keys(t[i], t[j], n) for i, j in pairs]))
    return np.array([edges // n, edges % n])


def midpoint_parents(mesh: Any, points: np.ndarray) -> np.ndarray:
    """(2, k) the old edge of ``mesh`` whose midpoint each of ``points`` (dim, k) is.

    Raises ValueError when a point is not the midpoint of an edge (up to round-off).
    """
    facets = mesh.edges if hasattr(mesh, "edges") and mesh.p.shape[0] == 3 else mesh.facets
    middles = 0.5 * (mesh.p[:, facets[0]] + mesh.p[:, facets[1]])
    distance, index = cKDTree(middles.T).query(points.T)
    size = float(np.max(np.abs(mesh.p))) if mesh.p.size else 1.0
    if len(distance) and np.max(distance) > 1e-9 * max(size, 1.0):
        raise ValueError("a new node is not the midpoint of an edge of the old mesh")
    return facets[:, index]


def prolongation(n_old: int, parents: np.ndarray) -> sp.csr_matrix:
    """The (n_old + k) × n_old matrix that keeps old nodal values and averages each new node's
    two ``parents`` (2, k)."""
    k = parents.shape[1]
    rows = np.concatenate([np.arange(n_old), np.repeat(n_old + np.arange(k), 2)])
    cols = np.concatenate([np.arange(n_old), parents.T.ravel()])
    values = np.concatenate([np.ones(n_old), np.full(2 * k, 0.5)])
    return sp.csr_matrix((values, (rows, cols)), shape=(n_old + k, n_old))


def uniform_prolongation(t: np.ndarray, n: int, times: int = 1) -> sp.csr_matrix:
    """The prolongation of ``times`` uniform refinements of the triangles ``t`` over ``n`` nodes."""
    P = sp.identity(n, format="csr")
    for _ in range(times):
        parents = uniform_parents(t, n)
        step = prolongation(n, parents)
        P = step @ P
        t = _split(t, n, parents)
        n = step.shape[0]
    return P


def _split(t: np.ndarray, n: int, parents: np.ndarray) -> np.ndarray:
    """The triangles of one uniform refinement (children at the edge midpoints)."""
    keys = edge_keys(parents[0], parents[1], n)
    mid = [n + np.searchsorted(keys, edge_keys(t[i], t[j], n)) for i, j in ((0, 1), (1, 2), (2, 0))]
    m01, m12, m20 = mid
    return np.hstack([np.vstack([t[0], m01, m20]), np.vstack([t[1], m12, m01]),
                      np.vstack([t[2], m20, m12]), np.vstack([m01, m12, m20])])
