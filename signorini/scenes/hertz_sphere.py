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
with ``r ≤ candidates · a`` are contact candidates. The default mesh is on the
accuracy-time front of docs/mesher.md. A finite sphere is not Hertz's half-space:
the converged model's a and p₀ differ from Hertz's in proportion to a/R, most at
ν = 0, and a finer mesh need not bring them nearer (docs/accuracy.md §3).

Hertz (Johnson 1985, §4.2): ``a = (3PR/(4E*))^(1/3)``, ``p₀ = 3P/(2πa²)``.
"""

from __future__ import annotations

import numpy as np

from signorini.references.analytic import hertz_sphere_load, hertz_sphere_radius
from signorini.scenes.base import (
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
    length,
    poisson_ratio,
    positive,
    refinements,
    two_refinements_coarser,
)
from signorini.scenes.hertz_cylinder import HertzDisc
from signorini.scenes.meshing import quarter_disc_snap
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
    grading(0.15),
    candidates("contact radius"),
    refinements(),
    LOADING,
    MESHER,
)

#: the analytic reference (signorini.references.catalogue) this family's problems compare with
REFERENCE = "hertz-3d"

#: one sphere: Hertz's formulas, per radian (2π in the whole sphere); a push δ grades the mesh
#: for Hertz's ``a = √(δR)``
SPHERE = HertzDisc(REFERENCE, hertz_sphere_radius, hertz_sphere_load, 2.0 * np.pi,
                   axisymmetric=True, graded_by_delta=True)
load_choice = SPHERE.loads
build = SPHERE.build
graded_ratio = SPHERE.graded_ratio


#: the default mesh's dofs and how they grow, fitted to the meshes built (docs/calibration.md)
SIZE = SizeModel(6824, 60, 0.15, 0.05, uniform=5.2, alpha=0.65, beta=1.15, far_field=100.0,
                 margin=1.13, ratio=graded_ratio)

#: adaptive refinement starts from the relaxed mesh: on Triangle's its pressure estimate
#: overstates the error more and would refine past the target (docs/estimate.md)
ADAPTIVE_START = {"mesher": "relaxed", "n_contact": 60, "grading": 0.15}

FAMILY = SceneFamily(
    name="hertz-sphere",
    summary="elastic sphere on a rigid flat, axisymmetric (r, z) model graded to the contact",
    params=PARAMS, build=build, loads=load_choice, reference=REFERENCE, size_model=SIZE,
    coarse=two_refinements_coarser, snap=quarter_disc_snap,
    validation=(Case("hertz-sphere", "hertz-sphere", {"a_over_R": 0.05}),),
    convergence_start={"n_contact": 12, "grading": 0.6},
    adaptive_start=ADAPTIVE_START)


__all__ = ["SPHERE", "load_choice", "build", "graded_ratio", "COMMON_PARAMS", "REFERENCE", "SIZE", "FAMILY"]
