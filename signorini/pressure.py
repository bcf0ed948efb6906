"""From multipliers to contact pressure, and its comparison with analytic references.

The nodal contact force ``λᵢ`` is the consistent nodal force of the contact
traction, so ``pᵢ = λᵢ / wᵢ`` with the lumped weight ``wᵢ = ∫ φᵢ ds`` is the
nodal pressure. Everything here is in physical units.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from .analytic import (contact_modulus, hertz_cylinder_half_width, hertz_cylinder_peak,
                       hertz_pressure)
from .kkt import ACTIVE, classify
from .problem import ContactProblem, ContactSolution


@dataclass(frozen=True)
class ContactProfile:
    """The contact state at the candidates, in physical units, sorted along the surface.

    ``x`` is the horizontal distance from the first point of contact, ``gap``
    the remaining gap ``d − Nu``, ``force`` the nodal force λ, ``pressure``
    ``λ / w``; ``total_force`` is the load of the full body (per unit thickness
    in 2D) and ``applied_load`` the same load measured as the reaction on the
    loaded boundary.
    """

    x: np.ndarray
    gap: np.ndarray
    force: np.ndarray
    pressure: np.ndarray
    active: np.ndarray
    labels: np.ndarray
    total_force: float
    applied_load: float

    def as_dict(self) -> dict:
        return {"x": self.x.tolist(), "gap": self.gap.tolist(), "force": self.force.tolist(),
                "pressure": self.pressure.tolist(), "active": self.active.tolist()}


def contact_profile(problem: ContactProblem, solution: ContactSolution) -> ContactProfile:
    """Physical gaps, forces and pressures of ``solution`` at the contact candidates."""
    s = problem.scales
    force = solution.lam * s.force
    labels = classify(problem, solution)
    return ContactProfile(
        x=problem.contact_points[:, 0] * s.length,
        gap=problem.gap(solution.u) * s.displacement,
        force=force,
        pressure=force / (problem.weights * s.weight),
        active=labels == ACTIVE,
        labels=labels,
        total_force=problem.total_contact_force(solution.lam) * s.force,
        applied_load=problem.applied_load(solution.u) * s.force)


def contact_half_width(profile: ContactProfile) -> float:
    """Half-width of the contact zone from the nodal pressures.

    Near the edge of a smooth contact ``p²`` falls linearly to zero (exactly
    so for Hertz: ``p² = p₀²(1 − x²/a²)``), so ``a`` is where a line through
    ``(x², p²)`` of the three active nodes before the last one reaches zero,
    kept between the last active and the first inactive node. The last active
    node itself is left out: its lumped pressure averages across the edge.
    """
    active = np.nonzero(profile.active)[0]
    if active.size == 0:
        return 0.0
    last = active[-1]
    upper = profile.x[last + 1] if last + 1 < profile.x.size else profile.x[last]
    fit = active[-4:-1] if active.size >= 4 else active
    if fit.size >= 2 and np.ptp(profile.x[fit]) > 0:
        slope, intercept = np.polyfit(profile.x[fit] ** 2, profile.pressure[fit] ** 2, 1)
        if slope < 0:
            return float(np.clip(np.sqrt(-intercept / slope), profile.x[last], upper))
    return float(0.5 * (profile.x[last] + upper))


def _l2_relative(x: np.ndarray, numeric: np.ndarray, reference) -> float:
    """‖p_h − p_ref‖ / ‖p_ref‖ on [0, x_max], p_h the piecewise-linear nodal interpolant."""
    grid = np.linspace(0.0, float(x.max()), 20_001)
    ref = reference(grid)
    diff = np.interp(grid, x, numeric) - ref
    return float(np.sqrt(np.trapezoid(diff ** 2, grid) / np.trapezoid(ref ** 2, grid)))


@dataclass(frozen=True)
class HertzComparison:
    """Numeric against analytic contact of a cylinder on a flat (Johnson 1985, §4.2).

    References use the measured total force P: ``a = √(4PR/(πE*))``,
    ``p₀ = 2P/(πa)``. ``force_balance`` is ``|P − applied| / P``.
    """

    a: float
    a_ref: float
    p0: float
    p0_ref: float
    pressure_l2_rel: float
    force_balance: float
    edge_margin: float

    @property
    def a_rel(self) -> float:
        return abs(self.a / self.a_ref - 1.0)

    @property
    def p0_rel(self) -> float:
        return abs(self.p0 / self.p0_ref - 1.0)

    def as_dict(self) -> dict[str, float]:
        return {**asdict(self), "a_rel": self.a_rel, "p0_rel": self.p0_rel}


def compare_hertz(problem: ContactProblem, solution: ContactSolution) -> HertzComparison:
    """Compare ``solution`` of a Hertz cylinder scene with Hertz's solution."""
    profile = contact_profile(problem, solution)
    R = problem.params["R"]
    P = profile.total_force
    if not P > 0:
        nan = float("nan")
        return HertzComparison(0.0, nan, nan, nan, nan, nan, nan)
    a_ref = hertz_cylinder_half_width(P, R, contact_modulus(problem.params["E"], problem.params["nu"]))
    p0_ref = hertz_cylinder_peak(P, a_ref)
    return HertzComparison(
        a=contact_half_width(profile), a_ref=a_ref,
        p0=float(profile.pressure[np.argmin(profile.x)]), p0_ref=p0_ref,
        pressure_l2_rel=_l2_relative(profile.x, profile.pressure,
                                     lambda x: hertz_pressure(x, a_ref, p0_ref)),
        force_balance=abs(P - profile.applied_load) / abs(P) if P else float("inf"),
        edge_margin=float(profile.x.max() / a_ref))


@dataclass(frozen=True)
class UniformComparison:
    """Numeric against the uniform pressure ``p = E* δ / H`` of a block on a flat."""

    pressure_ref: float
    pressure_max_rel: float
    force_balance: float

    def as_dict(self) -> dict[str, float]:
        return asdict(self)


def compare_uniform(problem: ContactProblem, solution: ContactSolution) -> UniformComparison:
    """Compare ``solution`` of the block scene with its uniform pressure."""
    profile = contact_profile(problem, solution)
    params = problem.params
    p_ref = contact_modulus(params["E"], params["nu"]) * params["delta"] / params["H"]
    P = profile.total_force
    return UniformComparison(
        pressure_ref=p_ref,
        pressure_max_rel=float(np.max(np.abs(profile.pressure / p_ref - 1.0))),
        force_balance=abs(P - profile.applied_load) / abs(P) if P else float("inf"))
