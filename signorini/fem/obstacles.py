"""Rigid obstacles described by a signed distance, and the gap rows they give.

Convention (one for every obstacle). The obstacle is the set ``φ ≤ 0`` of a
signed distance ``φ`` that is positive where the body may be. At a contact
candidate x of the body

- the **normal** is ``n = −∇φ(x) / |∇φ(x)|``: the body's outward normal
  towards the obstacle (for a body resting on the flat ``y = 0``:
  ``n = (0, −1)``);
- the **gap** is ``g = φ(x) / |∇φ(x)|``: the signed distance to the obstacle
  along n (exactly φ for a true distance, where ``|∇φ| = 1``; the division
  makes any smooth level-set function right to first order);
- the **row of N** is ``nᵀ`` on the node's displacement, so the constraint
  ``n · u ≤ g`` is the linearisation of ``φ(x + u) ≥ 0`` (small displacements,
  as in the rest of the package). A negative gap is an initial overlap.

Every obstacle has ``normals_and_gaps(points) -> (normals, gaps)`` with
``points`` of shape (k, dim), ``normals`` (k, dim) and ``gaps`` (k,), which is
what :func:`signorini.fem.assembly.assemble` consumes. Points and gaps are in the
obstacle's length unit.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Callable, Protocol, runtime_checkable

import numpy as np

from signorini.errors import InputError

log = logging.getLogger(__name__)

#: relative step of the central differences that give a normal when no gradient is known
GRADIENT_STEP = 1e-6


@runtime_checkable
class Obstacle(Protocol):
    """Anything that gives the body's normal and the gap at contact candidates."""

    def normals_and_gaps(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ...


def _points(points: np.ndarray) -> np.ndarray:
    points = np.atleast_2d(np.asarray(points, dtype=float))
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise InputError(f"obstacle points must have shape (k, 2) or (k, 3), got {points.shape}")
    return points


def rows_from_gradient(phi: np.ndarray, gradient: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Normals ``n = −∇φ/|∇φ|`` and gaps ``g = φ/|∇φ|`` from values and gradients of φ.

    Raises InputError where the gradient vanishes (no normal is defined there).
    """
    norm = np.linalg.norm(gradient, axis=1)
    bad = ~(np.isfinite(norm) & (norm > 0)) | ~np.isfinite(phi)
    if np.any(bad):
        i = int(np.argmax(bad))
        raise InputError(f"the obstacle's signed distance has no normal at contact candidate {i} "
                         f"(|∇φ| = {norm[i]:g}, φ = {phi[i]:g}): move the obstacle or the candidate")
    return -gradient / norm[:, None], phi / norm


@dataclass(frozen=True)
class HalfPlane:
    """A rigid flat (a line in 2D, a plane in 3D) through ``point``.

    ``normal`` is the body's outward normal towards the obstacle, i.e. it
    points from the body into the obstacle: ``φ(x) = −n̂ · (x − point)``.
    ``HalfPlane((0, h), (0, −1))`` is the flat ``y = h`` under the body.
    """

    point: tuple[float, ...]
    normal: tuple[float, ...]

    def __post_init__(self) -> None:
        n = np.asarray(self.normal, dtype=float)
        if n.shape != np.shape(self.point) or not np.linalg.norm(n) > 0:
            raise InputError(f"half-plane obstacle: normal {self.normal} must be a non-zero vector "
                             f"with as many components as point {self.point}")

    def signed_distance(self, points: np.ndarray) -> np.ndarray:
        """``φ(x) = −n̂ · (x − point)``."""
        n = np.asarray(self.normal, float) / np.linalg.norm(self.normal)
        return -(_points(points) - np.asarray(self.point, float)) @ n

    def normals_and_gaps(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``n = n̂`` at every point and ``g = φ(x)``."""
        points = _points(points)
        n = np.asarray(self.normal, float) / np.linalg.norm(self.normal)
        return np.tile(n, (len(points), 1)), self.signed_distance(points)


@dataclass(frozen=True)
class Circle:
    """A rigid cylinder (a disc in 2D; a ball in 3D) of ``radius`` around ``centre``.

    ``φ(x) = |x − c| − r``; the normal ``(c − x)/|x − c|`` points from the
    body towards the centre. The body lies outside the disc.
    """

    centre: tuple[float, ...]
    radius: float

    def __post_init__(self) -> None:
        if not (np.isfinite(self.radius) and self.radius > 0):
            raise InputError(f"circle obstacle: radius={self.radius!r} must be > 0")

    def signed_distance(self, points: np.ndarray) -> np.ndarray:
        """``φ(x) = |x − c| − r``."""
        return np.linalg.norm(_points(points) - np.asarray(self.centre, float), axis=1) - self.radius

    def normals_and_gaps(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``n = (c − x)/|c − x|`` and ``g = |x − c| − r``."""
        points = _points(points)
        offset = points - np.asarray(self.centre, float)
        return rows_from_gradient(np.linalg.norm(offset, axis=1) - self.radius,
                                  offset / np.maximum(np.linalg.norm(offset, axis=1), 1e-300)[:, None])


@dataclass(frozen=True)
class FlatPunch:
    """A rigid flat-ended punch under the body, face up, with rounded or sharp corners (2D).

    The punch is the strip ``|x − x₀| ≤ half_width + corner_radius`` below
    ``y = height`` whose two upper corners are rounded with ``corner_radius``
    r: its face is flat for ``|x − x₀| ≤ half_width`` and then falls away
    along quarter circles centred at ``(x₀ ± half_width, height − r)``. It is
    the set within r of the strip ``S₀ = {|x − x₀| ≤ half_width, y ≤ height − r}``,
    so ``φ = dist(x, S₀) − r`` outside ``S₀``. With ``r = 0`` the corners
    are sharp; a point straight above a sharp corner is given the face's
    normal (0, −1).
    """

    half_width: float
    corner_radius: float = 0.0
    height: float = 0.0
    centre_x: float = 0.0

    def __post_init__(self) -> None:
        if not (np.isfinite(self.half_width) and self.half_width > 0):
            raise InputError(f"punch obstacle: half_width={self.half_width!r} must be > 0")
        if not (np.isfinite(self.corner_radius) and self.corner_radius >= 0):
            raise InputError(f"punch obstacle: corner_radius={self.corner_radius!r} must be >= 0")

    def _distance_and_gradient(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        points = _points(points)
        if points.shape[1] != 2:
            raise InputError("the flat punch obstacle is two-dimensional: points must be (k, 2)")
        r = self.corner_radius
        rel_x = points[:, 0] - self.centre_x
        side = np.where(rel_x < 0, -1.0, 1.0)
        out_x = np.abs(rel_x) - self.half_width  # > 0: beside the strip S₀
        out_y = points[:, 1] - (self.height - r)  # > 0: above the strip S₀
        dx, dy = np.maximum(out_x, 0.0), np.maximum(out_y, 0.0)
        outside = np.hypot(dx, dy)
        gradient = np.zeros_like(points)
        ok = outside > 0
        gradient[ok, 0] = side[ok] * dx[ok] / outside[ok]
        gradient[ok, 1] = dy[ok] / outside[ok]
        # on or inside S₀: the nearest face (the top face when tied, as above a sharp corner)
        inside = ~ok
        to_top, to_side = -out_y[inside], -out_x[inside]
        top = to_top <= to_side
        gradient[inside] = np.where(top[:, None], [0.0, 1.0],
                                    np.column_stack([side[inside], np.zeros(inside.sum())]))
        phi = np.where(ok, outside, -np.minimum(-out_y, -out_x)) - r
        return phi, gradient

    def signed_distance(self, points: np.ndarray) -> np.ndarray:
        """``φ(x) = dist(x, S₀) − r`` (negative inside the punch)."""
        return self._distance_and_gradient(points)[0]

    def normals_and_gaps(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``n = −∇φ`` and ``g = φ`` (φ is a true distance here)."""
        return rows_from_gradient(*self._distance_and_gradient(points))


@dataclass(frozen=True)
class SignedDistance:
    """An obstacle given by any signed-distance (or level-set) function ``φ``.

    ``function(points) -> φ`` takes points of shape (k, dim). ``gradient``,
    when given, returns ∇φ of shape (k, dim); otherwise ∇φ comes from central
    differences with step ``step`` (default ``GRADIENT_STEP`` times the
    largest coordinate magnitude, at least ``GRADIENT_STEP``), which costs
    ``2·dim`` more calls of φ and is accurate to about ``step²`` for smooth φ.
    """

    function: Callable[[np.ndarray], np.ndarray]
    gradient: Callable[[np.ndarray], np.ndarray] | None = None
    step: float | None = None

    def _values(self, points: np.ndarray) -> np.ndarray:
        phi = np.asarray(self.function(points), dtype=float).reshape(-1)
        if phi.shape != (len(points),):
            raise InputError(f"signed-distance obstacle: the function returned {phi.shape[0]} values "
                             f"for {len(points)} points")
        return phi

    def numerical_gradient(self, points: np.ndarray) -> np.ndarray:
        """∇φ by central differences ``(φ(x + h eᵢ) − φ(x − h eᵢ)) / 2h``."""
        points = _points(points)
        h = self.step if self.step is not None else \
            GRADIENT_STEP * max(1.0, float(np.max(np.abs(points)))) if points.size else GRADIENT_STEP
        gradient = np.empty_like(points)
        for i in range(points.shape[1]):
            shift = np.zeros(points.shape[1])
            shift[i] = h
            gradient[:, i] = (self._values(points + shift) - self._values(points - shift)) / (2 * h)
        return gradient

    def signed_distance(self, points: np.ndarray) -> np.ndarray:
        return self._values(_points(points))

    def normals_and_gaps(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``n = −∇φ/|∇φ|`` and ``g = φ/|∇φ|``."""
        points = _points(points)
        phi = self._values(points)
        if self.gradient is not None:
            gradient = np.asarray(self.gradient(points), dtype=float).reshape(points.shape)
        else:
            gradient = self.numerical_gradient(points)
        return rows_from_gradient(phi, gradient)


@dataclass(frozen=True)
class ScaledQuery:
    """An obstacle in physical units that answers queries in physical or in scene units.

    :func:`signorini.fem.assembly.assemble` asks at the candidates' physical
    coordinates; a caller may also ask at coordinates divided by the scene's
    length ``L`` (and then gets gaps in units of L). This wrapper knows the
    candidates' physical coordinates, recognises which of the two it is being
    asked, evaluates the physical obstacle and returns gaps in the unit of the
    query. Queries at other points raise ValueError.
    """

    obstacle: Obstacle
    physical_points: np.ndarray
    length_scale: float

    def normals_and_gaps(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        points = _points(points)
        reference = np.asarray(self.physical_points, dtype=float)
        size = max(float(np.max(np.abs(reference))), 1e-300) if reference.size else 1.0
        for unit in (1.0, self.length_scale):
            if points.shape == reference.shape and \
                    np.max(np.abs(points * unit - reference), initial=0.0) <= 1e-9 * size:
                normals, gaps = self.obstacle.normals_and_gaps(reference)
                return normals, gaps / unit
        raise ValueError("obstacle queried at points other than the scene's contact candidates")


__all__ = ["Obstacle", "rows_from_gradient", "HalfPlane", "Circle", "FlatPunch", "SignedDistance",
           "ScaledQuery"]
