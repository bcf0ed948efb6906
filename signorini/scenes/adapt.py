"""Adaptive refinement: solve, estimate, mark, refine, until the estimate meets a target.

Each step (:func:`solve_adaptive`):

1. assemble the scene on the current mesh and solve it (any method; load
   targeting starts from the last step's contact zone);
2. when the contact outgrew the candidates (a node beyond them through the
   obstacle, or the outermost candidate in contact: the solution is
   ``model_inadequate``, :mod:`signorini.adequacy`), widen the candidates by
   :data:`GROWTH` on the same mesh and solve again;
3. estimate the error (:func:`signorini.fem.estimate.estimate`); stop when
   ``η / ‖u_h‖_E ≤ target``;
4. mark the fewest elements that carry a fraction :data:`THETA` of η²
   (Dörfler's bulk criterion: W. Dörfler, "A convergent adaptive algorithm
   for Poisson's equation", SINUM 33 (1996) 1106–1124), refine them
   conformingly (scikit-fem's red-green-blue ``MeshTri.refined(marked)``),
   move new boundary nodes onto the curved boundary, and stop instead when
   the refined mesh would exceed ``max_dofs``.

A family takes part when its ``build`` accepts ``mesh=`` (the scene rebuilt
on a given mesh: boundary sets found by position) and :data:`CURVED` says
how to put new nodes on its curved boundary.
"""

from __future__ import annotations

import inspect
import logging
import time
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from signorini.errors import InputError
from signorini.fem.assembly import assemble
from signorini.fem.estimate import ErrorEstimate, estimate
from signorini.fem.model import SceneModel
from signorini.problem import ContactProblem, ContactSolution
from signorini.scenes.families import get_scene, scene_reference
from signorini.scenes.meshing import snap_to_circle
from signorini.solvers.registry import solve as solve_problem

log = logging.getLogger(__name__)

#: Dörfler's bulk parameter: refine the fewest elements that carry this fraction of η²
THETA = 0.5
#: the candidates widen by this factor when the contact outgrows them
GROWTH = 1.5
MAX_GROWTH = 8
DEFAULT_MAX_DOFS = 100_000
MAX_STEPS = 30


def quarter_disc_snap(params: dict[str, Any]) -> Callable:
    """New arc nodes of the Hertz scenes' quarter disc moved radially onto the circle."""
    return snap_to_circle((0.0, params["R"]), params["R"])


#: how each adaptive family puts refined boundary nodes back on its curved boundary
CURVED: dict[str, Callable[[dict[str, Any]], Callable]] = {
    "hertz-cylinder": quarter_disc_snap,
    "hertz-sphere": quarter_disc_snap,
}


@dataclass
class AdaptiveRun:
    """What the adaptive loop did: the final problem and solution, and one row per solve."""

    problem: ContactProblem
    solution: ContactSolution
    estimate: ErrorEstimate | None
    steps: list[dict[str, Any]] = field(default_factory=list)
    reason: str = ""


def parse_target(value: Any) -> float:
    """A relative target: ``0.001``, ``"0.001"`` or ``"0.1%"``; InputError otherwise."""
    text = str(value).strip()
    try:
        target = float(text[:-1]) / 100.0 if text.endswith("%") else float(text)
    except ValueError:
        raise InputError(f"target error {value!r} is not a number: give e.g. 0.001 or 0.1%") from None
    if not 0.0 < target < 1.0:
        raise InputError(f"target error {value!r} must be in (0, 1), or a percentage in (0 %, 100 %)")
    return target


def dorfler(indicators: np.ndarray, theta: float = THETA) -> np.ndarray:
    """The fewest elements whose squared indicators sum to ``theta`` of the total (largest first)."""
    squares = indicators ** 2
    order = np.argsort(squares)[::-1]
    cumulative = np.cumsum(squares[order])
    count = int(np.searchsorted(cumulative, theta * cumulative[-1])) + 1
    return np.sort(order[:min(count, len(order))])


def refine(mesh: Any, marked: np.ndarray, snap: Callable | None) -> Any:
    """``mesh`` refined conformingly at ``marked`` elements, new boundary nodes snapped."""
    refined = mesh.refined(marked)
    return snap(refined) if snap is not None else refined


def _rebuild(family, params: dict[str, Any], given: set[str], mesh: Any,
             contact_extent: float | None) -> SceneModel:
    """The scene on ``mesh``; load targeting starts from the candidates within ``contact_extent``."""
    model = family.build(params, given, mesh=mesh)
    if contact_extent is not None:
        x = model.mesh.p[0, model.contact_nodes]
        model.predicted_contact = x <= contact_extent
    return model


