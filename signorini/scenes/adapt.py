"""Adaptive refinement: solve, estimate, mark, refine, until the estimate meets a target.

Each step (:func:`solve_adaptive`):

1. assemble the scene on the current mesh and solve it (any method; load
   targeting starts from the last step's contact zone);
2. when the contact outgrew the candidates (the solution is ``model_inadequate``,
   :mod:`signorini.certification.adequacy`), widen them on the same mesh and solve again;
3. estimate the error (:func:`signorini.fem.estimate.estimate`) and stop when the estimate of
   the chosen quantity meets the target: ``"pressure"`` (the default where the model has
   contact pressures: :class:`signorini.fem.contact_estimate.PressureEstimate`) or ``"energy"``
   (``η / ‖u_h‖_E``);
4. mark (:func:`signorini.scenes.marking.mark`), refine conformingly (scikit-fem's
   red-green-blue ``MeshTri.refined(marked)``) and move new boundary nodes onto the curved
   boundary; stop instead when the refined mesh would exceed ``max_dofs`` or, before its model
   is assembled, the memory the size guard allows (:func:`signorini.scenes.size.over_limit`),
   the last step's answer returned with a message saying the target was not met.

The first mesh is sized before it is made (:func:`signorini.scenes.size.check_size`). Given no
mesh parameter, a family starts from its ``adaptive_start`` (the Hertz scenes: the relaxed mesh
the budgets and the estimate's effectivity were measured on, :class:`~signorini.scenes.base.SceneFamily`).

Every 2D and axisymmetric scene and scene file takes part. A family whose
``build`` accepts ``mesh=`` and that has a ``snap`` (the Hertz scenes) is rebuilt on each new mesh, new nodes first moved onto its curved boundary,
and widens its candidate zone by :data:`GROWTH` when the contact outgrows
it. Any other model is carried onto the refinement
(:func:`signorini.fem.transfer.refined_model`) and takes as new candidates
the boundary nodes that went through the obstacle or border a candidate in
contact at the zone's edge (:func:`beyond_candidates`). 3D scenes are refused.
"""

from __future__ import annotations

import inspect
import logging
import time
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from signorini.errors import InputError, docs_page
from signorini.numerics.factor import timed
from signorini.fem.assembly import assemble
from signorini.fem.estimate import ErrorEstimate, estimate
from signorini.fem.transfer import refined_model, with_candidates
from signorini.fem.model import SceneModel
from signorini.certification.kkt import gap_scale
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.scenes.marking import THETA, mark
from signorini.scenes.registry import get_scene
from signorini.scenes.scenefile import build_scene_model, family_scene_values
from signorini.scenes.size import MEMORY_VARIABLE, Solver, check_size, over_limit

log = logging.getLogger(__name__)

QUANTITIES = ("pressure", "energy")
#: the candidates widen by this factor when the contact outgrows them
GROWTH = 1.5
MAX_GROWTH = 8
DEFAULT_MAX_DOFS = 100_000
MAX_STEPS = 30


@dataclass
class AdaptiveRun:
    """What the adaptive loop did: the final problem and solution, and one row per solve."""

    problem: ContactProblem
    solution: ContactSolution
    estimate: ErrorEstimate | None
    steps: list[dict[str, Any]] = field(default_factory=list)
    reason: str = ""
    #: the estimate met the target (False when a limit, a failed solve or the step count stopped it)
    target_met: bool = False


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


def measured(found: ErrorEstimate, quantity: str) -> float:
    """The estimate of ``quantity`` (relative)."""
    return found.relative if quantity == "energy" else found.pressure.relative


