"""Contact pressure against the analytic references: Hertz (cylinder, sphere, a block on a
cylinder), the uniform block and the flat punch.

Everything here is in physical units, from the contact profile of
:mod:`signorini.references.profile` (whose names this module also exports); every norm divides
pressures by the reference's largest value before it squares them (:func:`unit_of`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from signorini.references.analytic import (
    hertz_cylinder_half_width,
    hertz_cylinder_peak,
    hertz_pressure,
    hertz_sphere_peak,
    hertz_sphere_radius,
    punch_load_between,
    punch_pressure,
)
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.references.profile import (ContactProfile, contact_half_width, contact_profile,
                                          half_line, hertz_fit, hertz_fit_tangent, load_resultant,
                                          radial_distance, sub_profile, symmetry_plane_profiles,
                                          unit_of)

__all__ = ["ContactProfile", "HertzComparison", "PunchComparison", "UniformComparison",
           "compare_hertz", "compare_hertz_sphere", "compare_punch", "compare_reverse_hertz",
           "compare_uniform", "contact_half_width", "contact_profile", "hertz_fit",
           "hertz_fit_tangent", "load_resultant", "radial_distance", "symmetry_plane_profiles",
           "unit_of"]


def _l2_relative(x: np.ndarray, numeric: np.ndarray, reference) -> float:
    """‖p_h − p_ref‖ / ‖p_ref‖ on [0, x_max], p_h the piecewise-linear nodal interpolant."""
    grid, ref, numeric = _on_unit_grid(x, numeric, reference)
    diff = np.interp(grid, x / x.max(), numeric) - ref
    return float(np.sqrt(np.trapezoid(diff ** 2) / np.trapezoid(ref ** 2)))  # the step cancels


def _on_unit_grid(x: np.ndarray, numeric: np.ndarray, reference) -> tuple[np.ndarray, ...]:
    """A grid over [0, 1] in units of the largest x, the reference on it and ``numeric``, both
    in units of the reference's largest value: an interpolation's slopes stay representable."""
    grid = np.linspace(0.0, 1.0, 20_001)
    ref = reference(grid * float(x.max()))
    unit = unit_of(ref)
    return grid, ref / unit, numeric / unit


@dataclass(frozen=True)
class HertzComparison:
    """Numeric against analytic contact of a cylinder or sphere on a flat (Johnson 1985, §4.2).

    References use the measured total force P: ``a = √(4PR/(πE*))``,
    ``p₀ = 2P/(πa)`` for the cylinder. The numeric ``p0`` and ``a`` are
    those of Hertz's profile fitted to the nodal pressures
    (:func:`hertz_fit`); ``p0_nodal`` is the nodal pressure at the first
    point of contact and ``a_edge`` the edge found from the last active
    nodes (:func:`contact_half_width`). ``force_balance`` is
    ``|P − applied| / P``.
    """

    a: float
    a_ref: float
    p0: float
    p0_ref: float
    pressure_l2_rel: float
    force_balance: float
    edge_margin: float
    p0_nodal: float = float("nan")
    a_edge: float = float("nan")

    @property
    def a_rel(self) -> float:
        return abs(self.a / self.a_ref - 1.0)

    @property
    def p0_rel(self) -> float:
        return abs(self.p0 / self.p0_ref - 1.0)

    def as_dict(self) -> dict[str, float]:
        return {**asdict(self), "a_rel": self.a_rel, "p0_rel": self.p0_rel}


#: the comparison of an answer that carries no load: nothing to compare
_NO_CONTACT = HertzComparison(0.0, *[float("nan")] * 6)


def compare_hertz(problem: ContactProblem, solution: ContactSolution) -> HertzComparison:
    """Compare ``solution`` of a Hertz cylinder scene with Hertz's solution."""
    profile = contact_profile(problem, solution)
    return _against_cylinder(problem, profile, profile.total_force)


def _against_cylinder(problem: ContactProblem, profile: ContactProfile, P: float) -> HertzComparison:
    """A 2D contact profile (sorted by x) against Hertz's cylinder carrying the load P."""
    if not P > 0:
        return _NO_CONTACT
    scene = problem.model.reference  # what the scene hands its reference
    a_ref = hertz_cylinder_half_width(P, scene.R, scene.E_star)
    p0_ref = hertz_cylinder_peak(P, a_ref)
    p0, a = hertz_fit(profile.x, profile.pressure, profile.active)
    return HertzComparison(
        a=a, a_ref=a_ref, p0=p0, p0_ref=p0_ref,
        pressure_l2_rel=_l2_relative(profile.x, profile.pressure,
                                     lambda x: hertz_pressure(x, a_ref, p0_ref)),
        force_balance=abs(P - profile.applied_load) / P,
        edge_margin=float(profile.x.max() / a_ref),
        p0_nodal=float(profile.pressure[np.argmin(profile.x)]), a_edge=contact_half_width(profile))


@dataclass(frozen=True)
class UniformComparison:
    """Numeric against the uniform pressure ``p = E* δ / H`` of a block on a flat."""

    pressure_ref: float
    pressure_max_rel: float
    force_balance: float
    as_dict = asdict


