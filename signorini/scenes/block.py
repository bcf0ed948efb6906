"""An elastic block pressed onto a rigid flat: uniform pressure, checkable by hand.

The right half ``[0, W] × [0, H]`` of a ``2W``-wide block, plane strain: the
cut x = 0 is a symmetry plane, the top is pushed down by δ (u_x free), the
bottom rests on the flat ``y = 0`` without friction. Every bottom node is in
contact with the pressure ``p = E* δ / H`` (uniaxial plane strain), so the
full block carries ``P = 2 W p`` per unit thickness.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from skfem import MeshTri

from .base import FlatObstacle, Param, SceneFamily, SceneModel, at_least, poisson_ratio, positive

PARAMS = (
    Param("W", 1.0, "half-width of the block", check=positive),
    Param("H", 1.0, "height of the block", check=positive),
    Param("E", 1.0, "Young's modulus", check=positive),
    Param("nu", 0.3, "Poisson's ratio", check=poisson_ratio),
    Param("delta", 0.01, "prescribed downward displacement of the top", check=positive),
    Param("nx", 16, "elements along the width", kind=int, check=at_least(1)),
    Param("ny", 16, "elements along the height", kind=int, check=at_least(1)),
)


def build(p: dict[str, Any], given: set[str] | None = None) -> SceneModel:
    """The half block in physical units."""
    mesh = MeshTri.init_tensor(np.linspace(0.0, p["W"], p["nx"] + 1),
                               np.linspace(0.0, p["H"], p["ny"] + 1))
    x, y = mesh.p
    tol = 1e-12 * max(p["W"], p["H"])
    bottom = np.nonzero(np.abs(y) < tol)[0]
    facets = mesh.boundary_facets()
    on_bottom = np.all(np.isin(mesh.facets[:, facets], bottom), axis=0)
    top = np.nonzero(np.abs(y - p["H"]) < tol)[0]
    return SceneModel(
        mesh=mesh, E=p["E"], nu=p["nu"],
        dirichlet=[(0, np.nonzero(np.abs(x) < tol)[0], 0.0), (1, top, -p["delta"])],
        contact_nodes=bottom[np.argsort(x[bottom])], contact_facets=facets[on_bottom],
        obstacle=FlatObstacle(0.0), load_dofs=(1, top), length_scale=p["H"],
        force_multiplicity=2.0, params=dict(p))


FAMILY = SceneFamily(name="block", summary="elastic block pressed onto a rigid flat (uniform pressure)",
                     params=PARAMS, build=build, reference="uniform")
