"""Mesh-convergence studies: refine a scene k times, measure its errors, fit their rates.

A study solves a scene at levels 0, 1, …, k of uniform refinement (the
scene's ``refine`` parameter: every element split in four, so the element
size h halves and the dofs roughly quadruple) with every installed exact
method, and measures the errors against the scene's analytic reference
(:attr:`signorini.references.catalogue.Reference.convergence`). The rate of a metric is the
slope s of the least-squares line ``log err = s log h + c``
(``np.polyfit(np.log(h), np.log(err), 1)``); h is the median distance between
neighbouring contact candidates (:func:`signorini.studies.problems.candidate_spacing`).
Exact methods solve the same discrete problem, so their errors must
coincide; the study records how far their λ are apart. Every run goes
through the study runner (:mod:`signorini.studies.runner`) with no exact
answer (the reference policy ``none``): the worker rebuilds each level from
its spec, and λ is compared with the first converged method's in this process.

:func:`grading_comparison` sets the graded default against a uniform mesh
(the scene with ``grading`` → 0, i.e. the contact size everywhere) at equal
dofs, and estimates how many dofs each needs for a given error by
interpolating ``log err`` against ``log dofs`` (extrapolating with the fitted
rate when a series does not reach it).
"""

from __future__ import annotations

import logging
from dataclasses import asdict, dataclass, field
from typing import Any, Callable

import numpy as np
from matplotlib.figure import Figure

