"""A scene in physical units, ready for assembly: mesh, material, supports, obstacle, load."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from signorini.problem.model import ReferenceData
from signorini.fem.checks import check_model

#: the scenes' parameter ``volumetric``: element by element (plain P1), averaged at the nodes, or
#: ``auto``: averaged from :data:`NODAL_FROM_NU` on
CHOICES = ("auto", "element", "nodal")
#: ``auto`` averages at the nodes from this Poisson's ratio on, in 2D and axisymmetric models:
#: below it the two agree on the Hertz scenes and plain P1's K has fewer nonzeros
#: (docs/accuracy.md, §4; the average: :mod:`signorini.fem.volumetric`).
NODAL_FROM_NU = 0.4


def resolve(choice: str, nu: float, dim: int = 2) -> str:
    """``element`` or ``nodal``: what ``choice`` (one of :data:`CHOICES`) means at Poisson's ratio
    ν on a mesh of dimension ``dim``. ``auto`` keeps plain P1 on tetrahedra: there the average's
    K has 5.2 times the nonzeros, more than the 3D size guards and methods were measured for;
    ``volumetric=nodal`` asks for it explicitly."""
    if choice == "auto":
        return "nodal" if nu >= NODAL_FROM_NU and dim == 2 else "element"
    return choice


@dataclass
class FlatObstacle:
    """A rigid flat ``y = height`` (``z = height`` under a 3D body), approached from above: the
    normal is minus the points' last axis, (0, −1) or (0, 0, −1)."""

    height: float = 0.0

    def normals_and_gaps(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Unit outward normal of the body towards the obstacle and the initial gap per point."""
        normals = np.zeros((len(points), points.shape[1]))
        normals[:, -1] = -1.0
        return normals, points[:, -1] - self.height


@dataclass(frozen=True)
class CutLoad:
    """The load applied as a uniform traction on a cut of the body (as Hertz's theory loads it).

    ``facets`` are the boundary facets of the cut, ``nodes`` their nodes;
    ``component`` the direction of the push (1 = y in 2D, 2 = z in 3D),
    towards the obstacle along its negative axis. The traction is whatever
    makes the full body's load equal the scene's target (uniform over the
    cut, per unit area; in axisymmetric models weighted by the radius), and a
    prescribed displacement of the scene's load dofs (one reference node)
    removes the rigid translation: assembly adjusts it until that dof carries
    no force, so the body is loaded by the traction alone.
    """

    component: int
    nodes: np.ndarray
    facets: np.ndarray


@dataclass
class SceneModel:
    """A scene in physical units, ready for assembly.

    ``dirichlet`` lists ``(component, node indices, value)``: component 0 is x,
    1 is y. ``load_dofs`` are ``(component, nodes)`` whose reactions make up
    the applied load (sign: a push towards the obstacle is positive).
    ``target_load`` (full body, per unit thickness) asks assembly to adjust
    the prescribed displacement ``delta`` until the contact force equals it;
    prescribed values are then ``value × delta / delta_nominal``.
    """

    mesh: Any
    E: float
    nu: float
    dirichlet: list[tuple[int, np.ndarray, float]]
    contact_nodes: np.ndarray
    contact_facets: np.ndarray
    obstacle: Any  # anything with normals_and_gaps(points): see signorini.fem.obstacles
    load_dofs: tuple[int, np.ndarray]
    length_scale: float
    force_multiplicity: float = 1.0
    target_load: float | None = None
    params: dict[str, Any] = field(default_factory=dict)
    #: the mesh is the meridian half-plane (r, z) of a body of revolution; forces per radian
    axisymmetric: bool = False
    #: the target load as a traction on a cut (None: the load is the prescribed displacement's)
    cut_load: CutLoad | None = None
    #: per candidate: in contact by the scene's analytic estimate (load targeting starts there)
    predicted_contact: np.ndarray | None = None
    #: what to change when the contact outgrows the candidates (signorini.certification.adequacy)
    candidate_remedy: str = "extend the scene's contact candidates or lower the load"
    #: the scene parameter ``volumetric``: element, nodal or auto (signorini.fem.volumetric)
    volumetric_choice: str = "auto"
    #: the push δ of the loaded boundary (scene units) without a target load (None: none named)
    delta: float | None = None
    #: what the scene hands its analytic reference (None: it declares none)
    reference: ReferenceData | None = None

    def __post_init__(self) -> None:
        """Refuse a model that cannot be assembled right (:mod:`signorini.fem.checks`): a bad
        mesh, an obstacle that starts inside the body, units beyond double precision."""
        check_model(self)

    @property
    def volumetric(self) -> str:
        """How K integrates λ (tr ε)²: ``element`` (plain P1) or ``nodal`` (signorini.fem.volumetric).

        The scene's ``volumetric_choice`` (``auto`` by default: nodal from ν = 0.4 on in 2D)."""
        return resolve(self.volumetric_choice, self.nu, self.mesh.p.shape[0])


__all__ = ["CHOICES", "NODAL_FROM_NU", "resolve", "FlatObstacle", "CutLoad", "SceneModel"]
