"""Meshes graded towards the contact zone, built by local refinement in scikit-fem.

The target element size is ``h(x) = h_contact + grading · dist(x, zone)``:
uniform and fine where the pressure varies, growing linearly away from it.
Elements longer than the target are split (conforming red-green-blue
refinement of triangles, longest-edge bisection of tetrahedra) until none is;
nodes created on a curved boundary are moved onto it after every pass. The
Hertz scenes' quarter disc is kept so, or relaxed into near-equilateral
triangles (:mod:`signorini.scenes.relax`), or meshed by Triangle instead
(:mod:`signorini.scenes.triangulated`): :func:`graded_quarter_disc`'s ``mesher``.
"""

from __future__ import annotations

import logging
from contextlib import contextmanager
from dataclasses import dataclass
from functools import lru_cache
from itertools import combinations
from typing import Any, Callable

import numpy as np
from skfem import Mesh, MeshTri

from signorini.fem.model import CutLoad
from signorini.fem.topology import edge_keys, facets_on, moved, with_topology
from signorini.fem.transfer import split_uniformly
from signorini.scenes.relax import relax
from signorini.scenes.triangulated import triangle_size, triangulated_quarter_disc

log = logging.getLogger(__name__)

MAX_PASSES = 40
#: the most triangles a graded 2D mesh may reach (before any uniform refinement)
MAX_TRIANGLES = 400_000
#: the meshers of the Hertz scenes' quarter disc (:func:`graded_quarter_disc`); each scene picks its
#: default (its ``mesher`` parameter)
MESHERS = ("relaxed", "bisection", "triangle")


def refine_to_size(mesh: MeshTri, target: Callable[[np.ndarray], np.ndarray],
                   snap: Callable[[MeshTri], MeshTri] | None = None,
                   max_elements: int = MAX_TRIANGLES) -> MeshTri:
    """Refine the triangles of ``mesh`` until every longest edge is ≤ ``target(centroid)``
    (:func:`refine_simplices_to_size` with at most :data:`MAX_PASSES` passes)."""
    return refine_simplices_to_size(mesh, target, snap, max_elements, max_passes=MAX_PASSES)


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
    from scipy.spatial import Delaunay  # on use: scipy.spatial is slow to import

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
    nodes = with_topology(mesh).boundary_nodes()
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
        return moved(mesh, p)

    return snap


def quarter_disc_snap(params: dict[str, Any]) -> Callable[[MeshTri], MeshTri]:
    """New arc nodes of the Hertz scenes' quarter disc of radius ``params["R"]`` moved radially
    onto the circle (a family's ``snap``)."""
    return snap_to_circle((0.0, params["R"]), params["R"])


# --- refinement of triangles and tetrahedra alike -------------------------------------------


def longest_simplex_edges(mesh: Mesh) -> np.ndarray:
    """Longest edge of each simplex (triangle or tetrahedron) of ``mesh``."""
    p, t = mesh.p, mesh.t
    pairs = combinations(range(t.shape[0]), 2)
    return np.max([np.linalg.norm(p[:, t[i]] - p[:, t[j]], axis=0) for i, j in pairs], axis=0)


#: the most simplices a graded mesh may reach (before any uniform refinement)
MAX_ELEMENTS = 2_000_000


def refine_simplices_to_size(mesh: Mesh, target: Callable[[np.ndarray], np.ndarray],
                             snap: Callable[[Mesh], Mesh] | None = None,
                             max_elements: int = MAX_ELEMENTS, max_passes: int = 120) -> Mesh:
    """Refine ``mesh`` until every simplex's longest edge is ≤ ``target(centroid)``.

    Works for triangles and tetrahedra alike (scikit-fem's ``refined(marked)``:
    red-green-blue for triangles, longest-edge bisection for tetrahedra, which
    halves an edge only every few passes, hence the larger pass limit).
    """
    for _ in range(max_passes):
        centroids = mesh.p[:, mesh.t].mean(axis=1)
        marked = np.nonzero(longest_simplex_edges(mesh) > target(centroids))[0]
        if marked.size == 0:
            return mesh
        if mesh.t.shape[1] > max_elements:
            raise RuntimeError(f"mesh grading exceeded {max_elements} elements")
        with _skfem_copy_warnings_silenced():
            mesh = with_topology(mesh).refined(marked)
        if snap is not None:
            mesh = snap(mesh)
    log.warning("mesh grading stopped after %d passes", max_passes)
    return mesh


@contextmanager
def _skfem_copy_warnings_silenced():
    """scikit-fem's tetrahedral ``refined(marked)`` builds its new mesh from array slices and
    then warns (once per pass) that it copies them to C order; the copy is harmless."""
    logger = logging.getLogger("skfem.mesh.mesh")
    level = logger.level
    logger.setLevel(logging.ERROR)
    try:
        yield
    finally:
        logger.setLevel(level)


