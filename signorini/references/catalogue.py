"""The analytic references a scene can declare, by name.

Each scene family names its reference (``SceneFamily.reference``) and every
problem built from it carries that name (``ContactProblem.reference``);
everything that compares an answer with theory looks the reference up here
instead of testing names:

============== ============================================ ===================
name           comparison                                   key in solve JSON
============== ============================================ ===================
hertz-2d       Hertz's cylinder (plane strain)              ``hertz``
hertz-3d       Hertz's sphere (axisymmetric or 3D model)    ``hertz``
reverse-hertz  a block pressed by a rigid cylinder          ``hertz``
punch          a rigid flat punch, P/(π√(a² − x²))          ``punch``
uniform        uniform pressure E*δ/H (the block patch test) ``uniform``
============== ============================================ ===================

A reference also says its comparison in a solve's summary
(:func:`summary_lines`) and the claims the validation suite holds an exact
answer to (:class:`Claim`, with the suite's limits by name).

Formulas: :mod:`signorini.references.analytic`; comparisons: :mod:`signorini.references.pressure`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from signorini.references.analytic import hertz_cylinder_half_width, hertz_sphere_radius
from signorini.errors import InputError
from signorini.references.pressure import (
    compare_hertz,
    compare_hertz_sphere,
    compare_punch,
    compare_reverse_hertz,
    compare_uniform,
    contact_profile,
    radial_distance,
)
from signorini.problem.contact import ContactProblem, ContactSolution


@dataclass(frozen=True)
class Claim:
    """One claim about an answer against its reference: ``value`` at most the suite's limit
    named ``limit`` (:data:`signorini.studies.suite_checks.LIMITS`), or, with ``limit`` None, true."""

    name: str
    value: float | bool
    limit: str | None = None
    detail: str = ""


@dataclass(frozen=True)
class Reference:
    """An analytic reference: how to compare an answer with it, and what that measures.

    ``compare(problem, solution)`` returns an object with ``as_dict()``;
    ``key`` names that dictionary in a solve record; ``resultant`` says the
    load is the vertical resultant of tilted normals (curved or cornered
    obstacles), reported beside it; ``convergence`` lists the errors a
    refinement study fits rates to; ``figure`` says the validation report
    draws every method's pressure against this reference's profile;
    ``summary_line`` says the comparison in a solve's summary; ``claims``
    are what the validation suite holds the exact answer to (:class:`Claim`).
    """

    name: str
    summary: str
    compare: Callable[[ContactProblem, ContactSolution], Any]
    key: str
    convergence: tuple[str, ...] = ()
    resultant: bool = False
    figure: bool = False
    extent: Callable[[ContactProblem], float | None] | None = None
    extent_margin: float = 0.0
    #: the line a solve's summary shows of the comparison (its ``as_dict()``); None: no line
    summary_line: Callable[[dict[str, Any]], str] | None = None
    #: the errors a study runner's row records of every answer against it (the atlas's columns)
    row_errors: tuple[str, ...] = ()
    #: ``claims(problem, exact, metrics)``: what the validation suite checks of the exact answer
    claims: Callable[[ContactProblem, ContactSolution, dict[str, float]], list[Claim]] | None = None

    def metrics(self, problem: ContactProblem, solution: ContactSolution) -> dict[str, float]:
        """The comparison as a flat dictionary; empty when the answer has no finite forces."""
        if not np.all(np.isfinite(solution.lam)):
            return {}
        return self.compare(problem, solution).as_dict()


_PRESSURE_ERRORS = ("p0_rel", "a_rel", "pressure_l2_rel")


def _hertz_line(h: dict[str, Any]) -> str:
    if not all(isinstance(h.get(k), float) and np.isfinite(h[k]) for k in ("a", "p0")):
        return (f"  Hertz: the contact covers too few candidates to fit a and p0 (ref a = "
                f"{h['a_ref']:.6g}, p0 = {h['p0_ref']:.6g}): refine the mesh at the contact or "
                "raise the load")
    return (f"  Hertz: a = {h['a']:.6g} (ref {h['a_ref']:.6g}, {100 * h['a_rel']:.2f} %), "
            f"p0 = {h['p0']:.6g} (ref {h['p0_ref']:.6g}, {100 * h['p0_rel']:.2f} %), "
            f"pressure L2 {100 * h['pressure_l2_rel']:.2f} %")


def _punch_line(q: dict[str, Any]) -> str:
    return (f"  punch: load {q['load']:.6g}; pressure vs P/(π√(a² − x²)) on |x| ≤ "
            f"{q['inner']:g}a: max {100 * q['pressure_max_rel']:.2f} %, "
            f"L2 {100 * q['pressure_l2_rel']:.2f} %; edge node p = {q['edge_pressure']:.4g} "
            f"(element {q['edge_h']:.3g} next to the edge)")


def _pressure_claims(metrics: dict[str, float], prefix: str) -> list[Claim]:
    return [Claim("Hertz p0 relative error (pdas)", metrics["p0_rel"], prefix + "p0_rel"),
            Claim("Hertz a relative error (pdas)", metrics["a_rel"], prefix + "a_rel"),
            Claim("Hertz pressure L2 relative error (pdas)", metrics["pressure_l2_rel"],
                  prefix + "pressure_l2_rel"),
            _force_balance(metrics)]


def _force_balance(metrics: dict[str, float]) -> Claim:
    return Claim("force balance: contact force vs applied load (pdas)", metrics["force_balance"],
                 "force_balance")


_RAISE_CANDIDATES = "contact reached the end of the candidates: raise 'candidates'"


def _hertz_2d_claims(problem: ContactProblem, exact: ContactSolution,
                     metrics: dict[str, float]) -> list[Claim]:
    """Hertz's a, p₀ and pressure, force balance, and the last candidate out of contact."""
    outside = not bool(contact_profile(problem, exact).active[-1])
    return _pressure_claims(metrics, "hertz_") + [
        Claim("outermost candidate is not in contact", outside, None, _RAISE_CANDIDATES)]


