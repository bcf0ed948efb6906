"""Effectivity of the a posteriori estimate (signorini.fem.estimate) on the Hertz scenes, and
what adaptive refinement (signorini.scenes.adapt) reaches against uniform and hand-graded meshes.

    .venv/bin/python tools/estimate.py [effectivity] [adaptive] [punch] [start]  # adaptive 2.4 min;
                                                                          # writes docs/estimate/runs.json
    .venv/bin/python tools/estimate.py figure                     # adaptive.png from the JSON

Effectivity: for each scene and base mesh, a task of the studies' runner per level
``refine`` = 0, 1, ... (uniform refinements of the graded mesh). The true error of
level L is measured against the solution at level L + 2 (and, for a check on the
reference's own error, against the finest one): the runner's ``finer`` measure
(:func:`signorini.studies.measures.energy_error`: the coarse P1 field carried onto the
finer mesh node by node, every new node the midpoint of an old edge,
:mod:`signorini.fem.transfer`, nodes moved onto the arc keeping that average, and
``‖u_ref − u_h‖_E`` summed element by element on the finer mesh). Every solve is
``pdas`` at tol 1e-10 on the scene as signorini.solve builds it (``nested``, exact too,
from refine 2). The adaptive parts drive signorini.scenes.adapt's loop, each step
measured against a reference loop: not single solves, they run here. docs/estimate.md quotes the tables
``tables`` renders from the JSON (tools/readme.py writes them there;
tests/test_readme_numbers.py holds them).
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

import signorini
from signorini.files import atomic_write_text, to_json
from signorini.references.catalogue import reference_of
from signorini.scenes import SCENES as SCENE_FAMILIES
from signorini.scenes.adapt import solve_adaptive
from signorini.studies.runner import run_tasks
from signorini.studies.task import Task

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "estimate" / "runs.json"
SCENES = ("hertz-cylinder", "hertz-sphere")
#: (n_contact, grading, levels): a coarse base with three levels, each scene's default mesh with two
BASES = ((16, 0.2, 3), (None, None, 2))
REFERENCE_STEPS = 2
#: seconds a level's task (its solve and the finer ones it is measured against) may take
TIME_LIMIT = 600.0
#: the adaptive runs: targets (the contact pressure's relative L² error), the dof limit, the
#: reference (the same loop driven further), the ν values, and the meshes held against them
TARGETS = (0.003, 0.001)
MAX_DOFS = 80_000
REFERENCE_TARGET, REFERENCE_DOFS = 0.0002, 250_000
NUS = (0.0, 0.3, 0.45)
CHART_NU = 0.3
UNIFORM_LEVELS = 2
HAND_GRADED = ((40, 0.1), (60, 0.05), (120, 0.05))
FIGURE = ROOT / "docs" / "estimate" / "adaptive.png"


def mesh_params(scene: str, n_contact: int | None = None, grading: float | None = None,
                mesher: str | None = None) -> dict:
    """The mesh measured here: the scene's adaptive start (the relaxed mesh; the budgets and the
    effectivity were measured from it), with the parameters given (not None) in its place."""
    given = {"n_contact": n_contact, "grading": grading, "mesher": mesher}
    return {**SCENE_FAMILIES[scene].adaptive_start, **{k: v for k, v in given.items() if v is not None}}


def solve(scene: str, n_contact: int | None, grading: float | None, refine: int,
          nu: float | None = None, mesher: str | None = None):
    """The scene at ``refine`` on :func:`mesh_params`'s mesh, exactly; and the time."""
    method = "nested" if refine >= 2 else "pdas"
    start = time.perf_counter()
    result = signorini.solve(scene, method=method, tol=1e-10,
                             params={**mesh_params(scene, n_contact, grading, mesher), "refine": refine,
                                     **({} if nu is None else {"nu": nu})})
    seconds = time.perf_counter() - start
    if result.status != "converged":
        raise RuntimeError(f"{scene} refine={refine}: {result.status} ({result.message})")
    return result, seconds


