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

from signorini.scenes import hertz_two_cylinders as cylinders
from signorini.scenes.hertz_sphere import SIZE as ONE_SPHERE
from signorini.scenes.hertz_sphere import SPHERE

__all__ = ["FAMILY", "SPHERES_PAIR"]

#: what differs from the cylinders' parameters: the load's words and a sphere's mesh defaults
SPHERES = {"R1": {"doc": "radius of the upper sphere"}, "R2": {"doc": "radius of the lower sphere"},
           "P": {"doc": "total load on the spheres (exclusive with a_over_R, delta)"},
           "a_over_R": {"doc": "contact radius over R* (1/R* = 1/R1 + 1/R2): sets P by Hertz's "
                               "formula"},
           "n_contact": {"default": 60}, "grading": {"default": 0.15}}

PARAMS = tuple(dataclasses.replace(param, **SPHERES.get(param.name, {}))
               for param in cylinders.PARAMS)

#: two spheres: Hertz's formulas (``hertz-3d``), per radian; a push δ grades for ``a = √(δ R*)``
SPHERES_PAIR = cylinders.HertzPair(SPHERE, ONE_SPHERE)

FAMILY = SPHERES_PAIR.family(
    "hertz-two-spheres",
    "two elastic spheres in contact, axisymmetric (r, z), each quarter meshed on its own", PARAMS,
    {"n_contact": 12, "grading": 0.6})