def compare_uniform(problem: ContactProblem, solution: ContactSolution) -> UniformComparison:
    """Compare ``solution`` of the block scene with its uniform pressure."""
    profile = contact_profile(problem, solution)
    scene = problem.model.reference  # what the scene hands its reference
    p_ref = scene.E_star * problem.model.push.delta / scene.H
    P = profile.total_force
    return UniformComparison(
        pressure_ref=p_ref,
        pressure_max_rel=float(np.max(np.abs(profile.pressure / p_ref - 1.0))),
        force_balance=abs(P - profile.applied_load) / abs(P) if P else float("inf"))


# --- Hertz's sphere: axisymmetric (r, z) and 3D models (Johnson 1985, §4.2) -------------------


def _l2_relative_disc(r: np.ndarray, numeric: np.ndarray, reference) -> float:
    """‖p_h − p_ref‖ / ‖p_ref‖ over the disc ρ ≤ max r, p_h interpolated linearly in r.

    The norm is that of the contact plane, ``∫ p² 2πρ dρ`` (the 2π cancels).
    """
    order = np.argsort(r)
    grid, ref, numeric = _on_unit_grid(r, numeric, reference)
    diff = np.interp(grid, r[order] / r.max(), numeric[order]) - ref
    return float(np.sqrt(np.trapezoid(diff ** 2 * grid) / np.trapezoid(ref ** 2 * grid)))


def _l2_relative_surface(problem: ContactProblem, pressure: np.ndarray, reference,
                         subdivisions: int = 4) -> float:
    """‖p_h − p_ref‖ / ‖p_ref‖ over the contact candidates' surface triangles (3D).

    ``p_h`` is the P1 interpolant of the nodal pressures on each boundary
    triangle whose three nodes are candidates; both norms are integrated
    over the triangles projected on the flat, each split into
    ``subdivisions²`` parts with one point at each part's centroid.
    """
    from scipy.spatial import cKDTree

    mesh = problem.model.mesh
    nodes = cKDTree(mesh.p.T).query(problem.contact_points)[1]
    position = np.full(mesh.p.shape[1], -1)
    position[nodes] = np.arange(nodes.size)
    facets = mesh.facets[:, mesh.boundary_facets()]
    local = position[facets]
    local = local[:, np.all(local >= 0, axis=0)]  # (3, triangles) candidate indices
    xy = problem.contact_points[:, :2] * problem.scales.length
    length, unit = unit_of(xy), unit_of(reference(np.zeros(1)))  # areas and squares in these units
    k = subdivisions
    bary = [((i + 1 / 3) / k, (j + 1 / 3) / k) for i in range(k) for j in range(k - i)] + \
           [((i + 2 / 3) / k, (j + 2 / 3) / k) for i in range(k - 1) for j in range(k - 1 - i)]
    corners = xy[local]  # (3, triangles, 2)
    e1, e2 = corners[1] - corners[0], corners[2] - corners[0]
    u1, u2 = e1 / length, e2 / length
    area = 0.5 * np.abs(u1[:, 0] * u2[:, 1] - u1[:, 1] * u2[:, 0])  # in units of length²
    num = den = 0.0
    for s, t in bary:
        point = corners[0] + s * e1 + t * e2
        p_h = (1 - s - t) * pressure[local[0]] + s * pressure[local[1]] + t * pressure[local[2]]
        p_ref = reference(np.hypot(point[:, 0], point[:, 1]))
        num += float(np.sum(area * ((p_h - p_ref) / unit) ** 2))
        den += float(np.sum(area * (p_ref / unit) ** 2))
    return float(np.sqrt(num / den)) if den > 0 else float("nan")


def compare_hertz_sphere(problem: ContactProblem, solution: ContactSolution) -> HertzComparison:
    """Compare ``solution`` of a Hertz sphere scene (axisymmetric or 3D) with Hertz's solution.

    With the measured total force P (the whole sphere) the references are
    ``a = (3PR/(4E*))^(1/3)`` and ``p₀ = 3P/(2πa²)``, ``p(ρ) = p₀√(1 − ρ²/a²)``
    (Johnson 1985, §4.2). In the axisymmetric model the numeric p₀ and a are
    fitted (:func:`hertz_fit`) over the active nodes by radius, and
    ``a_edge`` is found as for the cylinder (:func:`contact_half_width`). In
    the 3D model p₀ is the nodal pressure at the first point of contact and a
    the mean edge along the two symmetry planes: the lumped nodal pressures
    of an unstructured surface mesh scatter, and a fit through their squares
    is biased by it more than the nodal peak is (docs/spheres.md).
    ``pressure_l2_rel`` is relative in the L2 norm of the contact plane
    (area-weighted), ``edge_margin`` the outermost candidate's radius over a.
    """
    profile = contact_profile(problem, solution)
    scene = problem.model.reference  # what the scene hands its reference
    P = profile.total_force
    if not P > 0:
        return _NO_CONTACT
    a_ref = hertz_sphere_radius(P, scene.R, scene.E_star)
    p0_ref = hertz_sphere_peak(P, a_ref)
    rho = radial_distance(problem.contact_points) * problem.scales.length

    def reference(r: np.ndarray) -> np.ndarray:
        return hertz_pressure(r, a_ref, p0_ref)

    p0_nodal = float(profile.pressure[np.argmin(rho)])
    if problem.contact_points.shape[1] == 2:
        order = np.argsort(rho)
        a = contact_half_width(sub_profile(profile, order, rho[order]))
        l2 = _l2_relative_disc(rho, profile.pressure, reference)
        p0, a_fit = hertz_fit(rho, profile.pressure, profile.active)
    else:  # a fit through the scattered p² of an unstructured surface is biased: the nodal peak
        a = float(np.mean([contact_half_width(line)
                           for line in symmetry_plane_profiles(problem, solution)]))
        l2 = _l2_relative_surface(problem, profile.pressure, reference)
        p0, a_fit = p0_nodal, a
    return HertzComparison(
        a=a_fit, a_ref=a_ref, p0=p0, p0_ref=p0_ref,
        pressure_l2_rel=l2,
        force_balance=abs(P - profile.applied_load) / abs(P),
        edge_margin=float(rho.max() / a_ref),
        p0_nodal=p0_nodal, a_edge=a)