def _contact_extent(model: SceneModel, problem: ContactProblem,
                    solution: ContactSolution) -> float | None:
    """How far the contact reached (physical x of the last candidate with a force)."""
    if not np.all(np.isfinite(solution.lam)) or not np.any(solution.lam > 0):
        return None
    return float(np.max(model.mesh.p[0, model.contact_nodes][solution.lam > 0]))


def solve_adaptive(name: str, values: dict[str, Any], target: float, *, method: str = "pdas",
                   tol: float | None = None, max_iter: int | None = None,
                   max_dofs: int | None = None, theta: float = THETA,
                   on_step: Callable[[ContactProblem, ContactSolution, ErrorEstimate | None], None]
                   | None = None, **options: Any) -> AdaptiveRun:
    """Refine scene ``name`` adaptively until ``η / ‖u_h‖_E ≤ target`` or ``max_dofs``.

    Returns the last step's problem, solution and estimate; ``reason`` says
    why the loop stopped (the target met, the dof limit, or a solve that did
    not converge) and is appended to the solution's message. ``on_step`` is
    called with every step's problem, solution and estimate (studies use it).
    """
    family = get_scene(name)
    if name not in CURVED or "mesh" not in inspect.signature(family.build).parameters:
        raise InputError(f"scene {name!r} cannot be refined adaptively: target error works for "
                         f"{', '.join(sorted(CURVED))}")
    max_dofs = DEFAULT_MAX_DOFS if max_dofs is None else int(max_dofs)
    if max_dofs <= 0:
        raise InputError(f"max dofs {max_dofs} must be positive")
    given = set(values)
    params = family.parse(values)
    snap = CURVED[name](params)
    model = family.build(params, given)
    run = None
    steps: list[dict[str, Any]] = []
    growths = 0
    for step in range(MAX_STEPS):
        start = time.perf_counter()
        problem = assemble(model)
        problem.scene, problem.reference = name, scene_reference(name)
        solution = solve_problem(problem, method, tol=tol, max_iter=max_iter, **options)
        seconds = time.perf_counter() - start
        if solution.status == "model_inadequate" and growths < MAX_GROWTH:
            growths += 1
            params = {**params, "candidates": params["candidates"] * GROWTH}
            log.info("step %d: the contact outgrew the candidates; widened to %g half-widths",
                     step, params["candidates"])
            model = _rebuild(family, params, given, model.mesh,
                             _contact_extent(model, problem, solution))
            steps.append(_row(step, problem, solution, None, 0, seconds, "candidates widened"))
            continue
        found = estimate(problem, solution) if solution.success else None
        if on_step is not None:
            on_step(problem, solution, found)
        run = AdaptiveRun(problem, solution, found, steps)
        if found is None:
            run.reason = f"adaptive refinement stopped: the solve ended {solution.status}"
            steps.append(_row(step, problem, solution, None, 0, seconds, "stopped"))
            break
        if found.relative <= target:
            run.reason = (f"target error {100 * target:.3g} % met: estimate {100 * found.relative:.3g} % "
                          f"at {problem.n} dofs after {step + 1} solves")
            steps.append(_row(step, problem, solution, found, 0, seconds, "target met"))
            break
        marked = dorfler(found.elements, theta)
        mesh = refine(model.mesh, marked, snap)
        dofs = mesh.p.size
        if dofs > max_dofs:
            run.reason = (f"max dofs {max_dofs} reached: estimate {100 * found.relative:.3g} % > target "
                          f"{100 * target:.3g} % at {problem.n} dofs (the next mesh has {dofs})")
            steps.append(_row(step, problem, solution, found, 0, seconds, "max dofs"))
            break
        steps.append(_row(step, problem, solution, found, len(marked), seconds, "refined"))
        model = _rebuild(family, params, given, mesh, _contact_extent(model, problem, solution))
    else:
        run.reason = f"adaptive refinement stopped after {MAX_STEPS} steps"
    run.solution.message = f"{run.solution.message}; {run.reason}".lstrip("; ")
    run.solution.extras["adaptive"] = steps
    log.info("%s", run.reason)
    return run


def _row(step: int, problem: ContactProblem, solution: ContactSolution,
         found: ErrorEstimate | None, marked: int, seconds: float, action: str) -> dict[str, Any]:
    """One flat record of a step (kept in the result's JSON under extras.adaptive)."""
    return {"step": step, "dofs": problem.n, "elements": int(problem.mesh.t.shape[1]),
            "candidates": problem.m, "status": solution.status,
            "estimate": found.relative if found is not None else float("nan"),
            "marked": marked, "seconds": seconds, "action": action}