@dataclass
class _Scene:
    """What the loop rebuilds on each new mesh: a family that builds on a given mesh (and can
    widen its candidates), or any 2D model carried onto the refinement
    (:func:`signorini.fem.transfer.refined_model`)."""

    name: str
    model: SceneModel
    family: Any = None
    params: dict[str, Any] = field(default_factory=dict)
    given: set[str] = field(default_factory=set)
    snap: Callable | None = None

    def rebuilt(self, mesh: Any, model: SceneModel, solution: ContactSolution) -> SceneModel:
        """The family's scene on ``mesh``; load targeting starts from the candidates within the
        reach of ``model``'s contact in ``solution`` (the x of its last candidate with a force)."""
        rebuilt = self.family.build(self.params, self.given, mesh=mesh)
        lam = solution.lam
        if np.all(np.isfinite(lam)) and np.any(lam > 0):
            extent = float(np.max(model.mesh.p[0, model.contact_nodes][lam > 0]))
            rebuilt.predicted_contact = rebuilt.mesh.p[0, rebuilt.contact_nodes] <= extent
        return rebuilt

    def on(self, model: SceneModel, mesh: Any, solution: ContactSolution) -> SceneModel:
        """The scene on ``mesh``, refined from ``model``'s (not yet snapped); ``solution`` is
        ``model``'s, and load targeting starts from its contact."""
        if self.family is not None:
            return self.rebuilt(self.snap(mesh) if self.snap else mesh, model, solution)
        return refined_model(model, mesh, solution.lam > 0, self.snap)


def _scene(name: str, values: dict[str, Any], solved_by: Solver | None = None) -> _Scene:
    """The scene ``name`` (a family or a ``.toml`` scene file) ready for the loop; a family's
    mesh too big for the memory limit is refused before it is made."""
    if name.lower().endswith(".toml"):
        found = family_scene_values(name, values)
        if found is None:  # a mesh scene
            scene, model = build_scene_model(name, values)
            return _checked(_Scene(scene, model))
        name, values = found
    family = get_scene(name)
    if not set(values) & set(family.adaptive_start):  # no mesh given: the measured start
        values = {**family.adaptive_start, **values}
    params = family.parse(values)
    check_size(name, params, solved_by)
    model = family.build(params, set(values))
    snap = family.snap(params) if family.snap is not None else None
    builds_on_mesh = snap is not None and "mesh" in inspect.signature(family.build).parameters
    return _checked(_Scene(name, model, family if builds_on_mesh else None, params, set(values), snap))


def _grown(scene: _Scene, model: SceneModel, problem: ContactProblem,
           solution: ContactSolution) -> SceneModel | None:
    """The model with more candidates after the contact outgrew them (None: nothing to add).

    A family that builds on a mesh widens its candidate zone by :data:`GROWTH`;
    any other model takes the boundary nodes beyond its candidates that went
    through the obstacle, and those next to an edge candidate in contact.
    """
    if scene.family is not None:
        scene.params = {**scene.params, "candidates": scene.params["candidates"] * GROWTH}
        log.info("the contact outgrew the candidates; widened to %g half-widths",
                 scene.params["candidates"])
        return scene.rebuilt(model.mesh, model, solution)
    extra = beyond_candidates(model, problem, solution)
    if extra.size == 0:
        return None
    log.info("the contact outgrew the candidates; %d boundary node(s) added", extra.size)
    return with_candidates(model, extra, solution.lam > 0)


def beyond_candidates(model: SceneModel, problem: ContactProblem,
                      solution: ContactSolution) -> np.ndarray:
    """Boundary nodes beyond the candidates that went through the obstacle, and those sharing a
    boundary facet with an edge candidate in contact (mesh node numbers)."""
    watch = problem.model.watch
    if watch is None or watch.nodes is None:
        return np.zeros(0, dtype=int)
    through = watch.nodes[-watch.gap(problem, solution.u) > 1e-9 * gap_scale(problem, solution.u)]
    touching = np.asarray(model.contact_nodes)[watch.edge[solution.lam[watch.edge] > 0]]
    mesh = model.mesh
    ends = mesh.facets[:, mesh.boundary_facets()]
    reach = np.isin(ends, touching).any(axis=0)
    beside = np.intersect1d(ends[:, reach].ravel(), watch.nodes)
    return np.union1d(through, beside)


def _steeper_than_measured(scene: _Scene) -> str:
    """A warning when a Hertz scene starts graded more steeply than its adaptive start: from there the
    pressure estimate was measured at half the true error (docs/estimate.md, "the start matters")."""
    if scene.family is None:
        return ""
    default = scene.family.adaptive_start.get(
        "grading", next(p.default for p in scene.family.params if p.name == "grading"))
    if scene.params["grading"] <= default:
        return ""
    return (f"; warning: the mesh started graded at {scene.params['grading']:g}, more steeply than "
            f"the adaptive start's {default:g}: from there the pressure estimate was measured below the true "
            f"error ({docs_page('estimate')}); start from that grading or finer")