# --- obstacles beyond a flat: flat punch, block on a rigid cylinder ------------------------


@dataclass(frozen=True)
class PunchComparison:
    """Numeric against analytic pressure under a rigid flat punch (Johnson 1985, ch. 2).

    With ``P`` the measured vertical load (:func:`load_resultant`), the
    reference is ``p(x) = P / (π√(a² − x²))``. ``pressure_max_rel`` and
    ``pressure_l2_rel`` compare nodal pressures with it over ``|x| ≤ inner·a``
    (away from the singular edges). ``edge_pressure`` is the nodal pressure
    at the face's edge, ``edge_h`` the length of the element next to it:
    under refinement the former grows like ``edge_h^(−1/2)``;
    ``edge_over_centre`` is it in units of the centre's ``P/(πa)``.
    ``force_balance`` is ``|P − applied| / P`` and ``target_rel``
    ``|P − P_target| / P_target`` (nan without a target).
    """

    a: float
    load: float
    applied_load: float
    force_balance: float
    target_rel: float
    inner: float
    pressure_max_rel: float
    pressure_l2_rel: float
    centre_rel: float
    edge_pressure: float
    edge_pressure_ref_mean: float
    edge_h: float
    edge_over_centre: float
    active_fraction: float

    def as_dict(self) -> dict[str, float]:
        return asdict(self)


def compare_punch(problem: ContactProblem, solution: ContactSolution,
                  inner: float = 0.5) -> PunchComparison:
    """Compare ``solution`` of the punch scene with ``p(x) = P/(π√(a² − x²))`` on ``|x| ≤ inner·a``."""
    profile = half_line(problem, contact_profile(problem, solution))
    a = float(problem.model.reference.a)
    P = load_resultant(problem, solution.lam)
    target = None if problem.model.push is None else problem.model.push.P
    nan = float("nan")
    if not P > 0:
        return PunchComparison(a, P, profile.applied_load, nan, nan, inner, nan, nan, nan, nan, nan,
                               nan, nan, 0.0)
    x, p = profile.x, profile.pressure
    zone = x <= inner * a * (1 + 1e-12)
    ref = punch_pressure(x[zone], a, P)
    under = np.nonzero(x <= a * (1 + 1e-9))[0]
    edge = under[-1]
    edge_h = float(x[edge] - x[edge - 1]) if edge > 0 else nan
    # the mean of the singular pressure over the edge node's half element, for scale
    edge_mean = punch_load_between(a - 0.5 * edge_h, a, a, P) / (0.5 * edge_h) if edge_h > 0 else nan
    return PunchComparison(
        a=a, load=P, applied_load=profile.applied_load,
        force_balance=abs(P - profile.applied_load) / P,
        target_rel=abs(P / target - 1.0) if target else nan,
        inner=inner,
        pressure_max_rel=float(np.max(np.abs(p[zone] / ref - 1.0))),
        pressure_l2_rel=_l2_relative(x[zone], p[zone], lambda s: punch_pressure(s, a, P)),
        centre_rel=float(p[0] / punch_pressure(np.array([x[0]]), a, P)[0] - 1.0),
        edge_pressure=float(p[edge]), edge_pressure_ref_mean=float(edge_mean), edge_h=edge_h,
        edge_over_centre=float(p[edge] / (P / (np.pi * a))),
        active_fraction=float(np.mean(profile.active[under])))


def compare_reverse_hertz(problem: ContactProblem, solution: ContactSolution) -> HertzComparison:
    """Compare a block pressed onto a rigid cylinder with Hertz's 2D solution (Johnson 1985, §4.2).

    As :func:`compare_hertz`, but the load is the vertical resultant
    (:func:`load_resultant`) rather than ``μ Σλ``: on the cylinder the normals
    tilt by up to a/R, and force balance holds for the resultant.
    """
    profile = half_line(problem, contact_profile(problem, solution))
    return _against_cylinder(problem, profile, load_resultant(problem, solution.lam))