def _hertz_3d_claims(problem: ContactProblem, exact: ContactSolution,
                     metrics: dict[str, float]) -> list[Claim]:
    """As in 2D (the 3D model to its own limits), the outermost ring out of contact."""
    prefix = "hertz_3d_" if problem.contact_points.shape[1] == 3 else "hertz_"
    rho = radial_distance(problem.contact_points)
    outside = not bool(np.any(contact_profile(problem, exact).active[rho >= 0.95 * rho.max()]))
    return _pressure_claims(metrics, prefix) + [
        Claim("outermost candidates are not in contact", outside, None, _RAISE_CANDIDATES)]


def _punch_claims(problem: ContactProblem, exact: ContactSolution,
                  metrics: dict[str, float]) -> list[Claim]:
    """The pressure away from the edges, force balance, the load (sharp corners), full contact."""
    claims = [Claim("punch pressure max relative error on |x| <= a/2 (pdas)",
                    metrics["pressure_max_rel"], "punch_pressure_rel"), _force_balance(metrics)]
    if np.isfinite(metrics["target_rel"]) and problem.model.reference.corner_radius == 0:
        claims.append(Claim("total contact force equals the load P (pdas)", metrics["target_rel"],
                            "load_target_rel"))
    touching = metrics["active_fraction"] == 1.0
    return claims + [Claim("every node under the punch face is in contact", touching, None,
                           f"only {100 * metrics['active_fraction']:.1f} % are")]


def _uniform_claims(problem: ContactProblem, exact: ContactSolution,
                    metrics: dict[str, float]) -> list[Claim]:
    return [Claim("uniform pressure max relative error (pdas)", metrics["pressure_max_rel"],
                  "uniform_pressure_rel"), _force_balance(metrics)]


def _hertz_extent(half_width: Callable[[float, float, float], float]):
    """``extent(problem)``: Hertz's contact half-width (radius) at the scene's target load
    (None without a target: a prescribed push)."""
    def extent(problem: ContactProblem) -> float | None:
        scene, P = problem.model.reference, problem.model.push.P if problem.model.push else None
        if scene is None or scene.R is None or scene.E_star is None or P is None or not P > 0:
            return None
        return half_width(P, scene.R, scene.E_star)
    return extent

REFERENCES: dict[str, Reference] = {r.name: r for r in (
    Reference("hertz-2d", "Hertz's cylinder on a flat, plane strain", compare_hertz, "hertz",
              _PRESSURE_ERRORS, figure=True, extent=_hertz_extent(hertz_cylinder_half_width),
              extent_margin=0.001, summary_line=_hertz_line, claims=_hertz_2d_claims,
              row_errors=("a_rel", "p0_rel", "pressure_l2_rel")),
    Reference("hertz-3d", "Hertz's sphere on a flat", compare_hertz_sphere, "hertz",
              _PRESSURE_ERRORS, figure=True, extent=_hertz_extent(hertz_sphere_radius),
              extent_margin=0.006, summary_line=_hertz_line, claims=_hertz_3d_claims),
    Reference("reverse-hertz", "a block pressed by a rigid cylinder (Hertz 2D)",
              compare_reverse_hertz, "hertz", _PRESSURE_ERRORS, resultant=True,
              summary_line=_hertz_line, claims=_hertz_2d_claims),
    Reference("punch", "a rigid flat punch on a half-plane", compare_punch, "punch",
              ("pressure_max_rel", "pressure_l2_rel", "edge_over_centre"), resultant=True,
              summary_line=_punch_line, claims=_punch_claims),
    Reference("uniform", "uniform pressure under a block pressed onto a flat", compare_uniform,
              "uniform", claims=_uniform_claims),
)}


def summary_lines(record: dict[str, Any]) -> list[str]:
    """The lines a solve record's comparisons (each under its reference's ``key``) show."""
    lines = {r.key: r.summary_line for r in REFERENCES.values() if r.summary_line is not None}
    return [line(record[key]) for key, line in lines.items() if record.get(key)]


def reference_of(problem: ContactProblem) -> Reference | None:
    """The reference ``problem`` declares (None when it declares none)."""
    if not problem.model.reference_name:
        return None
    if problem.model.reference_name not in REFERENCES:
        raise InputError(f"reference {problem.model.reference_name!r} is not one of "
                         f"{', '.join(sorted(REFERENCES))} (or '' for none)")
    return REFERENCES[problem.model.reference_name]


def reference_metrics(problem: ContactProblem, solution: ContactSolution) -> dict[str, float]:
    """Errors of ``solution`` against the reference ``problem`` declares ({} when none)."""
    reference = reference_of(problem)
    return reference.metrics(problem, solution) if reference else {}


__all__ = ["Claim", "Reference", "summary_lines", "reference_of", "reference_metrics", "REFERENCES"]
