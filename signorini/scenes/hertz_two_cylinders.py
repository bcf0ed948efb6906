"""Hertz between two elastic cylinders, plane strain: two quarter discs, meshed each on its own.

The upper cylinder (radius R1, E1, ν1) is the quarter of its disc below its
centre (0, R1), the lower one (R2, E2, ν2) the quarter above its centre
(0, −R2); they first touch at the origin. Each is meshed as
``hertz-cylinder`` meshes its disc (graded towards the contact, ``n_contact``
elements across the expected half-width), so the two contact faces do not
match. The cuts x = 0 are symmetry planes (``u_x = 0``). By default
(``loading=traction``, as ``hertz-cylinder``) each disc's cut through its
centre carries a uniform traction towards the other whose total is the load
P; the lower centre node is held and the upper one pushed down by δ, which
load control adjusts until the contact resultant is P (the centre nodes then
carry no force: they only remove the rigid translations). With
``loading=displacement``, or a prescribed ``delta``, the lower cut is held
and the upper cut pushed down flat. The upper disc's arc is the slave face;
its rows take the vertical as their normal (``normal=vertical``, Hertz's own
gap) or each master segment's normal (``normal=master``).

Two-body Hertz (Johnson 1985, §4.2): ``1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2``,
``1/R* = 1/R1 + 1/R2``, ``a = √(4PR*/(πE*))`` and ``p₀ = 2P/(πa)``; the
reference is ``hertz-cylinder``'s (``hertz-2d``) with that E* and R*. The
rigid flat is the limit E2 → ∞, R2 → ∞.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from signorini.problem.model import ReferenceData
from signorini.fem.topology import facets_on
from signorini.fem.two_bodies import Body, TwoBodyModel, series_modulus
from signorini.scenes.base import (A_OVER_R_RANGE, LOADING, MESHER, VOLUMETRIC, Case, Param,
                                   SceneFamily, SizeEstimate, checked_ratio, contact_ratio,
                                   hertz_load, length, one_of, positive)
from signorini.scenes.hertz_cylinder import CYLINDER, HertzDisc
from signorini.scenes.hertz_cylinder import PARAMS as CYLINDER_PARAMS
from signorini.scenes.hertz_cylinder import SIZE as ONE_DISC
from signorini.scenes.meshing import GradedDisc, graded_quarter_disc
from signorini.scenes.size import CountedSize
from signorini.scenes.two_block_patch import DISCRETISATION, materials

__all__ = ["CYLINDERS", "FAMILY", "HertzPair", "body", "disc", "pair_modulus", "pair_radius",
           "PARAMS"]

#: hertz-cylinder's parameters by name: its mesh parameters are this family's, for each disc,
#: with a finer default (the two discs' errors add: docs/two-bodies.md)
ONE_CYLINDER = {param.name: param for param in CYLINDER_PARAMS}

#: the master face reaches this much further than the slave's candidates, so that every slave
#: candidate projects onto it
MASTER_REACH = 1.5

PARAMS = (
    Param("R1", 1.0, "radius of the upper cylinder", check=length),
    Param("R2", 1.0, "radius of the lower cylinder", check=length),
    *materials("upper cylinder", "lower cylinder"),
    VOLUMETRIC,
    Param("P", None, "load per unit thickness of the full cylinders (exclusive with a_over_R, "
          "delta)", check=positive),
    Param("a_over_R", 0.05, "contact half-width over R* (1/R* = 1/R1 + 1/R2): sets P by Hertz's "
          "formula", check=contact_ratio),
    Param("delta", None, "prescribed downward displacement of the upper cut (no load targeting)",
          check=positive),
    *(dataclasses.replace(ONE_CYLINDER[name], default=default)
      for name, default in (("n_contact", 48), ("grading", 0.12), ("candidates", 2.0))),
    DISCRETISATION,
    Param("normal", "vertical", "the rows' normal: vertical (Hertz's gap, along the common normal "
          "at the first point of contact) or master (each master segment's: docs/two-bodies.md)",
          kind=str, check=one_of("vertical", "master")),
    LOADING,
    dataclasses.replace(MESHER, default="relaxed"),  # closer to Hertz than Triangle here
)


def pair_radius(p: dict[str, Any]) -> float:
    """``R*``: ``1/R* = 1/R1 + 1/R2``."""
    return 1.0 / (1.0 / p["R1"] + 1.0 / p["R2"])


def pair_modulus(p: dict[str, Any]) -> float:
    """``E*`` of the pair (:func:`~signorini.fem.two_bodies.series_modulus`)."""
    return series_modulus(p["E1"], p["nu1"], p["E2"], p["nu2"])


def disc(p: dict[str, Any], radius: float, a: float, extent: float) -> GradedDisc:
    """One body's quarter disc of ``radius``, graded to the half-width ``a``, its contact
    candidates reaching ``extent`` times a."""
    return graded_quarter_disc(radius, a / radius, p["n_contact"], p["grading"], 0, extent,
                               mesher=p["mesher"])


def body(disc: GradedDisc, E: float, nu: float, push: float, volumetric: str, upper: bool,
          traction: bool) -> Body:
    """One body: its quarter disc (mirrored below y = 0 for the lower one) held on its axis,
    its cut pushed by ``push`` (the lower one's: held), whole or at its centre node under a
    traction towards the other body."""
    mesh = disc.mesh
    if not upper:
        mesh = type(mesh)(mesh.p * np.array([[1.0], [-1.0]]), mesh.t[[0, 2, 1]])
    held = np.array([disc.centre]) if traction else disc.top
    return Body(mesh=mesh, E=E, nu=nu, dirichlet=[(0, disc.axis, 0.0), (1, held, -push)],
                contact_facets=facets_on(mesh, disc.candidates),
                load_nodes=held if upper else np.zeros(0, dtype=int), volumetric=volumetric,
                traction=(facets_on(mesh, disc.top), -1.0 if upper else 1.0) if traction else None)


@dataclasses.dataclass(frozen=True)
class HertzPair:
    """Two elastic bodies of revolution or cylinders, each a quarter disc meshed on its own, of
    the kind of the one-body model ``one`` (Hertz's formulas with R* and E*, the reference, the
    copies of the model in the pair, axisymmetric or not, what a prescribed push grades the mesh
    for); ``one_body`` is one body's size model."""

    one: HertzDisc
    one_body: SizeEstimate

    def loads(self, p: dict[str, Any], given: set[str]) -> tuple[float | None, float | None, float]:
        """The target load P (None: a prescribed push), the push δ (None: matched to P) and a/R*;
        a push that grades the mesh (spheres: ``√(δ R*)``) is checked as it is for one body, and
        any push refused below it: the initial gaps, divided by δ, would lose the contact."""
        loads = hertz_load(p, given, pair_radius(p), pair_modulus(p), self.one.half_width,
                           self.one.load, check_delta=False, graded_by_delta=self.one.graded_by_delta)
        ratio = None if loads[1] is None else float(np.sqrt(loads[1] / pair_radius(p)))
        if ratio is not None and ratio < A_OVER_R_RANGE[0]:  # a large push is judged, not refused
            checked_ratio(ratio, "delta", loads[1])
        return loads

    def contact_size(self, p: dict[str, Any], target: float | None, delta: float | None) -> float:
        """The contact half-width (radius) the discs are graded for: Hertz's at the target load, or
        for a push δ ``√(δ R*)`` or ``a_over_R · R*`` (as the one-body model grades)."""
        R = pair_radius(p)
        if target is not None:
            return self.one.half_width(target, R, pair_modulus(p))
        return float(np.sqrt(delta * R)) if self.one.graded_by_delta else p["a_over_R"] * R

    def build(self, p: dict[str, Any], given: set[str] | None = None) -> TwoBodyModel:
        """The two quarter discs in physical units: upper (slave) on lower (master)."""
        target, delta, _ = self.loads(p, set() if given is None else given)
        R, E_star = pair_radius(p), pair_modulus(p)
        a = self.contact_size(p, target, delta)
        delta_nominal = delta if delta is not None else a * a / R
        upper = disc(p, p["R1"], a, p["candidates"])
        lower = disc(p, p["R2"], a, MASTER_REACH * p["candidates"])
        traction = target is not None and p["loading"] == "traction"
        params = dict(p, P=target, delta=delta_nominal, a_over_R=a / R if target is not None else None)
        return TwoBodyModel(
            slave=body(upper, p["E1"], p["nu1"], delta_nominal, p["volumetric"], True, traction),
            master=body(lower, p["E2"], p["nu2"], 0.0, p["volumetric"], False, traction),
            discretisation=p["discretisation"], length_scale=R, force_multiplicity=self.one.multiplicity,
            reference=ReferenceData(self.one.reference, E_star=E_star, R=R), params=params,
            target_load=target, predicted=lambda points: points[:, 0] < a,
            direction=np.array([0.0, -1.0]) if p["normal"] == "vertical" else None,
            axisymmetric=self.one.axisymmetric)

    def mesh_dofs(self, p: dict[str, Any]) -> float:
        """The dofs of the two graded discs: one body's size model for each."""
        target, delta, _ = self.loads(p, set())
        a = self.contact_size(p, target, delta)
        return sum(self.one_body.graded({**p, "R": radius, "E": p["E1"], "nu": p["nu1"], "refine": 0,
                                         "P": None, "delta": None, "a_over_R": a / radius})
                   for radius in (p["R1"], p["R2"]))

    def family(self, name: str, summary: str, params: tuple[Param, ...],
               convergence_start: dict[str, Any]) -> SceneFamily:
        """The scene family of this pair, validated on two unlike bodies on a coarse mesh: every
        method of the suite, the dense ones too."""
        return SceneFamily(
            name=name, summary=summary, params=params, build=self.build, loads=self.loads,
            reference=self.one.reference, size_model=CountedSize(self.mesh_dofs),
            convergence_start=convergence_start,
            validation=(Case(name, name, {"E2": 3.0, "nu2": 0.2, "R2": 2.0, "n_contact": 16,
                                          "grading": 0.4}),))


#: two cylinders: Hertz's plane-strain formulas (``hertz-2d``); a push grades for ``a_over_R``
CYLINDERS = HertzPair(CYLINDER, ONE_DISC)

FAMILY = CYLINDERS.family(
    "hertz-two-cylinders",
    "two elastic cylinders in contact, plane strain, each quarter meshed on its own", PARAMS,
    {"n_contact": 15, "grading": 0.6})
