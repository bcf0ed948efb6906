"""Mesh-convergence studies: refine a scene k times, measure its errors, fit their rates.

A study solves a scene at levels 0, 1, …, k of uniform refinement (the
scene's ``refine`` parameter: every element split in four, so the element
size h halves and the dofs roughly quadruple) with every installed exact
method, and measures the errors against the scene's analytic reference
(:attr:`signorini.references.catalogue.Reference.convergence`). The rate of a metric is
:func:`fitted_rate` against h, the median distance between neighbouring contact candidates
(:func:`signorini.studies.problems.candidate_spacing`).
Exact methods solve the same discrete problem, so their errors must
coincide; the study records how far their λ are apart. Every run goes
through the study runner (:mod:`signorini.studies.runner`) with no exact
answer (the reference policy ``none``): the worker rebuilds each level from
its spec, and λ is compared with the first converged method's in this process.

:func:`grading_comparison` sets the graded default against a uniform mesh
(the scene with ``grading`` → 0, i.e. the contact size everywhere) at equal
dofs (:func:`dofs_for_error`). The figures and files of a study:
:mod:`signorini.studies.convergence_report`.
"""

from __future__ import annotations

import logging
from dataclasses import asdict, dataclass, field
from typing import Any, Callable

import numpy as np

from signorini.errors import InputError
from signorini.references.catalogue import REFERENCES
from signorini.scenes import SCENES, get_scene, portable_scene, scene_reference
from signorini.scenes.registry import FamilyField
from signorini.scenes.size import check_size
from signorini.solvers.registry import get_method
from signorini.solvers.registry import methods as registered_methods
from signorini.studies.runner import Row, Task, run_tasks

__all__ = ["COARSE_START", "ESTIMATES", "LABELS", "ConvergenceStudy", "GradingComparison", "LevelResult",
           "check_study", "dofs_for_error", "exact_methods", "fitted_rate", "grading_comparison",
           "level_results", "level_task", "run_study"]

log = logging.getLogger(__name__)

LABELS = {"p0_rel": "p₀ error", "a_rel": "a error", "pressure_l2_rel": "pressure L2 error",
          "pressure_max_rel": "pressure max error on the inner half",
          "edge_over_centre": "edge node pressure / (P/πa)",
          "estimate": "estimate η / ‖u_h‖ (energy norm)", "pressure_estimate": "pressure estimate"}
#: the a posteriori estimates a study records next to the errors (signorini.fem.estimate)
ESTIMATES = ("estimate", "pressure_estimate")
#: the coarse mesh each study starts from unless ``--set`` says otherwise, by scene (a live
#: view of each family's ``convergence_start``, :class:`signorini.scenes.base.SceneFamily`)
COARSE_START = FamilyField("convergence_start")
#: grading that makes a graded scene uniform: the contact's element size everywhere
UNIFORM_GRADING = 1e-6
#: seconds one run (assembly of its level included) may take before it is stopped
TIME_LIMIT = 3600.0


@dataclass(frozen=True)
class LevelResult:
    """One method at one refinement level."""

    level: int
    method: str
    status: str
    dofs: int
    candidates: int
    h: float
    errors: dict[str, float]
    lam_rel_vs_first: float
    assemble_s: float
    solve_s: float


