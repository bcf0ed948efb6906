"""Hertz's sphere as a 3D model: one quarter of the lower half, P1 tetrahedra.

The same sphere as :mod:`signorini.scenes.hertz_sphere`, modelled without
using its axial symmetry, only two mirror planes: the lower octant
``x ≥ 0, y ≥ 0, z ≤ R`` of the ball centred at (0, 0, R), touching the flat
z = 0 at the origin. The planes x = 0 and y = 0 are symmetry planes
(u_x = 0, u_y = 0 respectively), the cut z = R through the centre is pushed
down by a uniform δ (u_z = −δ), adjusted until the contact force equals the
target load; the model's ``force_multiplicity`` is 4, so reported loads are
those of the whole sphere. The mesh is graded by longest-edge bisection
towards the disc of radius 1.25 a around the contact point, and only the
surface nodes within ``candidates · a`` of the axis are contact candidates.
``refine`` splits every tetrahedron of the graded mesh into eight (new nodes
on the sphere moved onto it): the cheap way to a mesh of 10⁶ dofs.

It exists to be compared with the axisymmetric model: the same answer, and
what the third dimension costs (see ``validation/hertz_sphere.py``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from signorini.fem.model import FlatObstacle, SceneModel
from signorini.fem.topology import facets_on, moved, with_edges
from signorini.scenes.base import (
    CANDIDATE_REMEDY,
    LOADING,
    Case,
    Param,
    SceneFamily,
    at_least,
    candidates,
    grading,
    hertz_record,
    refinements,
    two_refinements_coarser,
)
from signorini.scenes.hertz_sphere import COMMON_PARAMS, REFERENCE, graded_ratio, load_choice
from signorini.scenes.ball_octant import (coarse_ball_octant, curved_boundary_facets, distance_to_disc,
                                         on_ball_octant_surface, snap_to_sphere)
from signorini.scenes.meshing import cut_loading, refine_simplices_to_size

PARAMS = COMMON_PARAMS + (
    Param("n_contact", 10, "elements across the contact radius (mesh fineness)", kind=int,
          check=at_least(3)),
    grading(0.5),
    candidates("contact radius", 1.3),
    refinements(3, "multiplies the dofs by about 8"),
    LOADING,
)

#: largest element edge anywhere (unit sphere)
MAX_SIZE = 0.3


def build(p: dict[str, Any], given: set[str] | None = None) -> SceneModel:
    """The quarter model of Hertz's sphere in physical units (z vertical, contact at the origin)."""
    R = p["R"]
    target, _, a_est = load_choice(p, set() if given is None else given)
    h_contact = a_est / p["n_contact"]

    def target_size(points: np.ndarray) -> np.ndarray:
        dist = distance_to_disc(points, 1.25 * a_est)
        return np.minimum(h_contact + p["grading"] * dist, MAX_SIZE)

    centre = (0.0, 0.0, 1.0)
    snap = snap_to_sphere(centre, 1.0)
    mesh = refine_simplices_to_size(coarse_ball_octant(), target_size, snap=snap)
    for _ in range(p["refine"]):  # eight children per tetrahedron, new surface nodes snapped
        mesh = snap(with_edges(mesh).refined())  # scikit-fem's refinement, its edges found fast
    surface = on_ball_octant_surface(mesh, centre)
    curved = curved_boundary_facets(mesh, centre)
    mesh = moved(mesh, mesh.p * R)
    x, y, z = mesh.p
    rho = np.hypot(x, y)
    candidates = surface[(rho[surface] <= p["candidates"] * a_est * R * (1 + 1e-9))
                         & (z[surface] < 0.5 * R)]
    tol = 1e-12 * R
    delta_nominal = p["delta"] if target is None else a_est ** 2 * R
    top = np.nonzero(np.abs(z - R) < tol)[0]
    pushed, cut_load = cut_loading(top, top[np.argmin(rho[top])], facets_on(mesh, top), p["loading"],
                                   target, component=2)
    candidates = candidates[np.lexsort((x[candidates], rho[candidates]))]
    return SceneModel(
        mesh=mesh, E=p["E"], nu=p["nu"],
        dirichlet=[(0, np.nonzero(np.abs(x) < tol)[0], 0.0),
                   (1, np.nonzero(np.abs(y) < tol)[0], 0.0),
                   (2, pushed, -delta_nominal)],
        contact_nodes=candidates, contact_facets=curved,
        obstacle=FlatObstacle(0.0),
        load_dofs=(2, pushed), length_scale=R, force_multiplicity=4.0,
        target_load=target, **hertz_record(p, REFERENCE, target, a_est, delta_nominal),
        cut_load=cut_load, predicted_contact=rho[candidates] < a_est * R,
        candidate_remedy=CANDIDATE_REMEDY.format(**p))


