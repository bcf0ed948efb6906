"""Meshes graded towards the contact zone, built by local refinement in scikit-fem.

The target element size is ``h(x) = h_contact + grading · dist(x, zone)``:
uniform and fine where the pressure varies, growing linearly away from it.
Elements longer than the target are split (conforming red-green-blue
refinement) until none is; nodes created on a curved boundary are moved onto
it after every pass.
"""

from __future__ import annotations

import logging
from typing import Callable

import numpy as np
from scipy.spatial import Delaunay
from skfem import MeshTri

log = logging.getLogger(__name__)

MAX_PASSES = 40


def longest_edges(mesh: MeshTri) -> np.ndarray:
    """Longest edge of each triangle."""
    p, t = mesh.p, mesh.t
    lengths = [np.linalg.norm(p[:, t[i]] - p[:, t[(i + 1) % 3]], axis=0) for i in range(3)]
    return np.max(lengths, axis=0)


def refine_to_size(mesh: MeshTri, target: Callable[[np.ndarray], np.ndarray],
                   snap: Callable[[MeshTri], MeshTri] | None = None,
                   max_elements: int = 400_000) -> MeshTri:
    """Refine ``mesh`` until every element's longest edge is ≤ ``target(centroid)``."""
    for _ in range(MAX_PASSES):
        centroids = mesh.p[:, mesh.t].mean(axis=1)
        marked = np.nonzero(longest_edges(mesh) > target(centroids))[0]
        if marked.size == 0:
            return mesh
        if mesh.t.shape[1] > max_elements:
            raise RuntimeError(f"mesh grading exceeded {max_elements} elements")
        mesh = mesh.refined(marked)
        if snap is not None:
            mesh = snap(mesh)
    log.warning("mesh grading stopped after %d passes", MAX_PASSES)
    return mesh


def distance_to_segment(points: np.ndarray, start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """Euclidean distance from each column of ``points`` (2, k) to the segment [start, end]."""
    direction = end - start
    length2 = float(direction @ direction)
    rel = points - start[:, None]
    s = np.clip((direction @ rel) / length2, 0.0, 1.0) if length2 > 0 else 0.0
    nearest = start[:, None] + np.outer(direction, s)
    return np.linalg.norm(points - nearest, axis=0)


def coarse_quarter_disc(rings: int = 4) -> MeshTri:
    """A coarse triangulation of the quarter disc below the centre (0, 1), radius 1.

    The region is ``x ≥ 0, y ≤ 1, x² + (y − 1)² ≤ 1``; its lowest point, the
    first point of contact, is the origin.
    """
    points = [(0.0, 1.0)]
    for k in range(1, rings + 1):
        r = k / rings
        for theta in np.linspace(-np.pi / 2, 0.0, 2 * k + 1):
            points.append((r * np.cos(theta), 1.0 + r * np.sin(theta)))
    p = np.array(points)
    t = Delaunay(p).simplices
    a, b, c = p[t[:, 0]], p[t[:, 1]], p[t[:, 2]]
    area = 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    keep = np.abs(area) > 1e-12
    return MeshTri(p.T, t[keep].T)


def on_circle_arc(mesh: MeshTri, centre: tuple[float, float], radius: float,
                  tol: float = 1e-9) -> np.ndarray:
    """Boundary nodes that lie on the curved part of a quarter disc (not on its two cuts)."""
    nodes = mesh.boundary_nodes()
    x, y = mesh.p[:, nodes]
    return nodes[(x > centre[0] + tol) & (y < centre[1] - tol)]


def snap_to_circle(centre: tuple[float, float], radius: float) -> Callable[[MeshTri], MeshTri]:
    """A function moving the arc's boundary nodes radially onto the circle."""
    c = np.asarray(centre, dtype=float)

    def snap(mesh: MeshTri) -> MeshTri:
        nodes = on_circle_arc(mesh, centre, radius)
        p = mesh.p.copy()
        offset = p[:, nodes] - c[:, None]
        p[:, nodes] = c[:, None] + radius * offset / np.linalg.norm(offset, axis=0)
        return MeshTri(p, mesh.t)

    return snap