def tasks() -> list[Task]:
    """A task per scene, base mesh and level: solved exactly, estimated, and measured against the
    same scene REFERENCE_STEPS refinements finer and at the finest level (the ``finer`` measure)."""
    out = []
    for scene in SCENES:
        for n_contact, grading, levels in BASES:
            mesh = mesh_params(scene, n_contact, grading)
            finest = levels + REFERENCE_STEPS - 1
            out += [Task(axis="effectivity", case=scene, value=refine,
                         problem={"kind": "scene", "scene": scene, "matched": False,
                                  "params": {**mesh, "refine": refine}},
                         method="nested" if refine >= 2 else "pdas", tol=1e-10,
                         reference={"kind": "none", "finer": {
                             "levels": sorted({refine + REFERENCE_STEPS, finest}),
                             "method": "nested", "tol": 1e-10}},
                         measure=("estimate", "reference", "finer"))
                    for refine in range(levels)]
    return out


def row_of(task: Task, row: dict) -> dict:
    """The study's row from the runner's."""
    if "finer" not in row or any(r["status"] != "converged" for r in row["finer"].values()):
        raise RuntimeError(f"{task.case} {task.problem['params']}: {row['status']} ({row['message']}); "
                           f"finer: {row.get('finer')}")
    refine, found, hertz = task.value, row["estimate"], row["reference"]
    finest = max(task.reference["finer"]["levels"])
    fine, finest_run = row["finer"][str(refine + REFERENCE_STEPS)], row["finer"][str(finest)]
    error = fine["error"]
    mesh = SCENE_FAMILIES[task.case].parse(task.problem["params"])
    return {"scene": task.case, "n_contact": mesh["n_contact"], "grading": mesh["grading"],
            "refine": refine, "dofs": row["dofs"], "estimate": found["eta"],
            "relative": found["estimate"], "recovery": found["eta_recovery"],
            "contact": found["eta_contact"], "energy_norm": found["energy_norm"],
            "error": error, "error_finest": finest_run["error"], "finest": finest,
            "effectivity": found["eta"] / error,
            "effectivity_recovery": found["eta_without_contact"] / error,
            "effectivity_finest": found["eta"] / finest_run["error"],
            "complementarity": fine["complementarity"],
            "p0_err": hertz["p0"] / hertz["p0_ref"] - 1, "a_err": hertz["a"] / hertz["a_ref"] - 1,
            "estimate_s": found["estimate_s"], "solve_s": row["time_s"]}


def run(chosen: list[Task] | None = None) -> list[dict]:
    chosen = tasks() if chosen is None else chosen
    rows = run_tasks(chosen, time_limit=TIME_LIMIT, progress=lambda i, n, t, r: print(
        f"{i}/{n} {t.case} {t.problem['params']}: {r['status']}", file=sys.stderr))
    return [row_of(task, row) for task, row in zip(chosen, rows)]


def _pct(x: float, digits: int = 3) -> str:
    return f"{100 * x:+.{digits}f} %"


