"""Load control: the push whose contact force is the target load, around any method.

A scene loaded by a target force P is assembled at a nominal push
(``problem.pending``). Its load and gaps are affine in the push s,
``f(s) = s f₁ + f₀`` and ``d(s) = d₀ + s d₁``, so on a fixed active set the
answer is affine in s too, and the push whose total contact force
``μ Σλ`` equals P solves one scalar equation per active set
(:func:`signorini.numerics.loading.push_for_load`). This module is the one
driver that finds it, with one of three strategies:

- **zone kernel** (large models whose contact zone can be predicted: from
  the reference's analytic contact width, else from a coarser model of the
  scene): one factorisation of K with the predicted core pinned, the push
  one more unknown of the band's LCP (:class:`signorini.numerics.zone.ZoneSolver`);
- **full active set**: the augmented system ``K u + N_Aᵀλ_A = s f₁ + f₀,
  N_A u = d₀ + s d₁, μ Σλ_A = P``, one factorisation per active-set step,
  from the active set the scene predicts
  (:func:`signorini.numerics.loading.calibrate_push`);
- **bordered multigrid**: for ``pdas-amg`` the push is one more unknown of
  each CG system (:class:`signorini.solvers.amg.LoadBorder`), so no
  factorisation is ever made (large 3D models).

Then the method solves the QP at that push. A method named by the caller
starts cold and the iterations it reports are its own; ``auto`` takes the
fastest route and is handed what load control learnt as an explicit warm
start. Every stage's work is in ``solution.work``: ``load control``, the
``prediction`` (a coarser model solved to predict the contact) and the
``method``.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from signorini.errors import InputError
from signorini.numerics import factor, loading, multigrid
from signorini.numerics.factor import FactorTooLarge, selection_dofs
from signorini.numerics.loading import calibrate_push
from signorini.numerics.zone import (Zone, ZoneSolver, predict_zone, radial_distance,
                                     zone_around_points)
from signorini.problem import ContactProblem
from signorini.references import reference_of
from signorini.solution import ContactSolution, WarmStart
from signorini.solvers import amg, auto, registry

log = logging.getLogger(__name__)

#: a load-targeted model of at least this many dofs (prescribed ones included) is matched on a
#: predicted contact zone (one factorisation) when its scene predicts one
ZONE_FROM_DOFS = 20_000

#: a function of a problem returning a coarser model of the same scene (or None)
CoarseModel = Callable[[ContactProblem], "ContactProblem | None"]


def counters() -> dict[str, int]:
    """Every work counter of the package, as it stands now."""
    return {"steps": loading.COUNTS["load_steps"], **factor.COUNTS,
            "cg_iterations": multigrid.COUNTS["cg_iterations"],
            "hierarchies": multigrid.COUNTS["hierarchies"]}


def spent(before: dict[str, int]) -> dict[str, int]:
    """The work done since ``before`` (a :func:`counters` reading), the zero counts left out."""
    now = counters()
    return {key: now[key] - before[key] for key in now if now[key] != before[key]}


@dataclass
class Matched:
    """A problem at the push whose load is its target, and what matching it found.

    ``warm_start`` holds the exact answer at that push (forces, and the
    displacement or the zone kernel's factorisation); ``how`` names the
    strategy; ``work`` what it cost.
    """

    problem: ContactProblem
    warm_start: WarmStart
    how: str
    work: dict[str, int]


def analytic_extent(problem: ContactProblem) -> float | None:
    """The reference's contact half-width (radius) at the target load, in the problem's lengths."""
    reference = reference_of(problem)
    a = reference.extent(problem) if reference is not None and reference.extent else None
    return None if a is None else a / problem.scales.length


def analytic_zone(problem: ContactProblem) -> Zone | None:
    """The contact zone from the reference's contact half-width (radius) at the target load."""
    a = analytic_extent(problem)
    return None if a is None else zone_around_points(problem.contact_points, a,
                                                     reference_of(problem).extent_margin)


def coarse_zone(problem: ContactProblem, coarse: ContactProblem | None,
                neighbours: int | None = None) -> tuple[Zone | None, ContactProblem | None]:
    """The zone at ``problem``'s candidates that a coarser model predicts, and that model at its
    load (None, None when there is none or it does not solve exactly)."""
    if coarse is None:
        return None, None
    try:
        if coarse.pending:
            settled = match(coarse)
            coarse, lam = settled.problem, settled.warm_start.lam
        else:
            answer = registry.solve(coarse, "pdas")
            if answer.status != "converged":
                return None, None
            lam = answer.lam
    except (InputError, ArithmeticError, ValueError) as exc:
        log.info("the coarse model did not solve (%s): no prediction", exc)
        return None, None
    return predict_zone(problem.contact_points, coarse.contact_points, lam > 0, neighbours), coarse


def predicted_zone(problem: ContactProblem, coarse: CoarseModel | None = None) -> Zone | None:
    """The contact zone load control matches a large model on: analytic, else from a coarser
    model; None for models under :data:`ZONE_FROM_DOFS` dofs or rows that bound no single dof."""
    disc = problem.discretisation
    if disc is None or disc.prescribed.size < ZONE_FROM_DOFS or selection_dofs(problem.N) is None:
        return None
    zone = analytic_zone(problem)
    if zone is None and coarse is not None:
        zone = coarse_zone(problem, coarse(problem))[0]
    return zone


def match(problem: ContactProblem, zone: Zone | None = None) -> Matched:
    """The problem at the push whose total contact force is its target load.

    The load is the contact forces' resultant along the push (on a curved
    obstacle each force counts with the cosine of its normal's tilt,
    ``Push.resultant``), the load the body's boundary applies. On the
    predicted ``zone`` by the zone kernel (one factorisation) when given and
    the obstacle is flat across the push, else (or should the prediction
    fail) on the full active-set system from the candidates the scene
    predicts in contact.
    """
    if not problem.pending:
        raise InputError("the problem has no target load to match: it is solved as it is")
    before = counters()
    pu, disc = problem.push, problem.discretisation
    f0 = pu.load * pu.f_load if pu.f_load is not None else None
    if zone is not None and pu.resultant is None:  # the zone kernel sums forces along the push
        try:
            system = ZoneSolver(problem.K, problem.N)
            scale, _, lam, final = system.push_for_load(
                pu.f1, pu.d0, pu.d1, pu.target, problem.force_multiplicity, zone,
                f0=np.zeros_like(pu.f1) if f0 is None else f0)
            log.info("load matched on a predicted zone (%s)", final.counts())
            return Matched(problem.pushed(scale), WarmStart(lam=lam, zone_solver=system, zone=final),
                           "zone kernel", spent(before))
        except FactorTooLarge:
            raise  # a refusal, not a failed prediction: the full active set would factorise too
        except (ValueError, ArithmeticError) as exc:
            log.info("load control on the predicted zone failed (%s): full active set", exc)
    scale, lam, u = calibrate_push(problem.K, problem.N, pu.f1, pu.d0, pu.d1, pu.target,
                                   problem.force_multiplicity, f0=f0,
                                   start=disc.predicted_contact, weights=pu.resultant)
    return Matched(problem.pushed(scale), WarmStart(lam=lam, u=u), "full active set",
                   spent(before))


def at_load(problem: ContactProblem, coarse: CoarseModel | None = None) -> ContactProblem:
    """``problem`` at its target load (matched by :func:`match` on the zone the scene predicts),
    or itself when it has none: the QP every method can then be run on, cold."""
    if not problem.pending:
        return problem
    return match(problem, predicted_zone(problem, coarse)).problem


def _predictions(problem: ContactProblem, method: str, options: dict[str, Any],
                 coarse: CoarseModel | None, zone: Zone | None = None) -> dict[str, Any]:
    """What the scene predicts, as the options of a method that takes a prediction (its own
    options win): ``nested`` a contact zone (``zone`` when load control already predicted it),
    ``pdas-amg`` a first active set."""
    given = set(options)
    if method == "nested" and not given & {"zone", "coarse"} \
            and selection_dofs(problem.N) is not None:
        if not options.get("analytic", True):
            zone = None  # the caller asked for no analytic zone: the coarse model's only
        elif zone is None:
            zone = analytic_zone(problem)
        if zone is None and coarse is not None:
            zone = coarse_zone(problem, coarse(problem))[0]
        return {"zone": zone} if zone is not None else {}
    if method == "pdas-amg" and not given & {"active0", "coarse", "warm_start"}:
        a = analytic_extent(problem)  # the candidates inside it: no coarse model to solve
        if a is not None:
            return {"active0": radial_distance(problem.contact_points) < a}
        if coarse is None:
            return {}
        zone, settled = coarse_zone(problem, coarse(problem), neighbours=1)
        if zone is None:
            return {}
        found = {"active0": zone.core}
        if problem.pending and settled is not None:  # the coarse model's push, as a first guess
            mine = float(np.max(np.abs(problem.discretisation.prescribed)))
            theirs = float(np.max(np.abs(settled.discretisation.prescribed)))
            found["push0"] = (problem.push.scale * theirs * settled.scales.displacement
                              / (mine * problem.scales.displacement))
        return found
    return {}


def solve(problem: ContactProblem, method: str = "auto", *, tol: float | None = None,
          max_iter: int | None = None, warm_start: Any = None, coarse: CoarseModel | None = None,
          keep_factor: bool = False, **options: Any) -> tuple[ContactProblem, ContactSolution]:
    """Solve ``problem`` with ``method``, matching its target load first when it has one.

    Returns the problem the answer solves (``problem`` itself, or it at the
    matched push) and the judged solution. ``coarse`` (from the scene: a
    coarser model of the same scene) feeds the predictions of the zone kernel,
    ``nested`` and ``pdas-amg``; ``keep_factor`` keeps the method's last
    factorisation on the solution (see :func:`signorini.solvers.registry.run`).
    """
    start = None if warm_start is None else WarmStart.of(warm_start)
    name = auto.choose(problem, options, start)[0] if method == "auto" else method
    bordered = problem.pending and name == "pdas-amg" and amg.border_factor(problem) is not None
    stages: dict[str, dict[str, int]] = {}
    zone = None
    if problem.pending and not bordered:
        log.info("matching the target load: predicting the contact zone on a coarser model")
        zone = predicted_zone(problem, coarse)  # predicted once: load control's, and nested's
        matched = match(problem, zone)
        stages["load_control"] = matched.work
        problem = matched.problem
    if method == "auto" and start is None and "load_control" in stages:
        start = matched.warm_start  # the fastest route: confirm what load control found
    else:  # a method named by the caller starts cold, from the scene's predictions only
        before = counters()
        options = {**_predictions(problem, name, options, coarse, zone), **options}
        work = spent(before)
        if work:  # a coarser model solved for its prediction
            stages["prediction"] = work
    settled, solution = registry.run(problem, method, tol=tol, max_iter=max_iter,
                                     warm_start=start, keep_factor=keep_factor, **options)
    solution.work = {**stages, **solution.work}
    if "load_control" in stages:
        solution.message += f"; load matched by {matched.how} ({_said(matched.work)})"
    return settled, solution


def _said(work: dict[str, int]) -> str:
    return ", ".join(f"{value} {key.replace('_', ' ')}" for key, value in work.items()) or "no work"


__all__ = ["CoarseModel", "Matched", "ZONE_FROM_DOFS", "analytic_extent", "analytic_zone", "at_load",
           "coarse_zone", "counters", "match", "predicted_zone", "solve", "spent"]