def _checked(scene: _Scene) -> _Scene:
    if (mesh := getattr(scene.model, "mesh", None)) is None or not hasattr(mesh, "refined") or mesh.dim() > 2:
        raise InputError(f"scene {scene.name!r} is {'3D' if mesh is not None else 'of two bodies'}: "
                         "target error refines one body in 2D or axisymmetric (marked triangles); refine "
                         "the others by their mesh parameters (3D uniformly with --set refine=N)")
    return scene


def solve_adaptive(name: str, values: dict[str, Any], target: float,
                   solver: Callable[[ContactProblem], tuple[ContactProblem, ContactSolution]], *,
                   max_dofs: int | None = None, theta: float = THETA, quantity: str | None = None,
                   solved_by: Solver | None = None,
                   on_step: Callable[[ContactProblem, ContactSolution, ErrorEstimate | None], None]
                   | None = None) -> AdaptiveRun:
    """Refine scene ``name`` (a family, or the path of a ``.toml`` scene file) adaptively until
    the estimate of ``quantity`` meets ``target`` or the next mesh would exceed ``max_dofs`` or
    the memory limit for the method ``solved_by`` (:func:`signorini.scenes.size.over_limit`).

    ``solver`` solves each step's problem (matching its target load) and
    returns the problem solved and the judged solution
    (:func:`signorini.solve_adaptive` passes load control with the method).

    ``quantity`` is ``"pressure"`` (the default where the scene has contact
    pressures) or ``"energy"``.
    Returns the last step's problem, solution (its ``seconds`` every step's, by stage) and
    estimate; ``reason`` says
    why the loop stopped (the target met, the dof or memory limit, or a solve
    that did not converge) and is appended to the solution's message. ``on_step`` is
    called with every step's problem, solution and estimate (studies use it).
    """
    if quantity is not None and quantity not in QUANTITIES:
        raise InputError(f"target quantity {quantity!r} is not one of {', '.join(QUANTITIES)}")
    if max_dofs is None:
        max_dofs = DEFAULT_MAX_DOFS
    elif isinstance(max_dofs, bool) or not isinstance(max_dofs, (int, np.integer)) or max_dofs <= 0:
        raise InputError(f"max dofs {max_dofs!r} must be a positive whole number, e.g. "
                         f"max_dofs={DEFAULT_MAX_DOFS}")
    stages: dict[str, float] = {}  # every step's seconds by stage: the record's time
    with timed(stages, "mesh"):
        scene = _scene(name, values, solved_by)
        _check_first(scene, solved_by, max_dofs)
    model = scene.model
    run = None
    steps: list[dict[str, Any]] = []
    growths = 0
    for step in range(MAX_STEPS):
        start = time.perf_counter()
        with timed(stages, "assemble"):
            problem = assemble(model)
        problem.name = scene.name
        problem, solution = solver(problem)
        for stage, spent in solution.seconds.items():
            stages[stage] = stages.get(stage, 0.0) + spent
        seconds = time.perf_counter() - start
        if solution.status == "model_inadequate" and growths < MAX_GROWTH:
            with timed(stages, "mesh"):
                grown = _grown(scene, model, problem, solution)
            if grown is not None:
                growths += 1
                model = grown
                steps.append(_row(step, problem, solution, None, 0, seconds, "candidates widened"))
                continue
        with timed(stages, "estimate"):
            found = estimate(problem, solution) if solution.success else None
        if on_step is not None:
            on_step(problem, solution, found)
        run = AdaptiveRun(problem, solution, found, steps)
        if found is None:
            run.reason = f"adaptive refinement stopped: the solve ended {solution.status}"
            steps.append(_row(step, problem, solution, None, 0, seconds, "stopped"))
            break
        if quantity is None:
            quantity = "pressure" if found.pressure is not None else "energy"
        elif quantity == "pressure" and found.pressure is None:
            raise InputError(f"scene {name!r} has no contact pressure estimate: give quantity 'energy'")
        what = "pressure" if quantity == "pressure" else "energy-norm"
        value = measured(found, quantity)
        log.info("step %d: %d dofs, %s estimate %.3g %% (target %.3g %%), %.2f s", step, problem.n,
                 what, 100 * value, 100 * target, seconds)
        if value <= target:
            run.target_met = True
            run.reason = (f"target {what} error {100 * target:.3g} % met: estimate {100 * value:.3g} % "
                          f"at {problem.n} dofs after {step + 1} solve{'s' * (step > 0)}")
            steps.append(_row(step, problem, solution, found, 0, seconds, "target met"))
            break
        with timed(stages, "mesh"):
            marked = mark(model.mesh, found, quantity, theta)
            mesh = model.mesh.refined(marked)
        limit = _limit_reached(mesh.p.size, max_dofs, model, solved_by)
        if limit is not None:
            action, reached, next_mesh = limit
            run.reason = (f"{reached} reached: {what} estimate {100 * value:.3g} % > target "
                          f"{100 * target:.3g} % at {problem.n} dofs "
                          f"(the next mesh has {next_mesh})")
            steps.append(_row(step, problem, solution, found, 0, seconds, action))
            break
        steps.append(_row(step, problem, solution, found, len(marked), seconds, "refined"))
        with timed(stages, "mesh"):
            model = scene.on(model, mesh, solution)
    else:
        run.reason = f"adaptive refinement stopped after {MAX_STEPS} steps"
    run.reason += _steeper_than_measured(scene)
    run.solution.message = f"{run.solution.message}; {run.reason}".lstrip("; ")
    run.solution.extras["adaptive"] = steps
    run.solution.seconds = stages
    run.solution.extras.update(target_error=target, target_on=quantity or "",
                               target_met=run.target_met)
    log.info("%s", run.reason)
    return run


