"""The contact state along the surface, in physical units, and the edge and peak it shows.

The nodal contact force ``λᵢ`` is the consistent nodal force of the contact
traction, so ``pᵢ = λᵢ / wᵢ`` with the lumped weight ``wᵢ = ∫ φᵢ ds`` is the
nodal pressure. Every fit divides positions and pressures by their largest
magnitude before it forms squares or products (:func:`unit_of`), so that it
means the same in any units in which the solve itself is representable.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from signorini.certification.kkt import ACTIVE, classify
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.reprs import short_repr

__all__ = ["ContactProfile", "contact_half_width", "contact_profile", "half_line", "hertz_fit",
           "hertz_fit_tangent", "load_resultant", "radial_distance", "sub_profile",
           "symmetry_plane_profiles", "unit_of"]


@dataclass(frozen=True)
class ContactProfile:
    """The contact state at the candidates, in physical units, sorted along the surface.

    ``x`` is the horizontal distance from the first point of contact (the radius in axisymmetric
    and 3D models; x as given, signed, for a plane QP given as arrays), ``gap``
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

    __repr__ = short_repr
    def as_dict(self) -> dict:
        return {key: getattr(self, key).tolist() for key in ("x", "gap", "force", "pressure", "active")}


def contact_profile(problem: ContactProblem, solution: ContactSolution) -> ContactProfile:
    """Physical gaps, forces and pressures of ``solution`` at the contact candidates."""
    s = problem.scales
    force = solution.lam * s.force
    labels = classify(problem, solution)
    return ContactProfile(
        x=radial_distance(problem.contact_points, signed=problem.model.mesh is None) * s.length,
        gap=problem.gap(solution.u) * s.displacement,
        force=force,
        pressure=(force / (problem.weights * s.weight) if problem.weights is not None
                  else np.full_like(force, np.nan)),
        active=labels == ACTIVE,
        labels=labels,
        total_force=problem.total_contact_force(solution.lam) * s.force,
        applied_load=problem.model.applied_load(solution.u) * s.force)


def unit_of(values: np.ndarray) -> float:
    """The largest finite magnitude among ``values`` (1 when there is none): what a fit or a
    norm divides by before it squares them."""
    values = np.abs(np.asarray(values, dtype=float))
    values = values[np.isfinite(values)]
    largest = float(values.max()) if values.size else 0.0
    return largest if largest > 0 else 1.0


def _line_through_squares(x: np.ndarray, pressure: np.ndarray) -> tuple[float, float, float, float]:
    """``(slope, intercept)`` of a line through ``(x², p²)`` in units of the largest x and p,
    and those two units."""
    xs, ps = unit_of(x), unit_of(pressure)
    slope, intercept = np.polyfit((x / xs) ** 2, (pressure / ps) ** 2, 1)
    return float(slope), float(intercept), xs, ps


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
        slope, intercept, xs, _ = _line_through_squares(profile.x[fit], profile.pressure[fit])
        if slope < 0:
            return float(np.clip(xs * np.sqrt(-intercept / slope), profile.x[last], upper))
    return float(0.5 * (profile.x[last] + upper))


def hertz_fit(x: np.ndarray, pressure: np.ndarray, active: np.ndarray) -> tuple[float, float]:
    """``(p₀, a)`` of Hertz's profile ``p² = p₀² (1 − x²/a²)`` fitted to nodal pressures.

    A least-squares line through ``(x², p²)`` of the active nodes, leaving out
    the outermost one (its lumped pressure averages across the edge of the
    zone); x is the distance from the first point of contact (the radius for
    a sphere). Every node of the zone counts, so the fit is not at the mercy
    of the one node at x = 0. NaN when fewer than three nodes are active.
    """
    idx = _fitted_nodes(x, active)
    if idx.size < 2 or np.ptp(x[idx]) == 0:
        return float("nan"), float("nan")
    slope, intercept, xs, ps = _line_through_squares(x[idx], pressure[idx])
    if not (intercept > 0 and slope < 0):
        return float("nan"), float("nan")
    return float(ps * np.sqrt(intercept)), float(xs * np.sqrt(-intercept / slope))


def _fitted_nodes(x: np.ndarray, active: np.ndarray) -> np.ndarray:
    """The nodes :func:`hertz_fit` fits: the active ones but the outermost, by increasing x."""
    return np.nonzero(active)[0][np.argsort(x[active])][:-1]


