"""Hertz's sphere, axisymmetric: an elastic sphere of radius R on a rigid flat, in (r, z).

A body of revolution loaded along its axis deforms without depending on the
angle, so the meridian half-plane (r, z), r ≥ 0, carries the whole problem:
the same quarter disc as the cylinder's model, now read as the lower half of
the sphere's meridian section, with the axisymmetric elasticity forms (weight
r, hoop strain u_r/r; see :func:`signorini.fem.assembly.axisymmetric_elasticity`).
The axis r = 0 has u_r = 0; the cut z = R through the centre is pushed down
by a uniform δ (u_z = −δ, u_r free), adjusted until the contact force equals
the target load. Forces are assembled per radian and the model's
``force_multiplicity`` is 2π, so reported loads are those of the whole sphere.
The mesh is graded towards the first point of contact; only the arc nodes
with ``r ≤ candidates · a`` are contact candidates. Default mesh (``n_contact=48``,
``grading=0.15``, Triangle: 5,421 dofs): the fastest solve in process among the
meshes that hold the sphere within 0.1 % of Hertz at ν = 0.3 and 0.45 and 0.15 %
at ν = 0.499 (docs/mesher.md). A finite sphere is not Hertz's half-space: the
converged model's a and p₀ differ from Hertz's in proportion to a/R, most at
ν = 0; at a/R = 0.05 and ν = 0.3 a finer mesh moves p₀ away from Hertz's, not
towards it, and within 0.05 % of Hertz the sphere needs a/R ≤ 0.0025
(docs/accuracy.md §3).

Hertz (Johnson 1985, §4.2): ``a = (3PR/(4E*))^(1/3)``, ``p₀ = 3P/(2πa²)``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from signorini.references.analytic import contact_modulus, hertz_sphere_load, hertz_sphere_radius
from signorini.errors import InputError
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
    checked_ratio,
    contact_ratio,
    grading_check,
    hertz_record,
    length,
    poisson_ratio,
    positive,
    two_refinements_coarser,
)
from signorini.scenes.meshing import disc_loading, graded_quarter_disc, quarter_disc_on, quarter_disc_snap
from signorini.scenes.size import SizeModel

COMMON_PARAMS = (
    Param("R", 1.0, "sphere radius", check=length),
    Param("E", 1.0, "Young's modulus", check=positive),
    Param("nu", 0.3, "Poisson's ratio", check=poisson_ratio),
    VOLUMETRIC,
    Param("P", None, "total load on the sphere (exclusive with a_over_R, delta)", check=positive),
    Param("a_over_R", 0.05, "contact radius over sphere radius: sets P by Hertz's formula",
          check=contact_ratio),
    Param("delta", None, "prescribed downward displacement of the centre cut (no load targeting)",
          check=positive),
)

PARAMS = COMMON_PARAMS + (
    Param("n_contact", 48, "elements across the contact radius (mesh fineness)", kind=int,
          check=at_least(4)),
    Param("grading", 0.15, "growth of the element size with distance from the contact zone",
          check=grading_check),
    Param("candidates", 2.0, "contact candidates extend to this multiple of the contact radius",
          check=at_least(1.2)),
    Param("refine", 0, "uniform refinements of the graded mesh (each quadruples the dofs)",
          kind=int, check=lambda k: None if 0 <= k <= 6 else "in 0..6"),
    LOADING,
    MESHER,
)


def load_choice(p: dict[str, Any], given: set[str]) -> tuple[float | None, float]:
    """The target load P (None when δ is prescribed) and the estimated a/R.

    One of ``P``, ``a_over_R`` (the default) or ``delta`` sets the load; with
    ``delta`` the estimate of a/R is Hertz's ``√(δ/R)`` from ``δ = a²/R``.
    """
    chosen = {name for name in given & {"P", "a_over_R", "delta"} if p[name] is not None}
    if len(chosen) > 1:
        raise InputError(f"scene parameters {' and '.join(sorted(chosen))} both set the load: "
                         "give only one of P, a_over_R, delta")
    R, E_star = p["R"], contact_modulus(p["E"], p["nu"])
    if "delta" in chosen:
        return None, checked_ratio(float(np.sqrt(p["delta"] / R)), "delta", p["delta"])
    if "P" in chosen:
        return p["P"], checked_ratio(hertz_sphere_radius(p["P"], R, E_star) / R, "P", p["P"])
    return hertz_sphere_load(p["a_over_R"] * R, R, E_star), p["a_over_R"]


#: the analytic reference (signorini.references.catalogue) this family's problems compare with
REFERENCE = "hertz-3d"

def build(p: dict[str, Any], given: set[str] | None = None, mesh: Any = None) -> SceneModel:
    """The axisymmetric model of Hertz's sphere in physical units (meridian plane (r, z))."""
    given = set() if given is None else given
    R = p["R"]
    target, a_est = load_choice(p, given)
    if mesh is not None:  # the scene on a given mesh (adaptive refinement: signorini.scenes.adapt)
        disc = quarter_disc_on(mesh, R, a_est, p["candidates"])
    else:
        disc = graded_quarter_disc(R, a_est, p["n_contact"], p["grading"], p["refine"],
                                   p["candidates"], mesher=p["mesher"])
    delta_nominal = p["delta"] if target is None else a_est ** 2 * R
    pushed, cut_load = disc_loading(disc, p["loading"], target)
    return SceneModel(
        mesh=disc.mesh, E=p["E"], nu=p["nu"],
        dirichlet=[(0, disc.axis, 0.0), (1, pushed, -delta_nominal)],
        contact_nodes=disc.candidates, contact_facets=disc.contact_facets,
        obstacle=FlatObstacle(0.0),
        load_dofs=(1, pushed), length_scale=R, force_multiplicity=2.0 * np.pi,
        target_load=target, **hertz_record(p, REFERENCE, target, a_est, delta_nominal),
        axisymmetric=True, cut_load=cut_load, candidate_remedy=CANDIDATE_REMEDY.format(**p),
        predicted_contact=disc.mesh.p[0, disc.candidates] < a_est * R)


def graded_ratio(p: dict[str, Any]) -> float:
    """The a/R a sphere's mesh is graded for: the load's (``P``, ``delta`` or ``a_over_R``)."""
    return load_choice(p, {k for k in ("P", "delta") if p.get(k) is not None})[1]


#: the default mesh's dofs and how they grow, fitted to the meshes built (docs/calibration.md)
SIZE = SizeModel(6824, 60, 0.15, 0.05, uniform=5.2, alpha=0.65, beta=1.15, far_field=100.0,
                 margin=1.13, ratio=graded_ratio)

#: adaptive refinement starts from the relaxed mesh: its pressure estimate is within a factor 2
#: of the true error there, and 3-6 on Triangle's meshes, which would refine past the target
#: (docs/estimate.md)
ADAPTIVE_START = {"mesher": "relaxed", "n_contact": 60, "grading": 0.15}

FAMILY = SceneFamily(
    name="hertz-sphere",
    summary="elastic sphere on a rigid flat, axisymmetric (r, z) model graded to the contact",
    params=PARAMS, build=build, loads=load_choice, reference=REFERENCE, size_model=SIZE,
    coarse=two_refinements_coarser, snap=quarter_disc_snap,
    validation=(Case("hertz-sphere", "hertz-sphere", {"a_over_R": 0.05}),),
    convergence_start={"n_contact": 12, "grading": 0.6},
    adaptive_start=ADAPTIVE_START)


__all__ = ["load_choice", "build", "graded_ratio", "COMMON_PARAMS", "SIZE", "FAMILY"]