from signorini.references.analytic import punch_pressure
from signorini.errors import InputError
from signorini.files import atomic_write_text, save_figure, to_json, writable_directory
from signorini.references.pressure import compare_punch, contact_profile
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.references.catalogue import REFERENCES
from signorini.scenes import SCENES, get_scene, portable_scene, scene_reference
from signorini.scenes.registry import FamilyField
from signorini.scenes.size import check_size
from signorini.solvers.registry import get_method
from signorini.solvers.registry import methods as registered_methods
from signorini.studies.runner import Row, Task, run_tasks

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

    def series(self, method: str, metric: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(h, dofs, error)`` of one method's converged levels."""
        rows = [r for r in self.rows if r.method == method and r.status == "converged"
                and np.isfinite(r.errors.get(metric, np.nan))]
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
        study.rates[name] = {}
        for metric in study.metrics:
            h, _, err = study.series(name, metric)
            keep = np.array([r.level >= fit_from for r in rows if r.method == name
                             and r.status == "converged" and np.isfinite(r.errors.get(metric, np.nan))],
                            dtype=bool)
            study.rates[name][metric] = fitted_rate(h[keep], err[keep]) if keep.size else float("nan")
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


# --- figures (each takes ax=None and returns the Axes) ---------------------------------------


def _axes(ax):
    if ax is None:
        ax = Figure(figsize=(6.4, 4.4), layout="constrained").add_subplot()
    return ax


def plot_convergence(study: ConvergenceStudy, ax=None, metrics: tuple[str, ...] | None = None):
    """Errors against h on log–log axes, one line per metric and exact method, rates in the legend."""
    ax = _axes(ax)
    markers = "osd^v"
    for i, metric in enumerate(metrics or study.metrics):
        for j, method in enumerate(study.methods[:1] if metric in ESTIMATES else study.methods):
            h, _, err = study.series(method, metric)
            if h.size == 0:
                continue
            rate = study.rates.get(method, {}).get(metric, float("nan"))
            style = ":" if metric in ESTIMATES else "-" if j == 0 else "--"
            ax.loglog(h, np.abs(err), style, color=f"C{i}", marker=markers[i % len(markers)],
                      ms=5 if j == 0 else 9, mfc="none" if j else None,
                      label=f"{LABELS.get(metric, metric)} ({method}): rate {rate:.2f}")
    ax.set_xlabel("h (spacing of the contact candidates)")
    ax.set_ylabel("relative error" if "edge_over_centre" not in (metrics or study.metrics)
                  else "relative error; edge pressure / (P/πa)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    ax.set_title(f"{study.scene}: convergence under uniform refinement", fontsize=9)
    return ax


def plot_grading(comparison: GradingComparison, ax=None):
    """The error of the graded and the uniform series against dofs, with the target line."""
    ax = _axes(ax)
    for name, study, marker in (("graded", comparison.graded, "o"),
                                ("uniform", comparison.uniform, "s")):
        _, dofs, err = study.series("pdas", comparison.metric)
        ax.loglog(dofs, err, "-", marker=marker, label=name)
    ax.axhline(comparison.target, color="k", lw=0.8, ls=":",
               label=f"{100 * comparison.target:g} % target")
    for dofs, how, color in ((comparison.graded_dofs, comparison.graded_how, "C0"),
                             (comparison.uniform_dofs, comparison.uniform_how, "C1")):
        if np.isfinite(dofs):
            ax.plot([dofs], [comparison.target], "x", color=color, ms=10,
                    label=f"{dofs:,.0f} dofs ({how})")
    ax.set_xlabel("dofs")
    ax.set_ylabel(LABELS.get(comparison.metric, comparison.metric))
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    ax.set_title(f"{comparison.scene}: graded against uniform meshes "
                 f"(grading saves {comparison.saving:,.0f}× the dofs)", fontsize=9)
    return ax


# --- the punch's edge ---------------------------------------------------------------------


def _punch(problem: ContactProblem, solution: ContactSolution):
    """The punch comparison, the pressure profile and the pressure unit ``P/(πa)``."""
    comparison = compare_punch(problem, solution)
    return comparison, contact_profile(problem, solution), comparison.load / (np.pi * comparison.a)


def plot_punch_pressure(problem: ContactProblem, solution: ContactSolution, ax=None):
    """Nodal pressure under the punch against ``P/(π√(a² − x²))``, in units of ``P/(πa)``."""
    ax = _axes(ax)
    comparison, profile, scale = _punch(problem, solution)
    a, P = comparison.a, comparison.load
    x, p = np.abs(profile.x), profile.pressure
    order = np.argsort(x)
    grid = np.linspace(0.0, a * (1 - 1e-4), 2000)
    ax.plot(grid / a, punch_pressure(grid, a, P) / scale, "k-", lw=1.2, label="P / (π√(a² − x²))")
    ax.plot(x[order] / a, p[order] / scale, "o", ms=3, mfc="none", label=f"{solution.method}")
    ax.axvspan(0, comparison.inner, color="0.9", zorder=0, label=f"compared (|x| ≤ {comparison.inner:g}a)")
    ax.set_xlabel("x / a")
    ax.set_ylabel("p / (P / πa)")
    ax.set_ylim(0, max(4.0, float(np.max(p) / scale) * 1.05))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return ax


def plot_punch_edge(problem: ContactProblem, solution: ContactSolution, ax=None):
    """Pressure against the distance ``a − |x|`` to the edge (log–log): slope −½ is the singularity."""
    ax = _axes(ax)
    comparison, profile, scale = _punch(problem, solution)
    a, P = comparison.a, comparison.load
    distance = a - np.abs(profile.x)
    under = distance >= -1e-12 * a
    grid = np.geomspace(1e-4 * a, a, 400)
    ax.loglog(grid / a, punch_pressure(a - grid, a, P) / scale, "k-", lw=1.2, label="P / (π√(a² − x²))")
    positive = under & (distance > 0)
    ax.loglog(distance[positive] / a, profile.pressure[positive] / scale, "o", ms=3, mfc="none",
              label=f"{solution.method}, h = {comparison.edge_h / a:.2g} a")
    edge = under & (distance <= 1e-12 * a)
    if np.any(edge):
        ax.axhline(float(profile.pressure[edge][0]) / scale, color="C3", lw=0.8, ls="--",
                   label="edge node (x = a)")
    ax.set_xlabel("(a − |x|) / a")
    ax.set_ylabel("p / (P / πa)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    return ax


# --- writing a study --------------------------------------------------------------------------


def study_table(study: ConvergenceStudy) -> list[str]:
    """Markdown table of a study: one row per level and method."""
    metrics = list(study.metrics)
    lines = ["| level | method | status | dofs | candidates | h | " +
             " | ".join(LABELS.get(m, m) for m in metrics) + " | λ vs first | solve [s] |",
             "|---:|---|---|---:|---:|---:|" + "---:|" * len(metrics) + "---:|---:|"]
    for r in study.rows:
        values = " | ".join(f"{r.errors[m]:.3e}" if m in r.errors else "–" for m in metrics)
        lam = f"{r.lam_rel_vs_first:.1e}" if np.isfinite(r.lam_rel_vs_first) else "–"
        lines.append(f"| {r.level} | {r.method} | {r.status} | {r.dofs} | {r.candidates} | "
                     f"{r.h:.3g} | {values} | {lam} | {r.solve_s:.2f} |")
    lines += ["", "Fitted rates (slope of log error against log h"
              + (f", levels ≥ {study.fit_from}" if study.fit_from else "") + "):", "",
              "| method | " + " | ".join(LABELS.get(m, m) for m in metrics) + " |",
              "|---|" + "---:|" * len(metrics)]
    for method, rates in study.rates.items():
        lines.append(f"| {method} | " + " | ".join(f"{rates.get(m, float('nan')):.2f}" for m in metrics)
                     + " |")
    return lines


def write_study(study: ConvergenceStudy, out, command: str,
                comparison: GradingComparison | None = None) -> dict[str, Any]:
    """Write ``convergence-<scene>.md``, ``.json`` and ``.png`` (and the grading figure) to ``out``."""
    directory = writable_directory(out)
    stem = f"convergence-{study.scene}"
    paths = {}
    ax = plot_convergence(study)
    save_figure(ax.figure, directory / f"{stem}.png")
    paths["figure"] = directory / f"{stem}.png"
    md = [f"# Convergence: {study.scene}", "", f"Command: `{command}`  ",
          "Parameters: " + ", ".join(f"{k}={v}" for k, v in study.params.items()), "",
          f"Largest λ difference between exact methods: {study.max_disagreement():.1e}", ""]
    md += study_table(study)
    md += ["", f"![convergence]({stem}.png)"]
    payload: dict[str, Any] = {"command": command, "study": study.as_dict()}
    if comparison is not None:
        ax = plot_grading(comparison)
        save_figure(ax.figure, directory / f"grading-{study.scene}.png")
        paths["grading"] = directory / f"grading-{study.scene}.png"
        md += ["", "## Graded against uniform meshes", "",
               f"{LABELS.get(comparison.metric, comparison.metric)} of {100 * comparison.target:g} %: "
               f"graded {comparison.graded_dofs:,.0f} dofs ({comparison.graded_how}), uniform "
               f"{comparison.uniform_dofs:,.0f} dofs ({comparison.uniform_how}; uniform error ∝ "
               f"dofs^{comparison.uniform_rate_per_dof:.2f}): grading saves "
               f"{comparison.saving:,.0f}× the dofs.", ""]
        md += study_table(comparison.uniform)
        md += ["", f"![grading](grading-{study.scene}.png)"]
        payload["grading"] = {k: v for k, v in comparison.as_dict().items()
                              if k not in ("graded", "uniform")}
        payload["uniform"] = comparison.uniform.as_dict()
    atomic_write_text(directory / f"{stem}.md", "\n".join(md) + "\n")
    atomic_write_text(directory / f"{stem}.json", to_json(payload))
    paths["markdown"] = directory / f"{stem}.md"
    paths["json"] = directory / f"{stem}.json"
    return paths