def tables(rows: list[dict], adaptive: list[dict] | None = None,
           punch: list[dict] | None = None, start: list[dict] | None = None) -> dict[str, str]:
    """Markdown tables by name: effectivity per level, and η against the Hertz errors."""
    lines = ["| scene | mesh (n_contact, grading) | refine | dofs | η / ‖u_h‖ | ‖e‖ / ‖u_h‖ "
             "| η / ‖e‖ | recovery part alone | η / ‖e‖ against the finest | contact share of η² |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        finer = r["finest"] > r["refine"] + REFERENCE_STEPS
        lines.append(
            f"| {r['scene']} | {r['n_contact']}, {r['grading']:g} | {r['refine']} | {r['dofs']:,} "
            f"| {100 * r['relative']:.2f} % | {100 * r['error'] / r['energy_norm']:.2f} % "
            f"| {r['effectivity']:.3f} | {r['effectivity_recovery']:.3f} "
            + (f"| {r['effectivity_finest']:.3f} (refine {r['finest']}) " if finer else "| — ")
            + f"| {100 * (r['contact'] / r['estimate']) ** 2:.2f} % |")
    out = {"effectivity": "\n".join(lines)}
    lines = ["| scene | mesh | refine | dofs | η / ‖u_h‖ | a | p₀ | 2λ_refᵀg(u_h) / ‖e‖² "
             "| estimate | solve |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(
            f"| {r['scene']} | {r['n_contact']}, {r['grading']:g} | {r['refine']} | {r['dofs']:,} "
            f"| {100 * r['relative']:.2f} % | {_pct(r['a_err'])} | {_pct(r['p0_err'])} "
            f"| {2 * r['complementarity'] / r['error'] ** 2:+.3f} "
            f"| {1e3 * r['estimate_s']:.0f} ms | {r['solve_s']:.2f} s |")
    out["estimate-hertz"] = "\n".join(lines)
    if adaptive:
        out["adaptive"] = adaptive_table(adaptive)
        out["adaptive-summary"] = adaptive_summary(adaptive)
    if punch:
        out["adaptive-punch"] = punch_table(punch)
    if start:
        out["adaptive-start"] = start_table(start)
    return out


#: adaptive runs started from a mesh graded more steeply than the scenes' default (ν = 0.3):
#: (n_contact, grading) of the start
STARTS = ((20, 0.3),)


def run_start() -> list[dict]:
    """The loop started from :data:`STARTS` on both Hertz scenes at ν = 0.3, every step against
    the reference (the default loop driven to REFERENCE_TARGET)."""
    rows = []
    for scene in SCENES:
        steps, _ = adaptive_steps(scene, {"nu": CHART_NU}, REFERENCE_TARGET, REFERENCE_DOFS)
        reference = steps[-1][0]
        for n_contact, grading in STARTS:
            params = {"nu": CHART_NU, "n_contact": n_contact, "grading": grading}
            steps, run = adaptive_steps(scene, params, min(TARGETS), MAX_DOFS)
            for k, (result, seconds) in enumerate(steps):
                rows.append(_row(result, reference, scene=scene, nu=CHART_NU, step=k, seconds=seconds,
                                 mesh=f"adaptive from ({n_contact}, {grading:g})",
                                 reference_dofs=reference.problem.n))
            rows[-1]["reason"] = run.reason
    return rows


#: the columns that end an effectivity table's header, and :func:`effectivity_cells` its rows'
EFFECTIVITY_HEADER = "| pressure estimate | pressure error | effectivity |"


def effectivity_cells(r: dict) -> str:
    return (f"| {100 * r['pressure_estimate']:.3f} % | {100 * r['pressure_error']:.3f} % "
            f"| {r['effectivity']:.2f} |")


def start_table(rows: list[dict]) -> str:
    lines = ["| scene | start (n_contact, grading) | step | dofs " + EFFECTIVITY_HEADER,
             "|---|---|---:|---:|---:|---:|---:|"]
    lines += [f"| {r['scene']} | {r['mesh'].split('from ')[1]} | {r['step']} | {r['dofs']:,} "
              + effectivity_cells(r) for r in rows]
    return "\n".join(lines)


#: the punch (sharp corners: the pressure is singular there, P/(π√(a² − x²)), not square
#: integrable; rounded corners: bounded) driven by each estimate: (label, params, target, on)
PUNCH_RUNS = (("sharp", {}, 0.001, "pressure"), ("sharp", {}, 0.02, "energy"),
              ("rounded, r = 0.2 a", {"corner_radius": 0.2}, 0.001, "pressure"),
              ("rounded, r = 0.2 a", {"corner_radius": 0.2}, 0.02, "energy"))
PUNCH_DOFS = 60_000


def run_punch() -> list[dict]:
    """The adaptive loop on the punch (no build on a given mesh: its model is carried onto each
    refinement), every step's estimates, against the energy and the pressure targets."""
    rows = []
    for label, params, target, on in PUNCH_RUNS:
        start = time.perf_counter()
        result = signorini.solve_adaptive("punch", target, target_on=on, max_dofs=PUNCH_DOFS,
                                 params=params)
        seconds = time.perf_counter() - start
        for s in result.solution.extras["adaptive"]:
            rows.append({"corners": label, "target": target, "on": on, "step": s["step"],
                         "dofs": s["dofs"], "candidates": s["candidates"], "energy": s["estimate"],
                         "pressure": s["pressure_estimate"], "action": s["action"]})
        rows[-1].update(status=result.status, seconds=seconds, reason=result.message.rsplit("; ", 1)[-1])
        print(f"punch {label} {on} {target}: {result.status}, {result.problem.n} dofs", file=sys.stderr)
    return rows


def punch_table(rows: list[dict]) -> str:
    lines = ["| corners | target | steps | dofs: first → last | energy estimate: first → last "
             "| pressure estimate: first → last | candidates widened | how it ended |",
             "|---|---|---:|---|---|---|---:|---|"]
    for key in dict.fromkeys((r["corners"], r["target"], r["on"]) for r in rows):
        run = [r for r in rows if (r["corners"], r["target"], r["on"]) == key]
        solved = [r for r in run if r["action"] != "candidates widened"]
        first, last = solved[0], solved[-1]
        lines.append(
            f"| {key[0]} | {100 * key[1]:g} % ({key[2]}) | {len(run)} "
            f"| {first['dofs']:,} → {last['dofs']:,} "
            f"| {100 * first['energy']:.2f} % → {100 * last['energy']:.2f} % "
            f"| {100 * first['pressure']:.1f} % → {100 * last['pressure']:.1f} % "
            f"| {sum(r['action'] == 'candidates widened' for r in run)} "
            f"| {last['status']}: {last['reason']} ({last['seconds']:.1f} s) |")
    return "\n".join(lines)


def pressure_profile(result) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Arc coordinate, nodal pressure and contact weight of every candidate (problem units)."""
    problem, solution = result.problem, result.solution
    return problem.contact_points[:, 0], solution.lam / problem.weights, problem.weights


def pressure_error(coarse, reference) -> float:
    """‖p_h − p_ref‖ / ‖p_h‖ over the coarse candidates (weighted by their contact weights), the
    reference's nodal pressure interpolated linearly along the arc."""
    x, p, w = pressure_profile(coarse)
    xr, pr, _ = pressure_profile(reference)
    order = np.argsort(xr)
    difference = p - np.interp(x, xr[order], pr[order])
    return float(np.sqrt(np.sum(w * difference ** 2) / np.sum(w * p ** 2)))


class _Step:
    """What :func:`solve_adaptive` hands ``on_step``, shaped like an API result."""

    def __init__(self, problem, solution, found):
        self.problem, self.solution, self.estimate = problem, solution, found


def where_the_error_is(result, reference, a: float) -> dict:
    """Which candidate carries the largest share of the true pressure error², and of the estimate's,
    each at x / a (a: Hertz's, problem units) with the other measure's share at that node."""
    x, p, w = pressure_profile(result)
    xr, pr, _ = pressure_profile(reference)
    order = np.argsort(xr)
    true = w * (p - np.interp(x, xr[order], pr[order])) ** 2
    true, estimate = true / true.sum(), result.estimate.pressure.indicators
    estimate = estimate / estimate.sum()
    worst_true, worst_estimate = int(np.argmax(true)), int(np.argmax(estimate))
    return {"true_top_x": float(x[worst_true] / a), "true_top_share": float(true[worst_true]),
            "estimate_share_at_true_top": float(estimate[worst_true]),
            "estimate_top_x": float(x[worst_estimate] / a),
            "estimate_top_share": float(estimate[worst_estimate]),
            "true_share_at_estimate_top": float(true[worst_estimate])}


def _row(result, reference, **fields) -> dict:
    problem, solution, found = result.problem, result.solution, result.estimate
    hertz = reference_of(problem).compare(problem, solution)
    error = pressure_error(result, reference)
    return {**fields, "dofs": problem.n, "relative": found.relative,
            "pressure_estimate": found.pressure.relative, "pressure_error": error,
            "effectivity": found.pressure.relative / error if error > 0 else float("nan"),
            "pressure_hertz": hertz.pressure_l2_rel,
            "p0_err": hertz.p0 / hertz.p0_ref - 1, "a_err": hertz.a / hertz.a_ref - 1,
            **where_the_error_is(result, reference, hertz.a_ref / problem.scales.length)}


def adaptive_steps(scene: str, params: dict, target: float, max_dofs: int):
    """Every step of one adaptive run (as :class:`_Step`, with the loop's time so far) and its end."""
    steps, start = [], time.perf_counter()

    def step(problem, solution, found):
        if found is None:  # the loop stops on it and says why (run.reason)
            print(f"{scene} {params}: {problem.n} dofs ended {solution.status}", file=sys.stderr)
            return
        steps.append((_Step(problem, solution, found), time.perf_counter() - start))
        print(f"{scene} {params} adaptive: {problem.n} dofs, pressure η "
              f"{100 * found.pressure.relative:.3f} %", file=sys.stderr)

    # pdas's default tolerance 1e-9: at 1e-10 the sphere at ν = 0.45 ends `inaccurate` at 66k dofs
    def solver(problem):
        result = signorini.solve(problem, "pdas", tol=1e-9)
        return result.problem, result.solution

    run = solve_adaptive(scene, params, target, solver, max_dofs=max_dofs, on_step=step)
    return steps, run


def run_adaptive() -> list[dict]:
    """Adaptive runs to the smaller target for every scene and ν, each step against a reference
    (the same loop driven to REFERENCE_TARGET); at ν = 0.3 also uniform and hand-graded meshes."""
    rows = []
    for scene in SCENES:
        for nu in NUS:
            steps, _ = adaptive_steps(scene, {"nu": nu}, REFERENCE_TARGET, REFERENCE_DOFS)
            reference = steps[-1][0]
            steps, run = adaptive_steps(scene, {"nu": nu}, min(TARGETS), MAX_DOFS)
            for k, (result, seconds) in enumerate(steps):
                rows.append(_row(result, reference, scene=scene, nu=nu, mesh="adaptive", step=k,
                                 seconds=seconds, reference_dofs=reference.problem.n))
            rows[-1]["reason"] = run.reason
            if nu != CHART_NU:
                continue
            for refine in range(UNIFORM_LEVELS + 1):
                result, seconds = solve(scene, None, None, refine, nu)
                rows.append(_row(result, reference, scene=scene, nu=nu, seconds=seconds,
                                 mesh=f"uniform, refine {refine}"))
            for n_contact, grading in HAND_GRADED:
                result, seconds = solve(scene, n_contact, grading, 0, nu)
                rows.append(_row(result, reference, scene=scene, nu=nu, seconds=seconds,
                                 mesh=f"graded ({n_contact}, {grading:g})"))
    return rows


def adaptive_table(rows: list[dict]) -> str:
    lines = ["| scene | ν | mesh | dofs | pressure estimate | pressure error | effectivity "
             "| vs Hertz: pressure | a | p₀ | time |",
             "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        label = f"adaptive, step {r['step']}" if r["mesh"] == "adaptive" else r["mesh"]
        lines.append(f"| {r['scene']} | {r['nu']:g} | {label} | {r['dofs']:,} "
                     f"| {100 * r['pressure_estimate']:.3f} % | {100 * r['pressure_error']:.3f} % "
                     f"| {r['effectivity']:.2f} | {100 * r['pressure_hertz']:.3f} % "
                     f"| {_pct(r['a_err'])} | {_pct(r['p0_err'])} | {r['seconds']:.1f} s |")
    return "\n".join(lines)


def adaptive_summary(rows: list[dict]) -> str:
    """Per scene, ν and target: the first adaptive step whose estimate meets it."""
    lines = ["| scene | ν | target | dofs | pressure error | a | p₀ | effectivity over the run |",
             "|---|---:|---:|---:|---:|---:|---:|---|"]
    for scene in SCENES:
        for nu in NUS:
            run = [r for r in rows if r["scene"] == scene and r["nu"] == nu and r["mesh"] == "adaptive"]
            known = [r["effectivity"] for r in run if np.isfinite(r["effectivity"])]
            span = f"{min(known):.2f}–{max(known):.2f}" if known else "—"
            for target in TARGETS:
                met = next((r for r in run if r["pressure_estimate"] <= target), None)
                if met is None:
                    lines.append(f"| {scene} | {nu:g} | {100 * target:g} % | not met within "
                                 f"{MAX_DOFS:,} | | | | {span} |")
                    continue
                lines.append(f"| {scene} | {nu:g} | {100 * target:g} % | {met['dofs']:,} "
                             f"| {100 * met['pressure_error']:.3f} % | {_pct(met['a_err'])} "
                             f"| {_pct(met['p0_err'])} | {span} |")
    return "\n".join(lines)


def adaptive_figure(rows: list[dict], path: Path) -> None:
    """The true pressure error against dofs and against time: adaptive, uniform, hand-graded."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from signorini.files import save_figure

    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5))
    from matplotlib.ticker import NullFormatter

    kinds = (("adaptive", "o-", "adaptive (pressure estimate)"), ("uniform", "s--", "uniform refinement"),
             ("graded", "^", "hand-graded (n_contact, grading)"))
    for row_axes, scene in zip(axes, SCENES):
        chosen = [r for r in rows if r["scene"] == scene and r["nu"] == CHART_NU]
        for kind, style, label in kinds:
            series = sorted((r for r in chosen if r["mesh"].startswith(kind)), key=lambda r: r["dofs"])
            for ax, key in zip(row_axes, ("dofs", "seconds")):
                ax.loglog([r[key] for r in series], [100 * r["pressure_error"] for r in series], style,
                          label=label)
                if kind == "adaptive":
                    ax.loglog([r[key] for r in series], [100 * r["pressure_estimate"] for r in series],
                              "o", mfc="none", color="C0", alpha=0.6, label="its estimate")
        for ax, key in zip(row_axes, ("dofs", "wall time [s] (adaptive: the loop so far)")):
            ax.xaxis.set_minor_formatter(NullFormatter())
            ax.yaxis.set_minor_formatter(NullFormatter())
            ax.set_xlabel(key)
            ax.set_ylabel("contact pressure error [%]")
            ax.set_title(f"{scene}, ν = {CHART_NU:g}", fontsize=9)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, path)


def load(part: str = "rows") -> list[dict]:
    return json.loads(OUT.read_text()).get(part, [])


if __name__ == "__main__":
    parts = sys.argv[1:] or ["effectivity", "adaptive", "punch", "start"]
    record = json.loads(OUT.read_text()) if OUT.exists() else {}
    record.pop("command", None)  # one command per part: each part is re-run on its own
    record.setdefault("commands", {}).update(
        {part: f"python tools/estimate.py {part}" for part in parts if part != "figure"})
    if "effectivity" in parts:
        record["rows"] = run()
    if "adaptive" in parts:
        record["adaptive"] = run_adaptive()
    if "punch" in parts:
        record["punch"] = run_punch()
    if "start" in parts:
        record["start"] = run_start()
    if parts != ["figure"]:
        atomic_write_text(OUT, to_json(record))
        print(f"written: {OUT}", file=sys.stderr)
    if "adaptive" in parts or "figure" in parts:
        adaptive_figure(record["adaptive"], FIGURE)
