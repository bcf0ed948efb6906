"""What adaptive refinement refines (:mod:`signorini.scenes.adapt`): Dörfler's bulk marking.

For the energy norm, the fewest elements that carry a fraction :data:`THETA` of
η² (W. Dörfler, "A convergent adaptive algorithm for Poisson's equation",
SINUM 33 (1996) 1106–1124). For the contact pressure, the fewest candidates
carrying :data:`THETA` of its estimate, with every element within :data:`REACH`
element sizes of them, and the elements carrying :data:`THETA_BULK` of η²
weighted by their nearness to the contact zone (:func:`contact_weights`), so
that the body under and around the contact keeps up with its surface.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from signorini.fem.estimate import ErrorEstimate

__all__ = ["REACH", "THETA", "THETA_BULK", "contact_weights", "dorfler", "elements_near", "mark",
           "node_sizes"]

#: Dörfler's bulk parameter: refine the fewest elements that carry this fraction of η²
THETA = 0.5
#: for the pressure: the fraction of η² refined besides the contact's neighbourhood, and the
#: neighbourhood's radius around a marked candidate in units of its largest element edge
THETA_BULK, REACH = 0.3, 3.0


def dorfler(indicators: np.ndarray, theta: float = THETA) -> np.ndarray:
    """The fewest elements whose squared indicators sum to ``theta`` of the total (largest first)."""
    squares = indicators ** 2
    order = np.argsort(squares)[::-1]
    cumulative = np.cumsum(squares[order])
    count = int(np.searchsorted(cumulative, theta * cumulative[-1])) + 1
    return np.sort(order[:min(count, len(order))])


def node_sizes(mesh: Any) -> np.ndarray:
    """The longest edge at each node of a triangle mesh."""
    sizes = np.zeros(mesh.p.shape[1])
    for a, b in ((0, 1), (1, 2), (0, 2)):
        length = np.linalg.norm(mesh.p[:, mesh.t[a]] - mesh.p[:, mesh.t[b]], axis=0)
        np.maximum.at(sizes, mesh.t[a], length)
        np.maximum.at(sizes, mesh.t[b], length)
    return sizes


def elements_near(mesh: Any, nodes: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Elements with a vertex within ``radius[i]`` of ``nodes[i]``, for some i."""
    from scipy.spatial import cKDTree  # on use: scipy.spatial is slow to import

    near = np.zeros(mesh.p.shape[1], dtype=bool)
    for found in cKDTree(mesh.p.T).query_ball_point(mesh.p[:, nodes].T, radius):
        near[found] = True
    return np.nonzero(near[mesh.t].any(axis=0))[0]


def mark(mesh: Any, found: ErrorEstimate, quantity: str, theta: float = THETA) -> np.ndarray:
    """The elements to refine for ``quantity`` (see the module's docstring)."""
    if quantity == "energy":
        return dorfler(found.elements, theta)
    pressure = found.pressure
    nodes = pressure.nodes[dorfler(np.sqrt(pressure.indicators), theta)]
    near = elements_near(mesh, nodes, REACH * node_sizes(mesh)[nodes])
    weighted = found.elements * contact_weights(mesh, pressure.nodes[pressure.active])
    return np.union1d(near, dorfler(weighted, THETA_BULK))


def contact_weights(mesh: Any, zone: np.ndarray) -> np.ndarray:
    """Each element's weight ``(ℓ / max(d, ℓ))²`` for the pressure's bulk marking: ``d`` the
    distance from its centroid to the nearest node in contact (``zone``), ``ℓ`` the contact
    zone's extent (the diagonal of the box around ``zone``, at least its largest element edge)."""
    from scipy.spatial import cKDTree  # on use: scipy.spatial is slow to import

    if zone.size == 0:
        return np.ones(mesh.t.shape[1])
    points = mesh.p[:, zone]
    extent = max(float(np.linalg.norm(points.max(axis=1) - points.min(axis=1))),
                 float(node_sizes(mesh)[zone].max()))
    distance, _ = cKDTree(points.T).query(mesh.p[:, mesh.t].mean(axis=1).T)
    return (extent / np.maximum(distance, extent)) ** 2
