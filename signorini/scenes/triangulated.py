"""The Hertz scenes' quarter disc meshed by Shewchuk's Triangle (quality Delaunay refinement).

The boundary is split first, at a spacing given by the size field, with the
arc's points computed on the circle; Triangle then triangulates inside that
fixed boundary and refines until every triangle is no larger than the
equilateral triangle of the local size and no angle is below
:data:`MIN_ANGLE` (Shewchuk, "Delaunay refinement algorithms for triangular
mesh generation", Comput. Geom. 22, 2002), through the ``triangle`` binding.
This is ``mesher=triangle`` of the Hertz scenes
(:func:`signorini.scenes.meshing.graded_quarter_disc`), the cylinder's default:
much faster than bisection followed by the node relaxation, with
near-equilateral triangles (docs/mesher.md compares the three meshers).
"""

from __future__ import annotations

from typing import Callable

import numpy as np
import triangle  # Shewchuk's Triangle
from skfem import MeshTri

Field = Callable[[np.ndarray], np.ndarray]

#: the edge length asked of Triangle, as a fraction of the size field h(x). Bisection stops once
#: every longest edge is at most h(x), so its edges are on average well below h(x); at this
#: fraction Triangle's default Hertz meshes have about as many nodes as the bisection meshes
TRIANGLE_SIZE = 0.68
#: the smallest angle Triangle is asked to keep, in degrees (its refinement is proven to end for
#: bounds up to about 33.8°); triangles touching the fixed boundary may fall a little below it
MIN_ANGLE = 30
#: at most this many refinement passes, each asking anew for the areas at the new triangles
TRIANGLE_PASSES = 6
#: the area of the equilateral triangle of unit side
EQUILATERAL = 0.25 * np.sqrt(3.0)


def arc(s: np.ndarray) -> np.ndarray:
    """The arc of the unit circle about (0, 1) from the first point of contact (0, 0), s = 0,
    to (1, 1), s = 1: every point on the circle to rounding."""
    angle = 0.5 * np.pi * np.asarray(s, dtype=float)
    return np.array([np.sin(angle), 1.0 - np.cos(angle)])


def top_cut(s: np.ndarray) -> np.ndarray:
    """The cut y = 1 through the centre, from (1, 1), s = 0, to the centre (0, 1), s = 1."""
    s = np.asarray(s, dtype=float)
    return np.array([1.0 - s, np.ones_like(s)])


def axis_cut(s: np.ndarray) -> np.ndarray:
    """The axis x = 0, from the centre (0, 1), s = 0, to the first point of contact, s = 1."""
    s = np.asarray(s, dtype=float)
    return np.array([np.zeros_like(s), 1.0 - s])


#: the quarter disc's boundary counter-clockwise from the first point of contact, as
#: (curve of s ∈ [0, 1], its length); each curve ends where the next begins
QUARTER_DISC_BOUNDARY = ((arc, 0.5 * np.pi), (top_cut, 1.0), (axis_cut, 1.0))


def triangle_size(size: Field) -> Field:
    """The edge lengths asked of Triangle: :data:`TRIANGLE_SIZE` (read at the call) times the
    size field ``size``."""
    scale = TRIANGLE_SIZE
    return lambda points: scale * size(points)


def _steps_along(curve: Field, size: Field, length: float) -> tuple[np.ndarray, np.ndarray]:
    """Parameters s sampled along ``curve`` and the number of local sizes ``∫ ds / size`` from
    s = 0 to each. The samples are even, plus geometric towards both ends, where a curve meets
    the fine zone, so that a size much smaller than the curve is resolved."""
    smallest = float(size(curve(np.linspace(0.0, 1.0, 1001))).min())
    towards_end = np.geomspace(min(0.1 * smallest / length, 1e-3), 1.0, 1000)
    s = np.unique(np.concatenate([np.linspace(0.0, 1.0, 2001), towards_end, 1.0 - towards_end]).clip(0.0, 1.0))
    points = curve(s)
    middles = 0.5 * (points[:, 1:] + points[:, :-1])
    steps = np.linalg.norm(np.diff(points, axis=1), axis=0) / size(middles)
    return s, np.concatenate([[0.0], np.cumsum(steps)])


def boundary_points(curve: Field, size: Field, length: float) -> np.ndarray:
    """Points ``curve(s)`` for s from 0 up to, not including, 1, one local size apart.

    The number of sizes along the curve is rounded to a whole number n ≥ 1 and the points are
    placed where ``∫ ds / size`` reaches 0, 1/n, ..., (n − 1)/n of it. The end ``curve(1)`` is
    the next curve's first point. ``length`` is the curve's length (to resolve the small sizes).
    """
    s, count = _steps_along(curve, size, length)
    n = max(1, int(round(count[-1])))
    return curve(np.interp(np.linspace(0.0, count[-1], n + 1)[:-1], count, s))


def triangulated_quarter_disc(size: Field, max_elements: int) -> MeshTri:
    """A quality Delaunay mesh, by Triangle, of the quarter disc ``x ≥ 0, y ≤ 1, x² + (y − 1)² ≤ 1``
    with edges of about ``size(x)`` (pass :func:`triangle_size` of the size field).

    The boundary is split by :func:`boundary_points` and kept as it is (Triangle's ``Y``: no
    point is added on it, so the arc's nodes, the contact candidates, lie on the circle). Each
    pass asks every triangle for at most the area of the equilateral triangle of side
    ``size(centroid)`` and a smallest angle of :data:`MIN_ANGLE`, until a pass adds no node or
    :data:`TRIANGLE_PASSES` are done. Raises ``RuntimeError`` past ``max_elements`` triangles.
    """
    vertices = np.hstack([boundary_points(curve, size, length)
                          for curve, length in QUARTER_DISC_BOUNDARY]).T
    n = len(vertices)
    segments = np.column_stack([np.arange(n), (np.arange(n) + 1) % n])
    switches = f"pq{MIN_ANGLE}Y"
    mesh = triangle.triangulate({"vertices": vertices, "segments": segments}, switches)
    for _ in range(TRIANGLE_PASSES):
        centroids = mesh["vertices"][mesh["triangles"]].mean(axis=1).T
        nodes = len(mesh["vertices"])
        mesh = triangle.triangulate({**mesh, "triangle_max_area": EQUILATERAL * size(centroids) ** 2},
                                    f"r{switches}a")
        if len(mesh["triangles"]) > max_elements:
            raise RuntimeError(f"mesh grading exceeded {max_elements} elements")
        if len(mesh["vertices"]) == nodes:
            break
    return MeshTri(np.ascontiguousarray(mesh["vertices"].T, dtype=float),
                   np.ascontiguousarray(mesh["triangles"].T))


__all__ = ["arc", "top_cut", "axis_cut", "triangle_size", "boundary_points",
           "triangulated_quarter_disc"]