@dataclass(frozen=True)
class GradedDisc:
    """The quarter of a disc of radius R below its centre, graded towards the contact point.

    ``candidates`` are the arc nodes with ``x ≤ candidate_extent · a`` sorted by
    x, ``contact_facets`` the arc's boundary facets, ``axis`` the nodes on the
    cut x = 0 and ``top`` those on the cut through the centre, y = R.
    """

    mesh: MeshTri
    candidates: np.ndarray
    contact_facets: np.ndarray
    axis: np.ndarray
    top: np.ndarray
    top_facets: np.ndarray

    @property
    def centre(self) -> int:
        """The node at the disc's centre, where the axis meets the top cut."""
        return int(np.intersect1d(self.axis, self.top)[0])


def cut_loading(top: np.ndarray, centre: int, top_facets: np.ndarray, loading: str,
                target: float | None, component: int = 1):
    """The pushed nodes and the cut load of a Hertz scene whose cut through the centre has the
    nodes ``top`` and the ``top_facets``: the whole cut, or its ``centre`` node and a traction
    along ``component``. With a prescribed displacement (no ``target``) the cut is pushed flat.
    """
    if loading == "displacement" or target is None:
        return top, None
    return np.array([centre]), CutLoad(component=component, nodes=top, facets=top_facets)


def quarter_disc_distance(p: np.ndarray) -> np.ndarray:
    """Signed distance (negative inside) to the quarter disc x ≥ 0, y ≤ 1 of the unit disc at (0, 1)."""
    return np.maximum.reduce([np.hypot(p[0], p[1] - 1.0) - 1.0, -p[0], p[1] - 1.0])


def snap_quarter_disc(p: np.ndarray, tol: float) -> np.ndarray:
    """Points within ``tol`` of the axis, the cut or the arc, put exactly on it."""
    p = p.copy()
    p[0, np.abs(p[0]) < tol] = 0.0
    p[1, np.abs(p[1] - 1.0) < tol] = 1.0
    radius = np.hypot(p[0], p[1] - 1.0)
    on_arc = (np.abs(radius - 1.0) < tol) & (p[0] > 0) & (p[1] < 1.0)
    p[:, on_arc] = np.array([[0.0], [1.0]]) + (p[:, on_arc] - np.array([[0.0], [1.0]])) / radius[on_arc]
    return p


def graded_quarter_disc(R: float, a_over_R: float, n_contact: int, grading: float,
                        refine: int = 0, candidate_extent: float = 2.0,
                        mesher: str = "relaxed") -> GradedDisc:
    """Mesh a quarter disc with ``n_contact`` elements across the expected half-width a.

    The element size is ``a/n_contact`` on the zone [0, 1.25 a] of the arc and
    grows by ``grading`` per unit distance from it; ``refine`` uniform
    refinements follow, each with the arc's new nodes moved onto the circle.
    ``mesher`` makes the graded mesh (one of :data:`MESHERS`): ``bisection``
    refines a coarse mesh to the size (right-angled triangles); ``relaxed`` then
    moves its nodes into near-equilateral triangles
    (:func:`signorini.scenes.relax.relax`: more accurate per dof); ``triangle`` is
    Triangle's quality mesh (:func:`signorini.scenes.triangulated.triangulated_quarter_disc`:
    much faster, near-equilateral), built from a/R to 12 digits so that the same scene in other
    units gives the same mesh. The last graded unit discs are kept (:func:`graded_unit_disc`).
    """
    if mesher not in MESHERS:
        raise ValueError(f"mesher={mesher!r} is not a mesher of the quarter disc: "
                         f"choose one of {', '.join(MESHERS)}")
    if mesher == "triangle":  # a ratio computed in other units differs in its last bits, which
        a_over_R = float(f"{a_over_R:.12g}")  # would tip Triangle's near-cocircular choices
    p, t, chain = graded_unit_disc(a_over_R, n_contact, grading, mesher)
    for _ in range(refine):
        p, t, chain = refine_uniformly(p, t, chain)
        offset = p[:, chain] - np.array([[0.0], [1.0]])
        p[:, chain] = np.array([[0.0], [1.0]]) + offset / np.linalg.norm(offset, axis=0)
    return quarter_disc_on(MeshTri(p * R, t.copy()), R, a_over_R, candidate_extent)