@dataclass
class ConvergenceStudy:
    """The rows of a study and the fitted rates ``rates[method][metric]``."""

    scene: str
    params: dict[str, Any]
    metrics: tuple[str, ...]
    rows: list[LevelResult]
    rates: dict[str, dict[str, float]] = field(default_factory=dict)
    fit_from: int = 0

    def series(self, method: str, metric: str,
               from_level: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(h, dofs, error)`` of one method's converged levels (from ``from_level`` on)."""
        rows = [r for r in self.rows if r.method == method and r.status == "converged"
                and np.isfinite(r.errors.get(metric, np.nan)) and r.level >= from_level]
        return (np.array([r.h for r in rows]), np.array([r.dofs for r in rows], dtype=float),
                np.array([r.errors[metric] for r in rows]))

    @property
    def methods(self) -> list[str]:
        return list(dict.fromkeys(r.method for r in self.rows))

    def max_disagreement(self) -> float:
        """The largest relative λ difference between exact methods at any level."""
        values = [r.lam_rel_vs_first for r in self.rows if np.isfinite(r.lam_rel_vs_first)]
        return max(values, default=0.0)

    def as_dict(self) -> dict[str, Any]:
        return {"scene": self.scene, "params": self.params, "metrics": list(self.metrics),
                "fit_from": self.fit_from, "rates": self.rates,
                "max_lam_rel_between_methods": self.max_disagreement(),
                "rows": [asdict(r) for r in self.rows]}


def fitted_rate(h: np.ndarray, error: np.ndarray) -> float:
    """Slope s of ``log err = s log h + c`` by least squares (nan with fewer than two points)."""
    h, error = np.asarray(h, float), np.asarray(error, float)
    keep = (h > 0) & (error > 0) & np.isfinite(error)
    if keep.sum() < 2:
        return float("nan")
    slope, _ = np.polyfit(np.log(h[keep]), np.log(np.abs(error[keep])), 1)
    return float(slope)


def exact_methods() -> list[str]:
    """Every installed method that is exact when it converges."""
    return [m.name for m in registered_methods(installed_only=True) if m.exact]


def _study_params(scene: str, params: dict[str, Any]) -> dict[str, Any]:
    family = get_scene(scene)
    names = {p.name for p in family.params}
    if "refine" not in names:
        raise InputError(f"scene {scene!r} has no 'refine' parameter: converge refines scenes "
                         f"that have one ({', '.join(_refinable())})")
    if "refine" in params:
        raise InputError("converge sets 'refine' itself: give --levels instead of --set refine=")
    start = {k: v for k, v in family.convergence_start.items() if k in names}
    start.update(params)
    return start


def _refinable() -> list[str]:
    return sorted(name for name, f in SCENES.items() if any(p.name == "refine" for p in f.params))


def level_task(scene: str, level: int, params: dict[str, Any], method: str, tol: float) -> Task:
    """The runner's task of one method at one level: no exact answer, the errors against theory."""
    return Task("convergence", scene, level,
                {"kind": "scene", "scene": scene, "params": {**params, "refine": level}}, method,
                tol=tol, reference={"kind": "none"}, measure=("reference", "estimate", "lam", "mesh"))


def level_results(rows: list[Row], metrics: tuple[str, ...]) -> list[LevelResult]:
    """The rows of one level as results: errors of converged runs, λ against the first converged."""
    known = next((r for r in rows if "h" in r), {})
    first: np.ndarray | None = None
    out = []
    for row in rows:
        status = "skipped" if row["status"] == "refused" else row["status"]
        converged = status == "converged"
        found = {**row.get("reference", {}), **row.get("estimate", {})}
        errors = {k: float("nan") if v is None else float(v)
                  for k, v in found.items() if k in metrics} if converged else {}
        lam = np.array(row.get("lam", []), dtype=float)
        if first is None and converged:
            first = lam
        lam_rel = float(np.max(np.abs(lam - first)) / np.max(np.abs(first))) \
            if first is not None and converged else float("nan")
        out.append(LevelResult(int(row["value"]), row["method"], status,
                               int(known.get("dofs", 0)), int(known.get("candidates", 0)),
                               float(known.get("h", float("nan"))), errors, lam_rel,
                               float(known.get("assemble_s", float("nan"))),
                               0.0 if status == "skipped" else float(row.get("time_s", float("nan")))))
    return out


def check_study(scene: str, levels: int, params: dict[str, Any] | None = None,
                methods: list[str] | None = None, fit_from: int = 0) -> tuple[dict[str, Any], Any]:
    """A convergence study's input checked before any run: ``(level-0 parameters, reference)``.

    InputError for levels outside 0..6, a scene without ``refine`` or a
    reference, an unknown method, ``fit_from`` beyond the levels, or a finest
    level too big for this machine (:func:`signorini.scenes.size.check_size`).
    """
    if not isinstance(levels, int) or isinstance(levels, bool) or not 0 <= levels <= 6:
        raise InputError(f"--levels {levels!r} must be an integer in 0..6 (each level quadruples the dofs)")
    base = _study_params(scene, dict(params or {}))
    reference = REFERENCES.get(scene_reference(scene))
    if reference is None or not reference.convergence:
        raise InputError(f"scene {scene!r} has no analytic reference to converge to")
    for name in methods or ():
        get_method(name)  # an unknown method is refused before any level is solved
    if isinstance(fit_from, bool) or not isinstance(fit_from, int) or not 0 <= fit_from <= max(levels - 1, 0):
        raise InputError(f"--fit-from {fit_from!r} must be a level in 0..{max(levels - 1, 0)}: a rate "
                         f"is fitted over at least two of the levels 0..{levels}")
    family = get_scene(scene)
    try:
        finest = family.parse({**base, "refine": levels})
    except InputError as exc:
        raise InputError(f"--levels {levels} asks for refine={levels} at the finest level: {exc}") from None
    check_size(scene, finest)
    return base, reference


def run_study(scene: str, levels: int, params: dict[str, Any] | None = None,
              methods: list[str] | None = None, tol: float = 1e-10, fit_from: int = 0,
              progress: Callable[[str], None] | None = None, *, isolate: bool | None = None,
              time_limit: float = TIME_LIMIT) -> ConvergenceStudy:
    """Solve ``scene`` at refinement levels 0..``levels`` with every exact method and fit rates.

    ``params`` override the scene's parameters (and the coarse start in
    :data:`COARSE_START`); ``fit_from`` leaves the first levels out of the
    rate fits (pre-asymptotic). Methods that refuse a level (dense ones on
    large meshes) are recorded as ``skipped``. The runs go through the study
    runner: one worker process (``isolate``; by default unless the family was
    registered in this process only), each run within ``time_limit`` seconds.
    """
    say = progress or (lambda message: None)
    base, reference = check_study(scene, levels, params, methods, fit_from)
    chosen = methods or exact_methods()
    tasks = [level_task(scene, level, base, name, tol) for level in range(levels + 1)
             for name in chosen]

    def report(index: int, count: int, task: Task, row: Row) -> None:
        if row["status"] == "refused":
            log.info("level %d: %s skipped (%s)", task.value, task.method, row.get("message"))
            return
        errors = {k: v for k, v in row.get("reference", {}).items() if k in reference.convergence} \
            if row["status"] == "converged" else {}
        say(f"level {task.value}: {row.get('dofs')} dofs, h = {row.get('h', float('nan')):.3g}, "
            f"{task.method} {row['status']} in {row.get('time_s', float('nan')):.2f} s: "
            + ", ".join(f"{k} {v:.3e}" for k, v in errors.items()))

    if isolate is None:  # a family registered in this process only is built here
        isolate = portable_scene(scene)
    done = run_tasks(tasks, isolate=isolate, time_limit=time_limit, progress=report)
    rows: list[LevelResult] = []
    for level in range(levels + 1):
        rows += level_results([r for t, r in zip(tasks, done) if t.value == level],
                              reference.convergence + ESTIMATES)
    study = ConvergenceStudy(scene, {**base, "levels": levels}, reference.convergence + ESTIMATES, rows,
                             fit_from=fit_from)
    for name in study.methods:
        study.rates[name] = {metric: fitted_rate(*study.series(name, metric, fit_from)[::2])
                             for metric in study.metrics}
    return study


# --- uniform against graded ------------------------------------------------------------------


def dofs_for_error(dofs: np.ndarray, error: np.ndarray, target: float) -> tuple[float, str]:
    """Dofs at which ``error`` reaches ``target``: log–log interpolation, else extrapolation.

    Returns ``(dofs, how)`` with ``how`` "interpolated" when two measured
    levels bracket the target, "extrapolated" when the fitted power law
    ``err ∝ dofs^s`` of the series had to be continued, nan when the error
    does not decrease.
    """
    dofs, error = np.asarray(dofs, float), np.asarray(error, float)
    order = np.argsort(dofs)
    dofs, error = dofs[order], error[order]
    for i in range(len(dofs) - 1):
        if error[i] >= target >= error[i + 1]:
            t = (np.log(target) - np.log(error[i])) / (np.log(error[i + 1]) - np.log(error[i]))
            return float(np.exp(np.log(dofs[i]) + t * (np.log(dofs[i + 1]) - np.log(dofs[i])))), \
                "interpolated"
    if len(dofs) >= 2:
        slope, intercept = np.polyfit(np.log(dofs), np.log(error), 1)
        if slope < 0:
            return float(np.exp((np.log(target) - intercept) / slope)), "extrapolated"
    return float("nan"), "not reached"


@dataclass
class GradingComparison:
    """Graded default against uniform meshes on one error metric."""

    scene: str
    metric: str
    target: float
    graded: ConvergenceStudy
    uniform: ConvergenceStudy
    graded_dofs: float
    graded_how: str
    uniform_dofs: float
    uniform_how: str
    uniform_rate_per_dof: float

    @property
    def saving(self) -> float:
        """How many times fewer dofs the graded mesh needs for the target error."""
        return self.uniform_dofs / self.graded_dofs

    def as_dict(self) -> dict[str, Any]:
        return {"scene": self.scene, "metric": self.metric, "target": self.target,
                "graded_dofs": self.graded_dofs, "graded_how": self.graded_how,
                "uniform_dofs": self.uniform_dofs, "uniform_how": self.uniform_how,
                "uniform_rate_per_dof": self.uniform_rate_per_dof, "saving": self.saving,
                "graded": self.graded.as_dict(), "uniform": self.uniform.as_dict()}


def grading_comparison(scene: str, graded: ConvergenceStudy, uniform_levels: int,
                       params: dict[str, Any] | None = None, metric: str = "p0_rel",
                       target: float = 0.005, uniform_n_contact: int = 4,
                       progress: Callable[[str], None] | None = None) -> GradingComparison:
    """Compare ``graded`` with uniform meshes (``grading`` → 0) at equal dofs.

    The uniform series starts at ``uniform_n_contact`` elements across the
    contact and is refined ``uniform_levels`` times with ``pdas`` only.
    """
    uniform_params = {**(params or {}), "n_contact": uniform_n_contact,
                      "grading": UNIFORM_GRADING}
    uniform = run_study(scene, uniform_levels, uniform_params, methods=["pdas"], progress=progress)
    _, g_dofs, g_err = graded.series("pdas", metric)
    _, u_dofs, u_err = uniform.series("pdas", metric)
    if g_dofs.size == 0 or u_dofs.size == 0:
        raise InputError(f"no converged pdas levels to compare on {metric}")
    graded_dofs, graded_how = dofs_for_error(g_dofs, g_err, target)
    uniform_dofs, uniform_how = dofs_for_error(u_dofs, u_err, target)
    slope = float(np.polyfit(np.log(u_dofs), np.log(u_err), 1)[0]) if u_dofs.size >= 2 else float("nan")
    return GradingComparison(scene, metric, target, graded, uniform, graded_dofs, graded_how,
                             uniform_dofs, uniform_how, slope)
