"""Load control, and the one pipeline from a checked request to a certified answer.

A scene loaded by a target force P is assembled at a nominal push
(``problem.model.pending``). Its load and gaps are affine in the push s,
``f(s) = s f₁ + f₀`` and ``d(s) = d₀ + s d₁``, so on a fixed active set the
answer is affine in s too, and the push whose total contact force
``μ Σλ`` equals P solves one scalar equation per active set
(:func:`signorini.numerics.push.push_for_load`). This module is the one
driver that finds it, whatever the method:

- **zone kernel** (large models whose contact zone can be predicted: from
  the reference's analytic contact width, else from a coarser model of the
  scene): one factorisation of K with the predicted core pinned, the push
  one more unknown of the band's LCP (:class:`signorini.numerics.zone.ZoneSolver`);
- **full active set**: the augmented system ``K u + N_Aᵀλ_A = s f₁ + f₀,
  N_A u = d₀ + s d₁, μ Σλ_A = P``, one factorisation per active-set step,
  from the active set the scene predicts
  (:func:`signorini.numerics.push.calibrate_push`);
- **left to the method**, when the method declares that it matches this
  problem's pending load itself (:attr:`Method.matches_load`, e.g. a bordered
  load unknown of each CG system: no factorisation is ever made).

:func:`solve` is the part of the pipeline (:func:`signorini.solve`) that runs when there is
something to do before the method: load control, or the scene's prediction for a method that
takes one; then the method (:func:`signorini.solvers.registry.run`: its answer held to the
contract and certified once). What a method can use is what it declares on its
:class:`~signorini.solvers.base.Method`, never its name: the scene's
``prediction`` of the contact (a zone, or a first active set) and whether it
takes load control's answer as an explicit warm start (``warm_from_load``);
a method that does not starts cold and the iterations it reports are its own.
Every stage's work is in ``solution.work``: ``load control``, the
``prediction`` (a coarser model solved to predict the contact) and the
``method``; their wall times, and the certificate's, in ``solution.seconds``.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any, Callable, NamedTuple

import numpy as np

from signorini.errors import InputError
from signorini.certification.kkt import Certificate
from signorini.numerics.active_set import ActiveSetSolver, selection_dofs
from signorini.numerics.factor import FactorTooLarge, counting, timed
from signorini.numerics.push import calibrate_push
from signorini.numerics.zone import (Zone, ZoneSolver, predict_zone, radial_distance,
                                     zone_around_points)
from signorini.problem.contact import ContactProblem, ContactSolution, WarmStart
from signorini.references.catalogue import reference_of
from signorini.solvers import registry
from signorini.solvers.registry import Request

log = logging.getLogger(__name__)

#: a load-targeted model of at least this many dofs (prescribed ones included) is matched on a
#: predicted contact zone (one factorisation) when its scene predicts one
ZONE_FROM_DOFS = 20_000

#: a function of a problem returning a coarser model of the same scene (or None)
CoarseModel = Callable[[ContactProblem], "ContactProblem | None"]


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
        if coarse.model.pending:
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
    model = problem.model
    if model.prescribed.size < ZONE_FROM_DOFS or selection_dofs(problem.N) is None:
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
    if not problem.model.pending:
        raise InputError("the problem has no target load to match: it is solved as it is")
    with counting() as work:
        problem, start, how = _matched(problem, zone)
    return Matched(problem, start, how, work.listed())


def _matched(problem: ContactProblem, zone: Zone | None) -> tuple[ContactProblem, WarmStart, str]:
    model = problem.model
    pu = model.push
    f0 = pu.load * pu.f_load if pu.f_load is not None else None
    if zone is not None and pu.resultant is None:  # the zone kernel sums forces along the push
        try:
            system = ZoneSolver(problem.K, problem.N)
            scale, _, lam, final = system.push_for_load(
                pu.f1, pu.d0, pu.d1, pu.target, problem.force_multiplicity, zone,
                f0=np.zeros_like(pu.f1) if f0 is None else f0)
            log.info("load matched on a predicted zone (%s)", final.counts())
            return (problem.pushed(scale), WarmStart(lam=lam, zone_solver=system, zone=final),
                    "zone kernel")
        except FactorTooLarge:
            raise  # a refusal, not a failed prediction: the full active set would factorise too
        except (ValueError, ArithmeticError) as exc:
            log.info("load control on the predicted zone failed (%s): full active set", exc)
    system = ActiveSetSolver(problem.K, problem.N)
    scale, lam, u = calibrate_push(problem.K, problem.N, pu.f1, pu.d0, pu.d1, pu.target,
                                   problem.force_multiplicity, f0=f0,
                                   start=model.predicted_contact, weights=pu.resultant, system=system)
    return (problem.pushed(scale), WarmStart(lam=lam, u=u, factor=system.factor),
            "full active set")


def at_load(problem: ContactProblem, coarse: CoarseModel | None = None) -> ContactProblem:
    """``problem`` at its target load (matched by :func:`match` on the zone the scene predicts),
    or itself when it has none: the QP every method can then be run on, cold."""
    if not problem.model.pending:
        return problem
    return match(problem, predicted_zone(problem, coarse)).problem


def _predictions(problem: ContactProblem, kind: str, options: dict[str, Any],
                 coarse: CoarseModel | None, zone: Zone | None = None) -> dict[str, Any]:
    """What the scene predicts, as the options of a method that takes a prediction of ``kind``
    (its own options win): ``zone`` a contact zone (``zone`` when load control already
    predicted it), ``active set`` a first active set (and, for a pending load, a first push)."""
    given = set(options)
    if kind == "zone" and not given & {"zone", "coarse"} and selection_dofs(problem.N) is not None:
        if not options.get("analytic", True):
            zone = None  # the caller asked for no analytic zone: the coarse model's only
        elif zone is None:
            zone = analytic_zone(problem)
        if zone is None and coarse is not None:
            zone = coarse_zone(problem, coarse(problem))[0]
        return {"zone": zone} if zone is not None else {}
    if kind == "active set" and not given & {"active0", "coarse", "warm_start"}:
        a = analytic_extent(problem)  # the candidates inside it: no coarse model to solve
        if a is not None:
            return {"active0": radial_distance(problem.contact_points) < a}
        if coarse is None:
            return {}
        zone, settled = coarse_zone(problem, coarse(problem), neighbours=1)
        if zone is None:
            return {}
        found = {"active0": zone.core}
        if problem.model.pending and settled is not None:  # the coarse model's push, as a first guess
            mine = float(np.max(np.abs(problem.model.prescribed)))
            theirs = float(np.max(np.abs(settled.model.prescribed)))
            found["push0"] = (problem.model.push.scale * theirs * settled.scales.displacement
                              / (mine * problem.scales.displacement))
        return found
    return {}


class Solved(NamedTuple):
    """The problem the answer solves (at the matched push for a target load), the judged
    answer, and its certificate (computed once)."""

    problem: ContactProblem
    solution: ContactSolution
    certificate: Certificate


def solve(problem: ContactProblem, request: Request, *, warm_start: Any = None,
          coarse: CoarseModel | None = None, keep_factor: bool = False) -> Solved:
    """Solve ``problem`` as ``request`` says (checked by
    :func:`~signorini.solvers.registry.check_request`), matching its target load first when it
    has one and the method does not match it itself, and handing a method that takes the
    scene's prediction of the contact that prediction (:func:`signorini.solve` comes here only
    then; any other problem goes to the method's run directly).

    ``coarse`` (from the scene: a coarser model of the same scene) feeds the
    predictions of the zone kernel and of the methods that take one;
    ``keep_factor`` keeps the method's last factorisation on the solution (see
    :func:`signorini.solvers.registry.run`).
    """
    start = None if warm_start is None else WarmStart.of(warm_start)
    runs = request.method.runs(problem, request.options, start)  # itself, or the one it picks
    runs.check_rows(problem)  # before load control's work
    stages: dict[str, dict[str, int]] = {}
    seconds: dict[str, float] = {}
    zone, matched, options = None, None, request.options
    if problem.model.pending and not runs.matches(problem):
        log.info("matching the target load: predicting the contact zone on a coarser model")
        with timed(seconds, "load control"):
            zone = predicted_zone(problem, coarse)  # predicted once: load control's and the method's
            matched = match(problem, zone)
        stages["load_control"] = matched.work
        problem = matched.problem
    if matched is not None and request.method.warm_from_load and (
            runs.prediction != "zone" or matched.warm_start.zone_solver is not None):
        # load control's answer, taken as an explicit warm start (by a method that predicts a
        # zone, only with K factorised around one: else it takes the scene's prediction); it is
        # exact at this load, so it replaces a start given from another (a slider's last answer)
        if start is not None:
            log.info("load control's answer at the matched load replaces the warm start given")
        start = matched.warm_start
    elif runs.prediction:  # a method that starts cold, from the scene's predictions only
        with counting() as work, timed(seconds, "prediction"):
            options = {**_predictions(problem, runs.prediction, options, coarse, zone), **options}
        if work.listed():  # a coarser model solved for its prediction
            stages["prediction"] = work.listed()
    solved = Solved(*registry.run(problem, request._replace(options=options), warm_start=start,
                                  keep_factor=keep_factor))
    solved.solution.work = {**stages, **solved.solution.work}
    solved.solution.seconds = {**seconds, **solved.solution.seconds}
    if matched is not None:
        solved.solution.message += f"; load matched by {matched.how} ({_said(matched.work)})"
    return solved


def _said(work: dict[str, int]) -> str:
    return ", ".join(f"{value} {key.replace('_', ' ')}" for key, value in work.items()) or "no work"


__all__ = ["CoarseModel", "Matched", "Solved", "ZONE_FROM_DOFS", "analytic_extent", "analytic_zone",
           "at_load", "coarse_zone", "match", "predicted_zone", "solve"]