@lru_cache(maxsize=8)
def graded_unit_disc(a_over_R: float, n_contact: int, grading: float,
                     mesher: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The graded quarter of the unit disc of :func:`graded_quarter_disc`: its points, triangles
    and the arc's nodes from the bottom (read-only: kept for the next call with these values)."""
    h_contact, zone_end = a_over_R / n_contact, np.array([1.25 * a_over_R, 0.0])

    def target_size(points: np.ndarray) -> np.ndarray:
        dist = distance_to_segment(points, np.zeros(2), zone_end)
        return np.minimum(h_contact + grading * dist, 0.25)

    if mesher == "triangle":
        mesh = triangulated_quarter_disc(triangle_size(target_size), MAX_TRIANGLES)
    else:
        mesh = refine_to_size(coarse_quarter_disc(), target_size, snap=snap_to_circle((0.0, 1.0), 1.0))
    if mesher == "relaxed":
        corners = [int(np.argmin(np.hypot(mesh.p[0] - x, mesh.p[1] - y))) for x, y in ((0, 0), (0, 1), (1, 1))]
        mesh = relax(mesh.p, quarter_disc_distance, target_size, corners, snap_quarter_disc)
    chain = arc_chain(mesh, 1.0)
    mesh.p.flags.writeable = mesh.t.flags.writeable = chain.flags.writeable = False
    return mesh.p, mesh.t, chain


def refine_uniformly(p: np.ndarray, t: np.ndarray,
                     chain: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Split every triangle into four at its edge midpoints; ``chain`` (a boundary polyline of
    node indices) gains its segments' midpoints in order.

    The same mesh as scikit-fem's ``refined()`` up to node numbering, built from integer edge
    keys (one 1D sort, :func:`~signorini.fem.transfer.split_uniformly`) rather than a sort of
    index pairs: several times faster on 10⁶ nodes.
    """
    n = p.shape[1]
    parents, children = split_uniformly(t, n)
    segment = np.searchsorted(edge_keys(parents[0], parents[1], n),
                              edge_keys(chain[:-1], chain[1:], n))
    chain_new = np.empty(2 * len(chain) - 1, dtype=np.int64)
    chain_new[0::2], chain_new[1::2] = chain, n + segment
    return np.hstack([p, 0.5 * (p[:, parents[0]] + p[:, parents[1]])]), children, chain_new


def facet_indices(mesh: MeshTri, first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """scikit-fem's facet index of each edge ``(first[k], second[k])`` of ``mesh``."""
    n = mesh.p.shape[1]
    keys = edge_keys(mesh.facets[0], mesh.facets[1], n)
    order = np.argsort(keys)
    wanted = edge_keys(np.asarray(first), np.asarray(second), n)
    found = order[np.searchsorted(keys, wanted, sorter=order)]
    if not np.array_equal(keys[found], wanted):
        raise ValueError("an edge of the chain is not an edge of the mesh")
    return found


def arc_chain(mesh: MeshTri, R: float) -> np.ndarray:
    """The nodes of the arc of the quarter disc of radius R below (0, R), with its two ends (the
    first point of contact and the top corner), in order from the bottom."""
    x, y = mesh.p
    arc = on_circle_arc(mesh, (0.0, R), R, tol=1e-9 * R)
    ends = np.nonzero((np.hypot(x, y) < 1e-9 * R) | (np.hypot(x - R, y - R) < 1e-9 * R))[0]
    chain = np.union1d(arc, ends)
    return chain[np.argsort(np.arctan2(y[chain] - R, x[chain]))]


def quarter_disc_on(mesh: MeshTri, R: float, a_over_R: float,
                    candidate_extent: float = 2.0) -> GradedDisc:
    """The parts of any triangulation of the quarter disc of radius R below (0, R), by position.

    The arc is every boundary node off the two cuts, ordered from the first
    point of contact: how :func:`graded_quarter_disc` finds the parts of its
    own mesh, and how :mod:`signorini.scenes.adapt` finds them on a refined one.
    """
    mesh = with_topology(mesh)
    x, y = mesh.p
    chain = arc_chain(mesh, R)
    candidates = chain[(x[chain] <= candidate_extent * a_over_R * R * (1 + 1e-9))
                       & (y[chain] < R * (1 - 1e-12))]
    top = np.nonzero(np.abs(y - R) < 1e-12 * R)[0]
    return GradedDisc(mesh=mesh, candidates=candidates[np.argsort(x[candidates])],
                      contact_facets=facet_indices(mesh, chain[:-2], chain[1:-1]),  # not the top corner
                      axis=np.nonzero(np.abs(x) < 1e-12 * R)[0], top=top,
                      top_facets=facets_on(mesh, top))


__all__ = ["refine_to_size", "distance_to_segment", "coarse_quarter_disc", "on_circle_arc",
           "snap_to_circle", "quarter_disc_snap", "longest_simplex_edges",
           "refine_simplices_to_size", "GradedDisc", "cut_loading", "quarter_disc_distance",
           "snap_quarter_disc", "graded_quarter_disc", "graded_unit_disc", "refine_uniformly",
           "facet_indices", "arc_chain", "quarter_disc_on", "MAX_TRIANGLES", "MESHERS", "MAX_ELEMENTS"]
