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

import math
from typing import Any

from signorini.references.analytic import contact_modulus, hertz_cylinder_half_width, hertz_cylinder_load
from signorini.problem.model import ReferenceData
from signorini.errors import InputError
from signorini.fem.model import SceneModel
from signorini.fem.obstacles import Circle
from signorini.scenes.base import (
    VOLUMETRIC,
    Case,
    Param,
    SceneFamily,
    at_least,
    block_size,
    checked_ratio,
    contact_ratio,
    grading_check,
    length,
    poisson_ratio,
    positive,
    two_refinements_coarser,
)
from signorini.scenes.punch import bottom_contact_model, graded_half_block, mirrored_about_x0
from signorini.scenes.size import SizeModel

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
    Param("grading", 0.3, "growth of the element size with distance from the contact zone",
          check=grading_check),
    Param("candidates", 2.0, "contact candidates extend to this multiple of the half-width",
          check=at_least(1.2)),
    Param("refine", 0, "uniform refinements of the graded mesh (each quadruples the dofs)",
          kind=int, check=lambda k: None if 0 <= k <= 6 else "in 0..6"),
    Param("half", 1, "1: right half with a symmetry plane; 0: the whole width", kind=int,
          check=lambda k: None if k in (0, 1) else "0 or 1"),
)


def load_choice(p: dict[str, Any], given: set[str]) -> tuple[float | None, float | None, float]:
    """``(target P or None, prescribed δ or None, estimated a/R)``."""
    chosen = {name for name in given & {"P", "a_over_R", "delta"} if p[name] is not None}
    if len(chosen) > 1:
        raise InputError(f"scene parameters {' and '.join(sorted(chosen))} both set the load: "
                         "give only one of P, a_over_R, delta")
    R, E_star = p["R"], contact_modulus(p["E"], p["nu"])
    if "delta" in chosen:  # a ~ √(δ R) up to Hertz's logarithm: refused where a/R would be
        checked_ratio(math.sqrt(p["delta"] / R), "delta", p["delta"])
        return None, p["delta"], p["a_over_R"]
    if "P" in chosen:
        a_over_R = checked_ratio(hertz_cylinder_half_width(p["P"], R, E_star) / R, "P", p["P"])
        return p["P"], None, a_over_R
    return hertz_cylinder_load(p["a_over_R"] * R, R, E_star), None, p["a_over_R"]


def build(p: dict[str, Any], given: set[str] | None = None) -> SceneModel:
    """The block on a rigid cylinder in physical units."""
    given = set() if given is None else given
    target, delta, a_over_R = load_choice(p, given)
    R = p["R"]
    a = a_over_R * R
    E_star = contact_modulus(p["E"], p["nu"])
    mesh = graded_half_block(p["size"], p["size"], FINE_END, p["n_contact"], p["grading"], p["refine"],
                             kinks=(p["candidates"],))
    if not p["half"]:
        mesh = mirrored_about_x0(mesh)
    delta_nominal = delta if delta is not None else \
        (target / E_star) * (1.0 / (2.0 * p["size"]) + 1.0 / 3.0)
    params = dict(p)
    params.update(P=target, delta=delta, a_over_R=a_over_R)
    return bottom_contact_model(
        mesh, scale=a, height=p["size"], candidate_end=p["candidates"], half=bool(p["half"]),
        obstacle=Circle(centre=(0.0, -R), radius=R), E=p["E"], nu=p["nu"],
        delta_nominal=delta_nominal, target=target, params=params,
        reference=ReferenceData(REFERENCE, E_star=E_star, R=R))


#: the analytic reference (signorini.references.catalogue) this family's problems compare with
REFERENCE = "reverse-hertz"


FAMILY = SceneFamily(
    name="reverse-hertz",
    summary="elastic block pressed onto a rigid cylinder (a curved obstacle), plane strain",
    params=PARAMS, build=build, loads=load_choice, reference=REFERENCE,
    # the default mesh's dofs and how they grow, fitted to the meshes built (docs/calibration.md)
    size_model=SizeModel(6118, 128, 0.3, uniform=2.66, alpha=0.55, beta=1.4, far_field=1300.0,
                         margin=1.16, block=True),
    coarse=two_refinements_coarser, validation=(Case("reverse-hertz", "reverse-hertz"),),
    convergence_start={"n_contact": 16, "grading": 0.6})
