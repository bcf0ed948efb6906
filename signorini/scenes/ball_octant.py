"""The lower octant of a ball in tetrahedra: the 3D sphere's mesh before and after grading.

A coarse octant from scikit-fem's ball, its curved surface found facet by facet, nodes moved
back onto the sphere after each refinement pass (:func:`snap_to_sphere`, checked for inverted
tetrahedra), and the distance to the contact disc that grades it; the refinement itself is
:func:`signorini.scenes.meshing.refine_simplices_to_size`.
"""

from __future__ import annotations

from typing import Callable

import numpy as np
from skfem import MeshTet

from signorini.fem.checks import signed_measures
from signorini.fem.topology import moved, with_topology


def coarse_ball_octant(refinements: int = 2) -> MeshTet:
    """A coarse tetrahedral mesh of the lower octant of the unit ball centred at (0, 0, 1).

    The region is ``x ≥ 0, y ≥ 0, z ≤ 1, x² + y² + (z − 1)² ≤ 1``: its
    lowest point, the first point of contact, is the origin. Built from
    scikit-fem's ball (whose eight initial tetrahedra are its octants),
    refined uniformly with the boundary moved onto the sphere, then cut.
    """
    ball = MeshTet.init_ball(refinements)
    centroids = ball.p[:, ball.t].mean(axis=1)
    octant = ball.restrict(np.nonzero((centroids[0] > 0) & (centroids[1] > 0)
                                      & (centroids[2] < 0))[0])
    p = octant.p + np.array([[0.0], [0.0], [1.0]])
    return MeshTet(np.ascontiguousarray(p), np.ascontiguousarray(octant.t))


def on_ball_octant_surface(mesh: MeshTet, centre: tuple[float, float, float],
                           tol: float = 1e-9) -> np.ndarray:
    """Nodes on the curved surface of a ball octant cut by the planes through ``centre``.

    A boundary facet is curved unless its three nodes lie in one of the cut
    planes ``x = cₓ``, ``y = c_y``, ``z = c_z``; the nodes of curved facets
    (including those on the rims where a plane meets the sphere) are returned.
    """
    curved = curved_boundary_facets(mesh, centre, tol)  # finds the facets first (fast)
    return np.unique(mesh.facets[:, curved])


def curved_boundary_facets(mesh: MeshTet, centre: tuple[float, float, float],
                           tol: float = 1e-9) -> np.ndarray:
    """Boundary facets of a ball octant that are not in one of its three cut planes."""
    facets = with_topology(mesh).boundary_facets()
    coords = mesh.p[:, mesh.facets[:, facets]]  # (3, 3 nodes, facets)
    planar = np.zeros(facets.size, dtype=bool)
    for axis in range(3):
        planar |= np.all(np.abs(coords[axis] - centre[axis]) < tol, axis=0)
    return facets[~planar]


def snap_to_sphere(centre: tuple[float, float, float],
                   radius: float) -> Callable[[MeshTet], MeshTet]:
    """A function moving the curved surface nodes of a ball octant radially onto the sphere.

    Radial moves from the centre keep nodes in the cut planes through it.
    Raises ``RuntimeError`` if a move turns a tetrahedron inside out (the
    mesh was too coarse near the surface for its curvature): the signed
    volumes (:func:`signorini.fem.checks.signed_measures`) before and after are compared on the tetrahedra with a node
    that moved, the only ones whose volume changed.
    """
    c = np.asarray(centre, dtype=float)[:, None]

    def snap(mesh: MeshTet) -> MeshTet:
        nodes = on_ball_octant_surface(mesh, centre)
        p = mesh.p.copy()
        offset = p[:, nodes] - c
        p[:, nodes] = c + radius * offset / np.linalg.norm(offset, axis=0)
        snapped = moved(mesh, p)
        changed = np.zeros(p.shape[1], dtype=bool)
        changed[nodes] = np.any(p[:, nodes] != mesh.p[:, nodes], axis=0)
        touched = np.nonzero(np.take(changed, mesh.t).any(axis=0))[0]
        corners = np.take(mesh.t, touched, axis=1)
        before, after = signed_measures(mesh.p, corners), signed_measures(p, corners)
        if np.any(before * after <= 0):
            raise RuntimeError("snapping to the sphere inverted a tetrahedron: "
                               "start from a finer coarse mesh")
        return snapped

    return snap


def distance_to_disc(points: np.ndarray, radius: float, height: float = 0.0) -> np.ndarray:
    """Distance from each column of ``points`` (3, k) to the horizontal disc
    ``{x² + y² ≤ radius², z = height}``."""
    rho = np.hypot(points[0], points[1])
    return np.hypot(np.maximum(rho - radius, 0.0), points[2] - height)


__all__ = ["coarse_ball_octant", "on_ball_octant_surface", "curved_boundary_facets",
           "snap_to_sphere", "distance_to_disc"]
