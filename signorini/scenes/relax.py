"""Well-shaped graded triangles: relax a point set as a truss of springs, re-triangulating.

Refining by bisection grades a mesh but leaves right-angled triangles (median
smallest angle about 39°); P1 elements on near-equilateral triangles are
markedly more accurate per dof (docs/accuracy.md measures it on Hertz's
cylinder). This module moves the nodes of a graded mesh as the joints of a
truss whose bars push apart until each is about as long as the size field
asks, re-triangulates (Delaunay) when the nodes have moved, and keeps them
inside the domain by projecting with its signed distance — the force-based
smoothing of Persson & Strang, "A simple mesh generator in MATLAB" (SIAM
Review 46, 2004), written here for the package's convex 2D domains.
"""

from __future__ import annotations

from typing import Callable

import numpy as np
from skfem import MeshTri

Field = Callable[[np.ndarray], np.ndarray]

#: bars are sized a little longer than asked so that they push (Persson & Strang use 1.2)
STRETCH = 1.2
STEP = 0.2
#: re-triangulate after a node moved this fraction of its size; stop below the second
RETRIANGULATE, SETTLED = 0.3, 5e-3
MAX_STEPS = 200


def _gradient(distance: Field, p: np.ndarray, eps: float) -> np.ndarray:
    """Central differences of the signed distance at points ``p`` (2, k)."""
    dx = np.array([[eps], [0.0]])
    dy = np.array([[0.0], [eps]])
    return np.array([distance(p + dx) - distance(p - dx), distance(p + dy) - distance(p - dy)]) / (2 * eps)


def _delaunay(p: np.ndarray, general_position: bool) -> np.ndarray:
    """Delaunay triangles (k, 3) of the points ``p`` (2, k).

    Points in general position have one Delaunay triangulation, which Triangle
    computes an order of magnitude faster than qhull. Nodes of a mesh refined
    by bisection are co-circular by fours, where each code picks its own
    diagonal: those go to qhull, whose picks the package's meshes are made of.
    """
    if general_position:
        import triangle

        return triangle.triangulate({"vertices": p.T})["triangles"]
    from scipy.spatial import Delaunay  # on use: scipy.spatial is slow to import

    return Delaunay(p.T).simplices


def _triangulate(p: np.ndarray, distance: Field, tol: float,
                 general_position: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Delaunay triangles whose centroid is inside the domain, and their unique edges."""
    t = _delaunay(p, general_position)
    t = t[distance(p[:, t].mean(axis=2)) < -tol]
    bars = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [0, 2]]]), axis=1)
    keys = np.unique(bars[:, 0] * p.shape[1] + bars[:, 1])
    return t, np.column_stack([keys // p.shape[1], keys % p.shape[1]])


def relax(points: np.ndarray, distance: Field, size: Field, fixed: np.ndarray,
          snap: Callable[[np.ndarray, float], np.ndarray]) -> MeshTri:
    """Relax ``points`` (2, k) inside the domain ``distance < 0`` towards edge lengths ``size``.

    ``fixed`` indexes points that must not move (corners); ``snap(p, tol)``
    puts the points within ``tol`` of a piece of the boundary exactly on it.
    Returns the final Delaunay triangulation, counter-clockwise.
    """
    p = np.array(points, dtype=float)
    h = size(p)
    eps = 1e-3 * float(h.min())
    free = np.ones(p.shape[1], dtype=bool)
    free[fixed] = False
    last = np.full_like(p, np.inf)
    t = bars = None
    for step in range(MAX_STEPS):
        if np.max(np.linalg.norm(p - last, axis=0) / h) > RETRIANGULATE:
            last = p.copy()
            t, bars = _triangulate(p, distance, eps, general_position=step > 0)
        start, end = p[:, bars[:, 0]], p[:, bars[:, 1]]
        vec = start - end
        length = np.linalg.norm(vec, axis=0)
        wanted = size(0.5 * (start + end))
        wanted *= STRETCH * np.sqrt(np.sum(length ** 2) / np.sum(wanted ** 2))
        push = np.maximum(wanted - length, 0.0) / length * vec
        n = p.shape[1]
        force = np.array([np.bincount(bars[:, 0], push[k], n) - np.bincount(bars[:, 1], push[k], n)
                          for k in range(2)])
        move = STEP * force * free
        p += move
        signed = distance(p)
        outside = signed > 0
        if outside.any():  # projected back: only their distance changes
            p[:, outside] -= signed[outside] * _gradient(distance, p[:, outside], eps)
            signed[outside] = distance(p[:, outside])
        h = size(p)
        inside = free & (signed < -eps)
        if not inside.any() or np.max(np.linalg.norm(move[:, inside], axis=0) / h[inside]) < SETTLED:
            break
    p = snap(p, 10 * eps)
    t, _ = _triangulate(p, distance, eps)
    a, b, c = p[:, t[:, 0]], p[:, t[:, 1]], p[:, t[:, 2]]
    area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    t[area < 0] = t[area < 0][:, [0, 2, 1]]
    t = t[np.abs(area) > 1e-12 * float(h.min()) ** 2]
    used = np.unique(t)
    index = np.full(p.shape[1], -1)
    index[used] = np.arange(used.size)
    return MeshTri(np.ascontiguousarray(p[:, used]), np.ascontiguousarray(index[t].T))


__all__ = ["relax"]
