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

from typing import Any

import numpy as np

from signorini.fem.model import CutLoad, FlatObstacle3D, SceneModel
from signorini.fem.topology import facets_on, moved
from signorini.scenes.base import CANDIDATE_REMEDY, LOADING, Param, SceneFamily, at_least, between
from signorini.scenes.hertz_sphere import COMMON_PARAMS, load_choice, recorded_params
from signorini.scenes.meshing import (
    coarse_ball_octant,
    curved_boundary_facets,
    distance_to_disc,
    on_ball_octant_surface,
    refine_simplices_to_size,
    snap_to_sphere,
)

PARAMS = COMMON_PARAMS + (
    Param("n_contact", 10, "elements across the contact radius (mesh fineness)", kind=int,
          check=at_least(3)),
    Param("grading", 0.5, "growth of the element size with distance from the contact zone",
          check=between(0.0, 2.0)),
    Param("candidates", 1.3, "contact candidates extend to this multiple of the contact radius",
          check=at_least(1.2)),
    Param("refine", 0, "uniform refinements of the graded mesh (each multiplies the dofs by "
          "about 8)", kind=int, check=lambda k: None if 0 <= k <= 3 else "in 0..3"),
    LOADING,
)

#: largest element edge anywhere (unit sphere)
MAX_SIZE = 0.3


def build(p: dict[str, Any], given: set[str] | None = None) -> SceneModel:
    """The quarter model of Hertz's sphere in physical units (z vertical, contact at the origin)."""
    given = set() if given is None else given
    R = p["R"]
    target, a_est = load_choice(p, given)
    h_contact = a_est / p["n_contact"]

    def target_size(points: np.ndarray) -> np.ndarray:
        dist = distance_to_disc(points, 1.25 * a_est)
        return np.minimum(h_contact + p["grading"] * dist, MAX_SIZE)

    centre = (0.0, 0.0, 1.0)
    snap = snap_to_sphere(centre, 1.0)
    mesh = refine_simplices_to_size(coarse_ball_octant(), target_size, snap=snap)
    for _ in range(p["refine"]):  # eight children per tetrahedron, new surface nodes snapped
        mesh = snap(mesh.refined())
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
    pushed, cut_load = top, None
    if p["loading"] == "traction" and target is not None:  # as the disc scenes (CutLoad)
        pushed = np.array([top[np.argmin(rho[top])]])
        cut_load = CutLoad(component=2, nodes=top, facets=facets_on(mesh, top))
    candidates = candidates[np.lexsort((x[candidates], rho[candidates]))]
    return SceneModel(
        mesh=mesh, E=p["E"], nu=p["nu"],
        dirichlet=[(0, np.nonzero(np.abs(x) < tol)[0], 0.0),
                   (1, np.nonzero(np.abs(y) < tol)[0], 0.0),
                   (2, pushed, -delta_nominal)],
        contact_nodes=candidates, contact_facets=curved,
        obstacle=FlatObstacle3D(0.0),
        load_dofs=(2, pushed), length_scale=R, force_multiplicity=4.0,
        target_load=target, params=recorded_params(p, target, a_est, delta_nominal),
        cut_load=cut_load, predicted_contact=rho[candidates] < a_est * R,
        candidate_remedy=CANDIDATE_REMEDY.format(**p))


FAMILY = SceneFamily(
    name="hertz-sphere-3d",
    summary="elastic sphere on a rigid flat, 3D quarter model (two symmetry planes) "
            "graded to the contact",
    params=PARAMS, build=build, loads=load_choice, reference="hertz-3d")
