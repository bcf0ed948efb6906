"""Hertz the other way round: an elastic block pressed onto a rigid cylinder, plane strain.

The block ``[−W, W] × [0, H]`` rests on a rigid cylinder of radius R whose
top touches the block's bottom at the origin (centre ``(0, −R)``); the
block's top is pushed down by a uniform δ (u_y = −δ, u_x free) adjusted until
the contact force equals the target load. The obstacle is curved, so every
candidate has its own normal ``(−x, −R)/√(x² + R²)`` (towards the centre)
and gap ``√(x² + R²) − R`` (:class:`signorini.fem.obstacles.Circle`): this scene
exercises obstacles beyond a flat. By default the right half is modelled
with the symmetry plane x = 0; ``half=0`` models the whole width.

For a block much larger than the contact, Hertz's 2D solution holds with
the block's contact modulus (the cylinder is rigid; Johnson 1985, §4.2):
``a = √(4PR/(πE*))``, ``p₀ = 2P/(πa)``, ``p(x) = p₀ √(1 − x²/a²)``, with
P the vertical load. W = H = ``size · a``; the mesh is graded towards
the contact zone and the candidates reach ``candidates · a``.
"""

from __future__ import annotations

from typing import Any

from signorini.references.analytic import contact_modulus
from signorini.problem.model import ReferenceData
from signorini.fem.model import SceneModel
from signorini.fem.obstacles import Circle
from signorini.scenes.base import (
    HALF,
    VOLUMETRIC,
    Case,
    Param,
    SceneFamily,
    at_least,
    block_size,
    candidates,
    contact_ratio,
    grading,
    length,
    poisson_ratio,
    positive,
    refinements,
    two_refinements_coarser,
)
from signorini.scenes.hertz_cylinder import CYLINDER
from signorini.scenes.punch import block_on_obstacle
from signorini.scenes.size import SizeModel

#: the analytic reference (signorini.references.catalogue) this family's problems compare with
REFERENCE = "reverse-hertz"
#: the mesh is uniformly fine on the bottom up to this multiple of the half-width
FINE_END = 1.25

PARAMS = (
    Param("R", 1.0, "radius of the rigid cylinder", check=length),
    Param("E", 1.0, "Young's modulus of the block", check=positive),
    Param("nu", 0.3, "Poisson's ratio of the block", check=poisson_ratio),
    VOLUMETRIC,
    Param("P", None, "vertical load per unit thickness of the whole block "
          "(exclusive with a_over_R, delta)", check=positive),
    Param("a_over_R", 0.02, "contact half-width over radius: sets P by Hertz's formula "
          "(with delta: only sizes the mesh)", check=contact_ratio),
    Param("delta", None, "prescribed downward displacement of the top (no load targeting)",
          check=positive),
    Param("size", 20.0, "block half-width and height in units of the half-width a",
          check=block_size(4.0)),
    Param("n_contact", 128, "elements across the contact half-width (rounded up to a power of two)",
          kind=int, check=at_least(4)),
    grading(0.3),
    candidates(),
    refinements(),
    HALF,
)


#: ``(target P or None, prescribed δ or None, estimated a/R)``: Hertz's cylinder's
load_choice = CYLINDER.loads


def build(p: dict[str, Any], given: set[str] | None = None) -> SceneModel:
    """The block on a rigid cylinder in physical units."""
    target, delta, a_over_R = load_choice(p, set() if given is None else given)
    R = p["R"]
    return block_on_obstacle(
        p, scale=a_over_R * R, fine_end=FINE_END, candidate_end=p["candidates"],
        obstacle=Circle(centre=(0.0, -R), radius=R), target=target, delta=delta,
        indentation=1.0 / 3.0, params=dict(p, P=target, delta=delta, a_over_R=a_over_R),
        reference=ReferenceData(REFERENCE, E_star=contact_modulus(p["E"], p["nu"]), R=R))


FAMILY = SceneFamily(
    name="reverse-hertz",
    summary="elastic block pressed onto a rigid cylinder (a curved obstacle), plane strain",
    params=PARAMS, build=build, loads=load_choice, reference=REFERENCE,
    # the default mesh's dofs and how they grow, fitted to the meshes built (docs/calibration.md)
    size_model=SizeModel(6118, 128, 0.3, uniform=2.66, alpha=0.55, beta=1.4, far_field=1300.0,
                         margin=1.16, block=True),
    coarse=two_refinements_coarser, validation=(Case("reverse-hertz", "reverse-hertz"),),
    convergence_start={"n_contact": 16, "grading": 0.6})


__all__ = ["load_choice", "build", "FAMILY"]
