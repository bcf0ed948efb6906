"""Hertz's cylinder: an elastic disc of radius R on a rigid flat, plane strain.

Modelled as the lower-right quarter of the disc (x ≥ 0 below its centre):
the cut x = 0 is a symmetry plane (u_x = 0). By default the cut through the
centre, y = R, carries a uniform traction whose total is the load P (per
unit thickness of the full cylinder, twice the quarter's), as Hertz's theory
loads the body; the centre node is pushed down by δ, and assembly adjusts δ
until that node carries no force (it only removes the rigid translation, so
K is non-singular). ``loading=displacement`` pushes the whole cut down by a
uniform δ instead (the cut stays flat: docs/accuracy.md compares the two), which
is also the model when ``delta`` is given. The mesh is graded towards the
first point of contact and only the arc nodes with ``x ≤ candidates · a`` are
contact candidates. The default mesh is on the accuracy-time front of docs/mesher.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

from signorini.references.analytic import contact_modulus, hertz_cylinder_half_width, hertz_cylinder_load
from signorini.fem.model import FlatObstacle, SceneModel
from signorini.scenes.base import (
    CANDIDATE_REMEDY,
    LOADING,
    MESHER,
    VOLUMETRIC,
    Case,
    Param,
    SceneFamily,
    at_least,
    candidates,
    contact_ratio,
    grading,
    hertz_load,
    hertz_record,
    length,
    poisson_ratio,
    positive,
    refinements,
    two_refinements_coarser,
)
from signorini.scenes.meshing import cut_loading, graded_quarter_disc, quarter_disc_on, quarter_disc_snap
from signorini.scenes.size import SizeModel

#: the analytic reference (signorini.references.catalogue) this family's problems compare with
REFERENCE = "hertz-2d"

PARAMS = (
    Param("R", 1.0, "cylinder radius", check=length),
    Param("E", 1.0, "Young's modulus", check=positive),
    Param("nu", 0.3, "Poisson's ratio", check=poisson_ratio),
    VOLUMETRIC,
    Param("P", None, "load per unit thickness of the full cylinder (exclusive with a_over_R, delta)",
          check=positive),
    Param("a_over_R", 0.05, "contact half-width over radius: sets P by Hertz's formula",
          check=contact_ratio),
    Param("delta", None, "prescribed downward displacement of the centre cut (no load targeting)",
          check=positive),
    Param("n_contact", 24, "elements across the contact half-width (mesh fineness)", kind=int,
          check=at_least(4)),
    grading(0.11),
    candidates(),
    refinements(),
    LOADING,
    MESHER,
)


@dataclass(frozen=True)
class HertzDisc:
    """One elastic body of revolution or cylinder on a rigid flat, modelled as a quarter disc
    graded to the contact: what differs between them is Hertz's ``half_width(P, R, E*)`` and its
    inverse ``load(a, R, E*)``, the reference, the copies ``multiplicity`` of the model in the
    whole body, whether it is axisymmetric and whether a prescribed δ grades the mesh for
    ``√(δ/R)`` (else for ``a_over_R``)."""

    reference: str
    half_width: Callable[[float, float, float], float]
    load: Callable[[float, float, float], float]
    multiplicity: float
    axisymmetric: bool = False
    graded_by_delta: bool = False

    def loads(self, p: dict[str, Any], given: set[str]) -> tuple[float | None, float | None, float]:
        """``(target P or None, prescribed δ or None, a/R the mesh is graded for)``
        (:func:`~signorini.scenes.base.hertz_load`)."""
        return hertz_load(p, given, p["R"], contact_modulus(p["E"], p["nu"]), self.half_width,
                          self.load, graded_by_delta=self.graded_by_delta)

    def graded_ratio(self, p: dict[str, Any]) -> float:
        """The a/R the mesh is graded for: the load's (``P``, ``delta`` or ``a_over_R``)."""
        return self.loads(p, {k for k in ("P", "delta") if p.get(k) is not None})[2]

    def build(self, p: dict[str, Any], given: set[str] | None = None, mesh: Any = None) -> SceneModel:
        """The quarter-disc model in physical units (the meridian plane (r, z) when axisymmetric)."""
        R = p["R"]
        target, delta, a_est = self.loads(p, set() if given is None else given)
        if mesh is not None:  # the scene on a given mesh (adaptive refinement: signorini.scenes.adapt)
            disc = quarter_disc_on(mesh, R, a_est, p["candidates"])
        else:
            disc = graded_quarter_disc(R, a_est, p["n_contact"], p["grading"], p["refine"],
                                       p["candidates"], mesher=p["mesher"])
        delta_nominal = delta if delta is not None else a_est ** 2 * R
        pushed, cut_load = cut_loading(disc.top, disc.centre, disc.top_facets, p["loading"], target)
        return SceneModel(
            mesh=disc.mesh, E=p["E"], nu=p["nu"],
            dirichlet=[(0, disc.axis, 0.0), (1, pushed, -delta_nominal)],
            contact_nodes=disc.candidates, contact_facets=disc.contact_facets,
            obstacle=FlatObstacle(0.0),
            load_dofs=(1, pushed), length_scale=R, force_multiplicity=self.multiplicity,
            target_load=target, **hertz_record(p, self.reference, target, a_est, delta_nominal),
            axisymmetric=self.axisymmetric, cut_load=cut_load,
            candidate_remedy=CANDIDATE_REMEDY.format(**p),
            predicted_contact=disc.mesh.p[0, disc.candidates] < a_est * R)


#: one cylinder: Hertz's plane-strain formulas, the quarter twice in the whole cylinder
CYLINDER = HertzDisc(REFERENCE, hertz_cylinder_half_width, hertz_cylinder_load, 2.0)
build = CYLINDER.build
graded_ratio = CYLINDER.graded_ratio


#: the default mesh's dofs and how they grow, fitted to the meshes built (docs/calibration.md)
SIZE = SizeModel(4866, 40, 0.15, 0.05, uniform=5.2, alpha=0.6, beta=1.15, far_field=100.0,
                 margin=1.18, ratio=graded_ratio)

VALIDATION = (
    Case("hertz-cylinder", "hertz-cylinder", {"a_over_R": 0.05}),
    # coarse enough for the dense backends (≤ 3000 dofs); its Hertz errors are not checked
    Case("hertz-cylinder-coarse", "hertz-cylinder",
         {"a_over_R": 0.05, "n_contact": 16, "grading": 0.4}, check_reference=False),
    Case("hertz-cylinder-SI", "hertz-cylinder", {"E": 2.1e11, "R": 0.01, "a_over_R": 0.05},
         same_as="hertz-cylinder"),
)

#: adaptive refinement starts from the relaxed mesh: on Triangle's its pressure estimate
#: overstates the error more and would refine past the target (docs/estimate.md)
ADAPTIVE_START = {"mesher": "relaxed", "n_contact": 40, "grading": 0.15}

FAMILY = SceneFamily(
    name="hertz-cylinder",
    summary="elastic cylinder on a rigid flat, plane strain, quarter model graded to the contact",
    params=PARAMS, build=build, loads=CYLINDER.loads, reference=REFERENCE, size_model=SIZE,
    coarse=two_refinements_coarser, snap=quarter_disc_snap, validation=VALIDATION,
    convergence_start={"n_contact": 15, "grading": 0.6},
    adaptive_start=ADAPTIVE_START)


__all__ = ["CYLINDER", "HertzDisc", "build", "graded_ratio", "PARAMS", "SIZE", "FAMILY"]