#: the graded octant's dofs ≈ OCTANT_FAR + OCTANT_SCALE · I^OCTANT_POWER, I = ∫ dV / h³ over
#: the unit octant for the target element size h of :func:`build`
#: (the number of tetrahedra the grading asks for): fitted to 18 meshes over grading 0.05..2,
#: n_contact 3..20 and a/R 0.01..0.2, 1.0 to 1.25 times their dofs
OCTANT_FAR, OCTANT_SCALE, OCTANT_POWER = 100.0, 64.4, 0.915
#: a uniform refinement of a tetrahedral mesh of N nodes multiplies them by 1 + edges / nodes,
#: below OCTANT_REFINE[0] − OCTANT_REFINE[1] · N^(-1/3) (the surface's nodes have fewer edges),
#: and never more than 8
OCTANT_REFINE = (7.7, 10.0)


@dataclass(frozen=True)
class GradedOctant:
    """The size of this family's mesh (:func:`build`) from its target element size
    ``h = min(a/n_contact + grading · dist(x, disc of radius 1.25 a), MAX_SIZE)``."""

    dim: int = 3

    def graded(self, p: dict[str, Any]) -> float:
        """The dofs of the graded mesh, before any uniform refinement."""
        a, n, g = graded_ratio(p), float(p["n_contact"]), float(p["grading"])
        with np.errstate(over="ignore"):  # an overflow is an infinite estimate
            return OCTANT_FAR + OCTANT_SCALE * octant_density(a, n, g) ** OCTANT_POWER

    def estimate(self, p: dict[str, Any]) -> float:
        nodes = self.graded(p) / 3.0
        for _ in range(p.get("refine", 0)):
            nodes *= min(8.0, OCTANT_REFINE[0] - OCTANT_REFINE[1] * nodes ** (-1 / 3))
        return 3.0 * nodes


def octant_density(a: float, n_contact: float, grading: float, points: int = 120) -> float:
    """``∫ dV / h³`` over the octant ``x, y ≥ 0, z ≤ 1`` of the unit ball centred at (0, 0, 1),
    ``h = min(a/n_contact + grading · d, MAX_SIZE)``, d the distance to the disc ``ρ ≤ 1.25 a``,
    ``z = 0`` (midpoint rule in (ρ, z), fine near the disc: within 0.5 % of a fine grid's)."""
    h0 = a / n_contact
    edges = np.unique(np.concatenate([np.linspace(0.0, 3.0 * a, points),
                                      np.geomspace(min(h0, a) / 20.0, 1.0, 2 * points), [0.0]]))
    middle, width = 0.5 * (edges[1:] + edges[:-1]), np.diff(edges)
    rho, z = middle[:, None], middle[None, :]
    inside = rho ** 2 + (z - 1.0) ** 2 <= 1.0
    with np.errstate(over="ignore", divide="ignore"):
        h = np.minimum(h0 + grading * np.hypot(np.maximum(rho - 1.25 * a, 0.0), z), MAX_SIZE)
        return float(np.sum(np.where(inside, 0.5 * np.pi * rho * np.outer(width, width) / h ** 3,
                                     0.0)))


FAMILY = SceneFamily(
    name="hertz-sphere-3d",
    summary="elastic sphere on a rigid flat, 3D quarter model (two symmetry planes) "
            "graded to the contact",
    params=PARAMS, build=build, loads=load_choice, reference=REFERENCE, size_model=GradedOctant(),
    coarse=two_refinements_coarser,
    validation=(Case("hertz-sphere-3d", "hertz-sphere-3d", {"a_over_R": 0.05},
                     agrees_with="hertz-sphere"),))


__all__ = ["build", "GradedOctant", "octant_density", "FAMILY"]
