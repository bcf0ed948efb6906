"""Hertz between two elastic spheres, axisymmetric: two quarter meridian discs, meshed each on its own.

The axisymmetric twin of ``hertz-two-cylinders``, with the same parameters
and the same two quarter discs, now read in the meridian half-plane (r, z):
the upper sphere (radius R1, E1, ν1) the quarter below its centre (0, R1),
the lower one (R2, E2, ν2) the quarter above its centre (0, −R2). The axis
r = 0 has ``u_r = 0``; each cut through a centre carries a uniform traction
towards the other sphere totalling P (``loading=traction``), the lower
centre node held and the upper one pushed by the δ load control finds, or
(``loading=displacement``, ``delta``) the lower cut held and the upper cut
pushed flat. K and the contact rows are per radian (weight r) and the
pair's ``force_multiplicity`` is 2π, so loads are those of the whole spheres.

Two-body Hertz (Johnson 1985, §4.2): ``1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2``,
``1/R* = 1/R1 + 1/R2``, ``a = (3PR*/(4E*))^(1/3)`` and ``p₀ = 3P/(2πa²)``;
the reference is ``hertz-sphere``'s (``hertz-3d``) with that E* and R*.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from signorini.references.analytic import hertz_sphere_load, hertz_sphere_radius
from signorini.problem.model import ReferenceData
from signorini.fem.two_bodies import TwoBodyModel
from signorini.scenes import hertz_two_cylinders as cylinders
from signorini.scenes.base import Case, SceneFamily
from signorini.scenes.hertz_sphere import SIZE as ONE_SPHERE
from signorini.scenes.size import CountedSize

__all__ = ["FAMILY"]

#: the analytic reference (signorini.references.catalogue) this family's problems compare with
REFERENCE = "hertz-3d"

#: what differs from the cylinders' parameters: the load's words and a sphere's mesh defaults
SPHERES = {"R1": {"doc": "radius of the upper sphere"}, "R2": {"doc": "radius of the lower sphere"},
           "P": {"doc": "total load on the spheres (exclusive with a_over_R, delta)"},
           "a_over_R": {"doc": "contact radius over R* (1/R* = 1/R1 + 1/R2): sets P by Hertz's "
                               "formula"},
           "n_contact": {"default": 60}, "grading": {"default": 0.15}}

PARAMS = tuple(dataclasses.replace(param, **SPHERES.get(param.name, {}))
               for param in cylinders.PARAMS)


def _load_choice(p: dict[str, Any], given: set[str]) -> tuple[float | None, float | None]:
    return cylinders.pair_load_choice(p, given, hertz_sphere_radius, hertz_sphere_load)


def _contact_radius(p: dict[str, Any], target: float | None, delta: float | None) -> float:
    R = cylinders.pair_radius(p)
    if target is not None:
        return hertz_sphere_radius(target, R, cylinders.pair_modulus(p))
    return float(np.sqrt(delta * R)) if delta is not None else p["a_over_R"] * R


def build(p: dict[str, Any], given: set[str] | None = None) -> TwoBodyModel:
    """The two quarter meridian discs in physical units: upper (slave) on lower (master)."""
    target, delta = _load_choice(p, set() if given is None else given)
    R, E_star = cylinders.pair_radius(p), cylinders.pair_modulus(p)
    a = _contact_radius(p, target, delta)
    delta_nominal = delta if delta is not None else a * a / R
    upper = cylinders.disc(p, p["R1"], a, p["candidates"])
    lower = cylinders.disc(p, p["R2"], a, cylinders.MASTER_REACH * p["candidates"])
    traction = target is not None and p["loading"] == "traction"
    params = dict(p, P=target, delta=delta_nominal, a_over_R=a / R if target is not None else None)
    return TwoBodyModel(
        slave=cylinders.body(upper, p["E1"], p["nu1"], delta_nominal, p["volumetric"], True,
                             traction),
        master=cylinders.body(lower, p["E2"], p["nu2"], 0.0, p["volumetric"], False, traction),
        discretisation=p["discretisation"], length_scale=R, force_multiplicity=2.0 * np.pi,
        reference=ReferenceData(REFERENCE, E_star=E_star, R=R), params=params,
        target_load=target, predicted=lambda points: points[:, 0] < a,
        direction=np.array([0.0, -1.0]) if p["normal"] == "vertical" else None, axisymmetric=True)


def mesh_dofs(p: dict[str, Any]) -> float:
    """The dofs of the two graded discs: ``hertz-sphere``'s size model for each."""
    target, delta = _load_choice(p, set())
    a = _contact_radius(p, target, delta)
    return sum(ONE_SPHERE.graded({**p, "R": radius, "E": p["E1"], "nu": p["nu1"], "refine": 0,
                                  "P": None, "delta": None, "a_over_R": a / radius})
               for radius in (p["R1"], p["R2"]))


FAMILY = SceneFamily(
    name="hertz-two-spheres",
    summary="two elastic spheres in contact, axisymmetric (r, z), each quarter meshed on its own",
    params=PARAMS, build=build, loads=_load_choice, reference=REFERENCE,
    size_model=CountedSize(mesh_dofs), convergence_start={"n_contact": 12, "grading": 0.6},
    validation=(Case("hertz-two-spheres", "hertz-two-spheres",
                     {"E2": 3.0, "nu2": 0.2, "R2": 2.0, "n_contact": 16, "grading": 0.4}),))