def hertz_fit_tangent(x: np.ndarray, pressure: np.ndarray, active: np.ndarray,
                      dpressure: np.ndarray) -> tuple[float, float]:
    """``(dp₀, da)`` of :func:`hertz_fit` when the pressures move by ``dpressure`` (same nodes).

    The line through ``(x², p²)`` is linear in ``p²``: its slope s and intercept c move by
    the fit of ``d(p²) = 2 p dp``, so ``dp₀ = p₀ dc / 2c`` and ``da = a (dc/c − ds/s) / 2``.
    """
    (p0, a), idx = hertz_fit(x, pressure, active), _fitted_nodes(x, active)
    if not np.isfinite(p0):
        return p0, a
    slope, intercept, xs, ps = _line_through_squares(x[idx], pressure[idx])
    dslope, dintercept = np.polyfit((x[idx] / xs) ** 2,
                                    2 * pressure[idx] * dpressure[idx] / ps ** 2, 1)
    return (float(p0 * dintercept / (2 * intercept)),
            float(a * (dintercept / intercept - dslope / slope) / 2))


def radial_distance(points: np.ndarray, signed: bool = False) -> np.ndarray:
    """Horizontal distance from the vertical axis through the first point of contact.

    ``points`` is (k, 2) for a plane or axisymmetric (r, z) model, where it is |x| (or x
    itself, ``signed``), or (k, 3) for a 3D model with z vertical, where it is ``√(x² + y²)``.
    """
    points = np.asarray(points, dtype=float)
    x = points[:, 0] if signed or points.shape[1] == 3 else np.abs(points[:, 0])
    return x if points.shape[1] == 2 else np.hypot(x, points[:, 1])


def sub_profile(profile: ContactProfile, order: np.ndarray, x: np.ndarray) -> ContactProfile:
    """The candidates ``order`` of ``profile`` as a profile of their own along ``x``."""
    return ContactProfile(x=x, gap=profile.gap[order], force=profile.force[order],
                          pressure=profile.pressure[order], active=profile.active[order],
                          labels=profile.labels[order], total_force=profile.total_force,
                          applied_load=profile.applied_load)


def symmetry_plane_profiles(problem: ContactProblem,
                            solution: ContactSolution) -> tuple[ContactProfile, ContactProfile]:
    """Pressure along the two symmetry planes of a 3D quarter model.

    Returns the candidates in the plane y = 0 sorted by x, then those in the
    plane x = 0 sorted by y; each profile's ``x`` is the distance from the
    first point of contact along its plane. For an axisymmetric body the two
    are the same curve p(r).
    """
    if problem.contact_points.shape[1] != 3:
        raise ValueError("symmetry-plane profiles need a 3D model (contact points with x, y, z)")
    profile = contact_profile(problem, solution)
    points = problem.contact_points * problem.scales.length
    tol = 1e-9 * problem.scales.length
    lines = []
    for plane, along in ((1, 0), (0, 1)):
        on = np.nonzero(np.abs(points[:, plane]) <= tol)[0]
        order = on[np.argsort(points[on, along])]
        lines.append(sub_profile(profile, order, points[order, along]))
    return lines[0], lines[1]


def load_resultant(problem: ContactProblem, lam: np.ndarray, component: int = -1) -> float:
    """The load the obstacle carries along axis ``component``, full body, physical units.

    The contact force on the body is ``−Nᵀλ``; summed over its dofs of one
    component and multiplied by the model's multiplicity,
    ``R = −μ Σᵢ (Nᵀλ)ᵢ,k``. With ``component`` the load axis (the last one,
    y in 2D, by default) this is the load pushed onto an obstacle below the
    body. For a flat (n = (0, −1)) it is ``μ Σλ``; on a curved obstacle each
    λᵢ counts with the cosine of its normal's tilt, so ``μ Σλ`` (the total
    *normal* force) exceeds the load.
    """
    dim = problem.contact_points.shape[1]
    component = component % dim
    size, free = problem.model.dofs()
    full = np.zeros(size)
    full[free] = problem.N.T @ np.asarray(lam, dtype=float)
    basis = getattr(problem, "basis", None)
    dofs = basis.nodal_dofs[component] if basis is not None else \
        np.arange(component, full.size, dim)
    return float(-problem.force_multiplicity * full[dofs].sum() * problem.scales.force)


def half_line(problem: ContactProblem, profile: ContactProfile) -> ContactProfile:
    """The candidates with x ≥ 0 (2D), sorted by x: all of a half model, the right half of a whole one."""
    x = problem.contact_points[:, 0] * problem.scales.length
    right = np.nonzero(x >= -1e-12 * max(1.0, float(np.max(np.abs(x)))))[0]
    order = right[np.argsort(x[right], kind="stable")]
    return sub_profile(profile, order, np.abs(x[order]))