def _memory_params(model: SceneModel) -> dict[str, Any]:
    """What :func:`signorini.scenes.size.bytes_per_dof` reads of a model."""
    return {**model.params, "nu": model.nu, "volumetric": model.volumetric}


def _check_first(scene: _Scene, solved_by: Solver | None, max_dofs: int) -> None:
    """InputError when the first model (a mesh scene file's, say) is already over ``max_dofs``
    or the memory limit."""
    if scene.model.mesh.p.size > max_dofs:
        raise InputError(f"scene {scene.name!r} starts with {scene.model.mesh.p.size:,} dofs, over "
                         f"max dofs {max_dofs:,}: raise max dofs (--max-dofs) or start from a "
                         "coarser mesh (a smaller n_contact)")
    over = over_limit(scene.model.mesh.p.size, 2, _memory_params(scene.model), solved_by)
    if over is not None:
        raise InputError(f"scene {scene.name!r} has {scene.model.mesh.p.size:,} dofs, about "
                         f"{over[0] / 1e9:,.1f} GB to build and solve, over the limit of "
                         f"{over[1] / 1e9:,.1f} GB ({MEMORY_VARIABLE}): start from a coarser mesh")


def _limit_reached(dofs: int, max_dofs: int, model: SceneModel,
                   solved_by: Solver | None) -> tuple[str, str, str] | None:
    """``(action, what was reached, the next mesh)`` when a refined mesh of ``dofs`` dofs
    exceeds ``max_dofs`` or the memory limit (before its model is assembled); None when it fits."""
    if dofs > max_dofs:
        return "max dofs", f"max dofs {max_dofs}", str(dofs)
    over = over_limit(dofs, 2, _memory_params(model), solved_by)
    if over is None:
        return None
    need, limit = over
    return ("memory limit", f"memory limit of {limit / 1e9:,.1f} GB ({MEMORY_VARIABLE}, else ¾ of "
            "this machine's memory)", f"{dofs} dofs, about {need / 1e9:,.1f} GB to build and solve")


def _row(step: int, problem: ContactProblem, solution: ContactSolution,
         found: ErrorEstimate | None, marked: int, seconds: float, action: str) -> dict[str, Any]:
    """One flat record of a step (kept in the result's JSON under extras.adaptive)."""
    return {"step": step, "dofs": problem.n, "elements": int(problem.model.mesh.t.shape[1]),
            "candidates": problem.m, "status": solution.status,
            "estimate": found.relative if found is not None else float("nan"),
            "pressure_estimate": found.pressure.relative
            if found is not None and found.pressure is not None else float("nan"),
            "marked": marked, "seconds": seconds, "action": action}


__all__ = ["AdaptiveRun", "parse_target", "measured", "beyond_candidates", "solve_adaptive"]
