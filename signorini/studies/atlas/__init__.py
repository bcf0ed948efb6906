"""The stability atlas: where each method fails, and whether the package says so.

Each **axis** sweeps one thing — Uzawa's step, the mesh, the tolerance, the
units, Poisson's ratio, a singular K, degenerate contact, ill-posed input —
and runs every installed method at each point. Every **run** records

- the method's own word (``claimed_status``: what it said before the package
  judged it) and the package's status (``status``, from
  :func:`signorini.solvers.registry.solve`);
- the independent certificate :func:`signorini.kkt.certificate` and whether
  its worst relative residual is within the accepted tolerance ``τ``
  (``ACCEPT_FACTOR · tol``, or ``DEFAULT_ACCEPT`` without a tolerance);
- the distance from a trusted exact answer ``(u*, λ*)`` (PDAS at 1e-9 on the
  non-dimensionalised problem, or the analytic patch solution):
  ``‖λ − λ*‖∞ / max(‖λ*‖∞, 1e-5 ‖f‖∞)`` and the number of misclassified
  contact nodes (weakly active nodes left out, :func:`signorini.kkt.compare`,
  plus nodes with zero force that penetrate, which that comparison misses);
- the Hertz errors of a and p₀ where the scene is Hertz's cylinder.

An answer **agrees** with the exact one when no node is misclassified and
the force error is at most ``min(AGREE_FACTOR · τ, AGREE_CAP)`` (the
validation suite's ratio, λ within 1e-6 at a tolerance of 1e-9, capped). A
method's own claim of success is **correct** when its answer passes the
certificate and agrees; the package's status is **right** when it says
``converged`` only for answers that agree, grants it whenever the claim was
correct, calls no solvable problem ``infeasible``, and never raises on a
problem that was built.

Runs happen in a worker process with a time limit (as in
:mod:`signorini.studies.bench`): a backend that hangs or crashes costs one row, the
worker is restarted, and the atlas goes on.
"""

from __future__ import annotations

import csv
import io
import json
import logging
import math
import os
import select
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable, Sequence

import numpy as np
import scipy.sparse as sp

from signorini.diagnose import diagnose, regularise
from signorini.errors import InputError
from signorini.problem import ContactProblem, ContactSolution
from signorini.studies.problems import ILL_POSED_CASES, REFERENCE_TOL, build_spec, ill_posed_problem
from signorini.studies.runner import (AGREE_CAP, AGREE_FACTOR, ATLAS_TOL, BUILD_ONLY,
                                      DEFAULT_TIME_LIMIT, EXTRA_STATUSES, ITERATION_CAPS,
                                      NEAR_FACTOR, NUMERIC, Task, run_task, run_tasks)

log = logging.getLogger(__name__)

#: methods of a --quick atlas
QUICK_METHODS = ("pdas", "uzawa", "qp-osqp", "qp-clarabel")

COLUMNS = ("axis", "case", "value", "scene", "dofs", "candidates", "method", "tol", "options",
           "expect", "status", "claimed_status", "wrapper", "iterations", "time_s", "kkt_worst",
           "kkt_name", "cert_ok", "lam_rel", "u_rel", "misclassified", "weak",
           "misclassified_strict", "weak_penetrating", "exact_ok", "near_exact", "claim_correct",
           "wrapper_right", "conservative", "outcome", "a_rel", "p0_rel", "pressure_l2_rel",
           "ref_a_rel", "ref_p0_rel", "ref_pressure_l2_rel", "rho_over_bound", "lambda_max",
           "bound_at_solution", "patch_lam_rel", "diagnosis", "message", "problem")


# --- problems, references and one run ------------------------------------------------------------


# --- the axes ------------------------------------------------------------------------------------


def atlas_methods(quick: bool = False) -> list[str]:
    """Installed methods, exact ones first; a quick atlas takes :data:`QUICK_METHODS`."""
    from signorini.solvers.registry import methods

    order = {"active set": 0, "dual": 1, "qp": 2, "cvxpy": 3}
    found = sorted((m for m in methods(installed_only=True) if m.family != "user"),
                   key=lambda m: (order.get(m.family, 4), m.name))
    names = [m.name for m in found]
    return [n for n in names if n in QUICK_METHODS] if quick else names


def _scene(scene: str, nondimensionalise: bool = True, **params: Any) -> dict[str, Any]:
    return {"kind": "scene", "scene": scene, "params": params, "nondimensionalise": nondimensionalise}


def _capped(method: str, tol: float | None) -> int | None:
    return ITERATION_CAPS.get(method) if tol is not None else None


def _every_method(axis: str, case: str, value: Any, problem: dict[str, Any], methods: list[str],
                  **extra: Any) -> list[Task]:
    tol = extra.pop("tol", ATLAS_TOL)
    return [Task(axis, case, value, problem, method, tol=tol, max_iter=_capped(method, tol), **extra)
            for method in methods]


# axis 1: Uzawa's step
STEP_FRACTIONS = (0.05, 0.1, 0.25, 0.5, 0.75, 0.9, 0.95, 0.99, 1.01, 1.05, 1.1, 1.15, 1.2, 1.25,
                  1.5, 2.0, 2.5)
STEP_SCENES = {"hertz-cylinder": {"n_contact": 16, "grading": 0.4}, "block": {"nx": 8, "ny": 8}}
QUICK_STEP_SCENES = {"hertz-cylinder": {"n_contact": 8, "grading": 0.5}, "block": {"nx": 4, "ny": 4}}
STEP_CAPS = {"uzawa": 60_000, "uzawa-nesterov": 20_000}


def _tasks_step(quick: bool, methods: list[str]) -> list[Task]:
    fractions = (0.5, 0.95, 1.25) if quick else STEP_FRACTIONS
    out = []
    for scene, params in (QUICK_STEP_SCENES if quick else STEP_SCENES).items():
        for method, cap in STEP_CAPS.items():
            if method in methods:
                out += [Task("uzawa-step", scene, fraction, _scene(scene, **params), method,
                             options={"step_fraction": fraction}, max_iter=cap, measure=("bound",))
                        for fraction in fractions]
    return out


# axis 2: mesh refinement
MESH_BASE = {"n_contact": 8, "grading": 0.5}
MESH_LEVELS = (0, 1, 2, 3)


def _tasks_mesh(quick: bool, methods: list[str]) -> list[Task]:
    out = []
    for level in (MESH_LEVELS[:2] if quick else MESH_LEVELS):
        out += _every_method("mesh", f"refine {level}", level,
                             _scene("hertz-cylinder", **MESH_BASE, refine=level), methods)
    return out


# axis 3: tolerance
TOLERANCES = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
TOLERANCE_SCENE = {"n_contact": 24, "grading": 0.35}
QUICK_TOLERANCE_SCENE = {"n_contact": 8, "grading": 0.5}
#: backends without a tolerance to set: run once, at their own settings
NO_TOLERANCE = ("qp-quadprog",)


def _tasks_tolerance(quick: bool, methods: list[str]) -> list[Task]:
    problem = _scene("hertz-cylinder", **(QUICK_TOLERANCE_SCENE if quick else TOLERANCE_SCENE))
    tolerances = (1e-3, 1e-8, None) if quick else TOLERANCES + (None,)
    out = []
    for method in methods:
        if not (method.startswith("qp-") or method == "cvxpy"):
            continue
        for tol in ((None,) if method in NO_TOLERANCE else tolerances):
            out.append(Task("tolerance", "default" if tol is None else f"{tol:.0e}",
                            "default" if tol is None else tol, problem, method, tol=tol,
                            max_iter=_capped(method, tol)))
    return out


# axis 4: units and scaling
UNIT_SYSTEMS = (("E=1, R=1", 1.0, 1.0), ("E=1, R=0.01", 1.0, 0.01),
                ("MPa, mm: E=2.1e5, R=10", 2.1e5, 10.0), ("Pa, m: E=2.1e11, R=0.01", 2.1e11, 0.01),
                ("Pa, mm: E=2.1e11, R=10", 2.1e11, 10.0), ("E=2.1e11, R=1", 2.1e11, 1.0))
UNITS_MESH = {"n_contact": 16, "grading": 0.4}


def _tasks_units(quick: bool, methods: list[str]) -> list[Task]:
    systems = UNIT_SYSTEMS[2:4] if quick else UNIT_SYSTEMS
    mesh = QUICK_TOLERANCE_SCENE if quick else UNITS_MESH
    out = []
    for label, E, R in systems:
        scaled = _scene("hertz-cylinder", **mesh, E=E, R=R)
        for nondimensionalise in (True, False):
            problem = _scene("hertz-cylinder", nondimensionalise, **mesh, E=E, R=R)
            case = f"{label}, {'scaled' if nondimensionalise else 'raw'}"
            out += _every_method("units", case, label, problem, methods,
                                 reference={"kind": "pdas", "problem": scaled})
    return out


# axis 5: near-incompressibility
POISSON = (0.3, 0.4, 0.45, 0.49, 0.499, 0.4999)
POISSON_MESH = {"n_contact": 16, "grading": 0.4}


def _tasks_poisson(quick: bool, methods: list[str]) -> list[Task]:
    ratios = (0.3, 0.4999) if quick else POISSON
    mesh = QUICK_TOLERANCE_SCENE if quick else POISSON_MESH
    out = []
    for nu in ratios:
        problem = _scene("hertz-cylinder", **mesh, nu=nu)
        for task in _every_method("poisson", "mesh A", nu, problem, methods):
            out.append(Task(**{**task.as_dict(), "measure": ("profile",)}) if task.method == "pdas"
                       else task)
    for level, name in ((1, "mesh B"), (2, "mesh C"))[: 1 if quick else 2]:
        out += [Task("poisson", name, nu, _scene("hertz-cylinder", **mesh, nu=nu, refine=level),
                     "pdas", measure=("profile",)) for nu in ratios]
    return out


# axis 6: a body held only by contact
FORCE_BLOCK = {"nx": 8, "ny": 8}
REGULARISATION = 1e-8
EPSILONS = (1e-14, 1e-12, 1e-10, 1e-8, 1e-6, 1e-4, 1e-2)


def _force_spec(params: dict[str, Any], epsilon: float = 0.0) -> dict[str, Any]:
    return {"kind": "force-controlled", "params": params, "pressure": 0.01,
            "regularisation": epsilon}


def _tasks_force(quick: bool, methods: list[str]) -> list[Task]:
    params = {"nx": 4, "ny": 4} if quick else FORCE_BLOCK
    exact = {"kind": "force-controlled-exact"}
    out = _every_method("force-control", "singular K", 0.0, _force_spec(params), methods,
                        reference=exact, measure=("diagnosis", "patch"))
    out += _every_method("force-control", f"regularised ε={REGULARISATION:g}", REGULARISATION,
                         _force_spec(params, REGULARISATION), methods, measure=("patch",))
    for epsilon in ((1e-8, 1e-2) if quick else EPSILONS):
        for method in ("pdas", "qp-clarabel"):
            if method in methods:
                out.append(Task("force-control", f"ε={epsilon:g}", epsilon,
                                _force_spec(params, epsilon), method, measure=("patch",)))
    return out


# axis 7: degenerate contact
TOUCHING = (0.25, 0.5)


def _tasks_degenerate(quick: bool, methods: list[str]) -> list[Task]:
    params = {"nx": 4, "ny": 4} if quick else {"nx": 8, "ny": 8}
    out = []
    for touching in TOUCHING[:1] if quick else TOUCHING:
        out += _every_method("degenerate", f"touching={touching:g}", touching,
                             _scene("block", **params, touching=touching), methods)
    return out


# axis 8: infeasible and ill-posed input
ILL_POSED_EXPECT = {"penetrated": "refuse", "no-candidates": "refuse", "zero-weight": "refuse",
                    "duplicate": "solve", "never-touches": "solve"}


def _tasks_ill_posed(quick: bool, methods: list[str]) -> list[Task]:
    params = {"nx": 4, "ny": 4}
    out = []
    for case, expect in ILL_POSED_EXPECT.items():
        spec = {"kind": "ill-posed", "case": case, "params": params}
        flag = "solve" if case == "never-touches" else "refuse"  # the build row: flagged or clean
        out.append(Task("ill-posed", case, case, spec, BUILD_ONLY, expect=flag,
                        measure=("diagnosis",)))
        if case == "duplicate":  # λ is not unique: compare u with that of the block listed once
            reference = {"kind": "pdas", "problem": _scene("block", **params),
                         "displacement_only": True}
            out += _every_method("ill-posed", case, case, spec, methods, expect=expect,
                                 answer="displacement", reference=reference)
        elif case in ("penetrated", "never-touches"):
            out += _every_method("ill-posed", case, case, spec, methods, expect=expect)
    return out


@dataclass(frozen=True)
class Axis:
    """One sweep of the atlas: its tasks, what it asks and how it is reported."""

    number: int
    name: str
    title: str
    question: str
    tasks: Callable[[bool, list[str]], list[Task]]


AXES: tuple[Axis, ...] = (
    Axis(1, "uzawa-step", "Uzawa's step ρ",
         "Uzawa converges iff 0 < ρ < 2/λ_max(W): what happens on either side of the bound, and "
         "does the package name a divergence or a two-step cycle?", _tasks_step),
    Axis(2, "mesh", "Mesh refinement",
         "How do iterations and time grow as h halves, and does PDAS stay mesh-independent?",
         _tasks_mesh),
    Axis(3, "tolerance", "Solver tolerance",
         "At which tolerance does each QP backend find the right contact, and where is its own "
         "'solved' dishonest?", _tasks_tolerance),
    Axis(4, "units", "Units and scaling",
         "What do raw units (E up to 2.1e11, lengths in m or mm) do to each method, with and "
         "without the package's non-dimensionalisation?", _tasks_units),
    Axis(5, "poisson", "Near-incompressibility",
         "How does P1 locking show in the pressure as ν → 0.5, and do the solvers cope?",
         _tasks_poisson),
    Axis(6, "force-control", "A body held only by contact",
         "K is singular under force control: which methods still work, and what does a small "
         "regularisation cost?", _tasks_force),
    Axis(7, "degenerate", "Degenerate contact",
         "Nodes that touch with zero force: does the comparison classify them and stay quiet?",
         _tasks_degenerate),
    Axis(8, "ill-posed", "Infeasible and ill-posed input",
         "Does every infeasible or ill-posed input end in a clear error or status?",
         _tasks_ill_posed),
)


def select_axes(names: Iterable[str] | None) -> tuple[Axis, ...]:
    """The axes named (by number or name) in ``names``; all when empty."""
    names = list(names or [])
    if not names:
        return AXES
    by_key = {str(a.number): a for a in AXES} | {a.name: a for a in AXES}
    chosen = []
    for name in names:
        if name not in by_key:
            raise InputError(f"--axis {name!r} is not an axis: choose a number 1-{len(AXES)} or one "
                             f"of {', '.join(a.name for a in AXES)}")
        if by_key[name] not in chosen:
            chosen.append(by_key[name])
    return tuple(sorted(chosen, key=lambda a: a.number))


@dataclass
class AtlasResult:
    """Every row of an atlas run, the axes it covered and how long it took."""

    rows: list[dict[str, Any]]
    axes: tuple[Axis, ...]
    elapsed_s: float
    axis_seconds: dict[str, float]
    quick: bool = False


def run_atlas(axes: Sequence[Axis] = AXES, *, quick: bool = False, isolate: bool = True,
              time_limit: float = DEFAULT_TIME_LIMIT, methods: Sequence[str] | None = None,
              progress: Callable[[Axis, int, int, Task, dict[str, Any]], None] | None = None
              ) -> AtlasResult:
    """Run the tasks of ``axes`` with every installed method (or ``methods``).

    Parameters
    ----------
    axes : the axes to run (:data:`AXES` by default).
    quick : tiny meshes, few points and :data:`QUICK_METHODS` (a smoke test of the machinery).
    isolate : run each task in a worker process with ``time_limit`` seconds (default), or here.
    time_limit : seconds a task may take before its worker is stopped.
    methods : the methods to run (default: :func:`atlas_methods`).
    progress : called after each task with ``(axis, index, total, task, row)``.
    """
    if not (isinstance(time_limit, (int, float)) and math.isfinite(time_limit) and time_limit > 0):
        raise InputError(f"--time-limit {time_limit!r} must be a positive number of seconds")
    names = list(methods) if methods is not None else atlas_methods(quick)
    start = time.perf_counter()
    rows: list[dict[str, Any]] = []
    seconds: dict[str, float] = {}
    for axis in axes:
        tasks = axis.tasks(quick, names)
        began = time.perf_counter()
        report = None if progress is None else (
            lambda i, n, task, row, axis=axis: progress(axis, i, n, task, row))
        rows += run_tasks(tasks, isolate=isolate, time_limit=time_limit, progress=report)
        seconds[axis.name] = time.perf_counter() - began
        log.info("axis %d (%s): %d runs in %.1f s", axis.number, axis.name, len(tasks),
                 seconds[axis.name])
    return AtlasResult(rows, tuple(axes), time.perf_counter() - start, seconds, quick)


# --- summaries -----------------------------------------------------------------------------------


def _method_rows(rows: Iterable[dict[str, Any]]) -> list[dict[str, Any]]:
    return [r for r in rows if r.get("method") != BUILD_ONLY]


def method_summary(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per method: runs, claims of success, how many were correct, and the package's record.

    ``correct_rate`` is the fraction of the method's own claims of success
    that were true (NaN without claims); ``wrapper_rate`` the fraction of its
    runs where the package's status was right.
    """
    out = []
    runs = _method_rows(rows)
    for method in dict.fromkeys(r["method"] for r in runs):
        mine = [r for r in runs if r["method"] == method]
        claims = [r for r in mine if r.get("claimed_status") == "converged"]
        correct = sum(bool(r.get("claim_correct")) for r in claims)
        wrapper = sum(bool(r.get("wrapper_right")) for r in mine)
        statuses = {}
        for r in mine:
            statuses[r["status"]] = statuses.get(r["status"], 0) + 1
        out.append({"method": method, "runs": len(mine), "claims": len(claims),
                    "claims_correct": correct,
                    "correct_rate": correct / len(claims) if claims else float("nan"),
                    "right": sum(r.get("outcome") == "right" for r in mine),
                    "conservative": sum(bool(r.get("conservative")) for r in mine),
                    "wrapper_right": wrapper, "wrapper_rate": wrapper / len(mine),
                    "statuses": statuses})
    return out


def wrapper_record(rows: list[dict[str, Any]]) -> tuple[int, int, list[dict[str, Any]]]:
    """``(right, runs, faults)``: how often the package's status was right, and the rows where not."""
    runs = _method_rows(rows)
    faults = [r for r in runs if not r.get("wrapper_right")]
    return len(runs) - len(faults), len(runs), faults


def _applicable(axis: str, row: dict[str, Any]) -> bool:
    """Runs that count for the method × axis verdict (inside Uzawa's bound; not refused)."""
    if row.get("status") == "refused" or row.get("method") == BUILD_ONLY:
        return False
    if axis == "uzawa-step":
        return row["value"] <= (0.5 if row["method"] == "uzawa-nesterov" else 1.0)
    if axis == "force-control":
        return not str(row["case"]).startswith("ε=")
    return True


def verdicts(rows: list[dict[str, Any]]) -> dict[tuple[str, str], str]:
    """``(method, axis) → "works n/n" | "degrades k/n" | "fails 0/n"``: right runs among those that count."""
    out = {}
    for r in rows:
        key = (r["method"], r["axis"])
        if key in out or not _applicable(r["axis"], r):
            continue
        mine = [s for s in rows if (s["method"], s["axis"]) == key and _applicable(s["axis"], s)]
        right = sum(s.get("outcome") == "right" for s in mine)
        word = "works" if right == len(mine) else ("fails" if right == 0 else "degrades")
        out[key] = f"{word} {right}/{len(mine)}"
    return out


# --- the report ----------------------------------------------------------------------------------

_SHORT = {"converged": "conv", "inaccurate": "inacc", "max_iter": "max_it", "diverged": "div",
          "infeasible": "infeas", "failed": "fail", "refused": "n/a", "input-error": "error",
          "raised": "RAISED", "timeout": "timeout", "crashed": "crash", "built": "built"}


def _num(value: Any, digits: int = 1) -> str:
    if value is None or (isinstance(value, float) and not np.isfinite(value)):
        return "–"
    if isinstance(value, (int, np.integer)) or (isinstance(value, float) and value.is_integer()
                                                 and abs(value) < 1e6 and digits == 0):
        return f"{int(value):,}"
    return f"{value:.{digits}e}"


def _cell(row: dict[str, Any] | None, detail: str = "") -> str:
    """Status, ``*`` for a false claim the package caught, ``°`` for a right answer it turned
    down, ``!`` where the package's status was wrong; then ``detail``."""
    if row is None:
        return ""
    text = _SHORT.get(row["status"], row["status"])
    if row.get("outcome") == "caught":
        text += "*"
    if row.get("conservative"):
        text += "°"
    if not row.get("wrapper_right", True):
        text += "!"
    return f"{text} {detail}".strip()


def _pivot(rows: list[dict[str, Any]], row_key: str, col_key: str,
           cell: Callable[[dict[str, Any]], str], corner: str = "",
           col_label: Callable[[Any], str] = str) -> list[str]:
    row_values = list(dict.fromkeys(r[row_key] for r in rows))
    col_values = list(dict.fromkeys(r[col_key] for r in rows))
    index = {(r[row_key], r[col_key]): r for r in rows}
    lines = ["| " + " | ".join([corner] + [col_label(c) for c in col_values]) + " |",
             "|" + "---|" * (len(col_values) + 1)]
    for value in row_values:
        cells = [_cell_or_blank(index.get((value, c)), cell) for c in col_values]
        lines.append("| " + " | ".join([str(value)] + cells) + " |")
    return lines


def _cell_or_blank(row: dict[str, Any] | None, cell: Callable[[dict[str, Any]], str]) -> str:
    return "" if row is None else cell(row)


def _axis_rows(rows: list[dict[str, Any]], axis: str) -> list[dict[str, Any]]:
    return [r for r in rows if r["axis"] == axis]


def _fraction_text(value: float) -> str:
    return f"{value:g}×"


# axis 1
def _findings_step(rows: list[dict[str, Any]]) -> list[str]:
    out = []
    for case in dict.fromkeys(r["case"] for r in rows):
        for method in dict.fromkeys(r["method"] for r in rows):
            mine = sorted((r for r in rows if r["case"] == case and r["method"] == method),
                          key=lambda r: r["value"])
            if not mine:
                continue
            right = [r["value"] for r in mine if r["outcome"] == "right"]
            failing = [r for r in mine if r["outcome"] != "right"]
            text = f"**{case}, {method}** ({mine[0].get('dofs', 0):.0f} dofs): "
            if right:
                text += (f"right answer for ρ from {_fraction_text(min(right))} to "
                         f"{_fraction_text(max(right))} the bound 2/λ_max(W)")
                iters = {r["value"]: r["iterations"] for r in mine if r["outcome"] == "right"}
                shown = [v for v in (0.05, 0.5, 0.95) if v in iters]
                if shown:
                    text += " (" + ", ".join(f"{iters[v]:,.0f} iterations at {_fraction_text(v)}"
                                             for v in shown) + ")"
            beyond = [r for r in failing if r["value"] > (max(right) if right else 0)]
            if beyond:
                kinds = {}
                for r in beyond:
                    kind = r["status"]
                    if r["status"] == "diverged":
                        kind = ("diverged: two-step cycle" if "cycle" in str(r["message"])
                                else "diverged: growth")
                    kinds.setdefault(kind, []).append(r["value"])
                text += "; beyond: " + "; ".join(
                    f"{kind} at {', '.join(_fraction_text(v) for v in values)}"
                    for kind, values in kinds.items())
            inside = [r for r in failing if right and r["value"] < max(right)]
            if inside:
                text += "; not right inside that range at " + ", ".join(
                    f"{_fraction_text(r['value'])} ({r['status']})" for r in inside)
            bound = mine[0].get("bound_at_solution")
            if method == "uzawa" and bound is not None and np.isfinite(bound):
                text += (f". On the exact active set A the bound is 2/λ_max(W_AA) = "
                         f"{bound:.3f} × 2/λ_max(W)")
                if right and max(right) > 1.0:
                    text += (" — steps past 2/λ_max(W) can still converge, but the iteration "
                             "starts from λ = 0, far from A, so the slack is smaller")
            out.append(text + ".")
    return out


def _table_step(rows: list[dict[str, Any]]) -> list[str]:
    for r in rows:
        r["_column"] = f"{r['case']}, {r['method']}"
    lines = _pivot(rows, "value", "_column",
                   lambda r: _cell(r, f"{r.get('iterations', 0):,.0f}"),
                   corner="ρ / (2/λ_max)")
    for r in rows:
        r.pop("_column", None)
    return lines


def _figure_step(rows: list[dict[str, Any]]):
    from signorini.output import plots
    from signorini.studies.atlas import figures

    ax = figures.atlas_step_sweep(rows)
    ax.set_title("Axis 1: Uzawa's step (filled: right answer)", fontsize=9)
    return ax.figure


# axis 2
def _findings_mesh(rows: list[dict[str, Any]]) -> list[str]:
    levels = sorted({r["value"] for r in rows})
    dofs = {lv: next(r["dofs"] for r in rows if r["value"] == lv) for lv in levels}
    out = ["levels: " + ", ".join(f"refine {lv} = {dofs[lv]:,.0f} dofs" for lv in levels) + "."]
    for method in dict.fromkeys(r["method"] for r in rows):
        mine = sorted((r for r in rows if r["method"] == method), key=lambda r: r["value"])
        if method in ("pdas", "uzawa", "uzawa-nesterov", "condensed"):
            its = [r.get("iterations", float("nan")) for r in mine]
            text = (f"**{method}**: iterations " + " → ".join(_num(i, 0) for i in its)
                    + ", time " + " → ".join(f"{r.get('time_s', float('nan')):.2f}" for r in mine)
                    + " s")
            if len(its) >= 2 and all(np.isfinite(its)) and min(its) > 0:
                growth = (its[-1] / its[0]) ** (1.0 / (len(its) - 1))
                text += f" (×{growth:.2f} per halving of h"
                if method == "pdas":
                    step = (its[-1] - its[0]) / (len(its) - 1)
                    text += (f": about {step:.1f} more steps per halving — nearly, not exactly, "
                             "mesh-independent")
                text += ")"
            out.append(text + ".")
    for level in levels:
        mine = [r for r in rows if r["value"] == level]
        right = [r for r in mine if r["outcome"] == "right"]
        fastest = min(right, key=lambda r: r["time_s"]) if right else None
        not_right = [f"{r['method']} ({_cell(r)})" for r in mine if r["outcome"] != "right"
                     and r["status"] != "refused"]
        text = f"refine {level}: {len(right)} of {len(mine)} methods right"
        if fastest:
            text += f", fastest {fastest['method']} ({fastest['time_s']:.2f} s)"
        if not_right:
            text += "; not right: " + ", ".join(not_right)
        out.append(text + ".")
    return out


def _table_mesh(rows: list[dict[str, Any]]) -> list[str]:
    dofs = {r["value"]: r.get("dofs") for r in rows}
    return _pivot(rows, "method", "value",
                  lambda r: _cell(r, f"{r.get('iterations', 0):,.0f} it, {r.get('time_s', 0):.2g} s"),
                  corner="method", col_label=lambda v: f"refine {v} ({dofs[v]:,.0f} dofs)")


def _figure_mesh(rows: list[dict[str, Any]]):
    from matplotlib.figure import Figure

    from signorini.output import plots
    from signorini.studies.atlas import figures

    figure = Figure(figsize=(11, 4.4), layout="constrained")
    left, right = figure.subplots(1, 2)
    answered = [r for r in rows if r["status"] not in ("refused", "input-error")]
    counted = [r for r in answered if (r.get("iterations") or 0) > 0]  # some backends say 0
    figures.atlas_series(counted, "dofs", "iterations", ax=left,
                       ylabel="iterations (as the method counts them)")
    figures.atlas_series(answered, "dofs", "time_s", ax=right, ylabel="time (build + solve) [s]")
    figure.suptitle("Axis 2: mesh refinement of Hertz's cylinder (filled: right answer)", fontsize=9)
    return figure


# axis 3
def _findings_tolerance(rows: list[dict[str, Any]]) -> list[str]:
    out = []
    for method in dict.fromkeys(r["method"] for r in rows):
        mine = [r for r in rows if r["method"] == method]
        numeric = sorted((r for r in mine if r["value"] != "default"), key=lambda r: -r["value"])
        right = [r for r in numeric if r["outcome"] == "right"]
        false_claims = [r for r in mine if not r["claim_correct"]]
        text = f"**{method}**: "
        if right:
            text += f"right from tol = {right[0]['value']:.0e}"
            later = [r for r in numeric if r["value"] < right[0]["value"] and r["outcome"] != "right"]
            if later:
                text += " (not at " + ", ".join(f"{r['value']:.0e}: {_cell(r)}" for r in later) + ")"
        elif numeric:
            text += "right at no tolerance"
        else:
            text += "no tolerance to set"
        if false_claims:
            worst = max(false_claims, key=lambda r: (_wrong_nodes(r), r.get("lam_rel") or 0))
            text += (f"; its own success was false in {len(false_claims)} of "
                     f"{sum(r.get('claimed_status') == 'converged' for r in mine)} claims (worst at "
                     f"tol {worst['case']}: {_plural(_wrong_nodes(worst), 'node')} misclassified, "
                     f"λ off by {_num(worst.get('lam_rel'))}")
            if np.isfinite(worst.get("a_rel", np.nan)):
                text += (f", a off Hertz by {100 * worst['a_rel']:.1f} % and p₀ by "
                         f"{100 * worst['p0_rel']:.1f} % where the exact answer gives "
                         f"{100 * worst['ref_a_rel']:.1f} % and {100 * worst['ref_p0_rel']:.1f} %")
            text += ")"
        default = next((r for r in mine if r["value"] == "default"), None)
        if default is not None:
            text += (f"; at its own defaults: {_cell(default)}, λ off by "
                     f"{_num(default.get('lam_rel'))}, {_plural(_wrong_nodes(default), 'node')} "
                     "misclassified")
            if np.isfinite(default.get("a_rel", np.nan)) and _wrong_nodes(default) > 0:
                text += (f" (Hertz a off by {100 * default['a_rel']:.1f} %, p₀ by "
                         f"{100 * default['p0_rel']:.1f} %)")
        out.append(text + ".")
    return out


def _plural(count: float, noun: str) -> str:
    if not np.isfinite(count):
        return f"– {noun}s"
    return f"{count:.0f} {noun}{'' if count == 1 else 's'}"


def _wrong_nodes(row: dict[str, Any]) -> float:
    """Misclassified nodes, counting those the package labels weak although they penetrate."""
    values = [row.get("misclassified"), row.get("weak_penetrating")]
    values = [v for v in values if isinstance(v, (int, float)) and np.isfinite(v)]
    return float(sum(values)) if values else float("nan")


def _nodes_text(row: dict[str, Any]) -> str:
    hidden = row.get("weak_penetrating")
    text = _num(row.get("misclassified"), 0)
    if isinstance(hidden, (int, float)) and np.isfinite(hidden) and hidden > 0:
        text += f"+{hidden:.0f}p"
    return text


def _table_tolerance(rows: list[dict[str, Any]]) -> list[str]:
    return _pivot(rows, "method", "case",
                  lambda r: _cell(r, f"{_num(r.get('lam_rel'), 0)}/{_nodes_text(r)}"),
                  corner="backend \\ tol")


def _figure_tolerance(rows: list[dict[str, Any]]):
    from matplotlib.figure import Figure

    from signorini.output import plots
    from signorini.studies.atlas import figures

    numeric = [r for r in rows if r["value"] != "default"]
    figure = Figure(figsize=(11, 4.4), layout="constrained")
    left, right = figure.subplots(1, 2)
    figures.atlas_series(numeric, "value", "lam_rel", ax=left, xlabel="tolerance asked for",
                       ylabel="‖λ − λ*‖∞ / ‖λ*‖∞")
    left.plot([1e-10, 1e-2], [1e-10, 1e-2], "k:", lw=0.8)
    left.invert_xaxis()
    figures.atlas_series(numeric, "value", "misclassified", ax=right, xlabel="tolerance asked for",
                       ylabel="misclassified contact nodes", logy=False)
    right.invert_xaxis()
    figure.suptitle("Axis 3: tolerance (filled: right answer; red ring: the backend's own "
                    "'solved' was false)", fontsize=9)
    return figure


# axis 4
def _findings_units(rows: list[dict[str, Any]]) -> list[str]:
    out = []
    for scaling in ("scaled", "raw"):
        mine = [r for r in rows if r["case"].endswith(scaling)]
        systems = list(dict.fromkeys(r["value"] for r in mine))
        counts = [f"{s}: {sum(r['outcome'] == 'right' for r in mine if r['value'] == s)}/"
                  f"{sum(r['value'] == s for r in mine)}" for s in systems]
        out.append(f"**{scaling}** — methods right per unit system: " + "; ".join(counts) + ".")
    for method in dict.fromkeys(r["method"] for r in rows):
        scaled = [r for r in rows if r["method"] == method and r["case"].endswith("scaled")]
        raw = [r for r in rows if r["method"] == method and r["case"].endswith("raw")]
        s_ok = sum(r["outcome"] == "right" for r in scaled)
        r_ok = sum(r["outcome"] == "right" for r in raw)
        if s_ok != r_ok or s_ok < len(scaled):
            bad = [f"{r['value']} ({_cell(r)}, λ off {_num(r.get('lam_rel'))})"
                   for r in raw if r["outcome"] != "right"]
            text = f"**{method}**: right in {s_ok}/{len(scaled)} systems scaled, {r_ok}/{len(raw)} raw"
            if bad:
                text += "; raw units fail at " + "; ".join(bad)
            out.append(text + ".")
    return out


def _table_units(rows: list[dict[str, Any]]) -> list[str]:
    return _pivot(rows, "method", "case", lambda r: _cell(r, _num(r.get("lam_rel"), 0)),
                  corner="method")


def _figure_units(rows: list[dict[str, Any]]):
    from matplotlib.figure import Figure

    from signorini.output import plots
    from signorini.studies.atlas import figures

    figure = Figure(figsize=(11, 5.0), layout="constrained")
    left, right = figure.subplots(1, 2, sharey=True)
    for ax, scaling in ((left, "scaled"), (right, "raw")):
        figures.atlas_outcomes([r for r in rows if r["case"].endswith(scaling)], column="value", ax=ax,
                             title=f"{'non-dimensionalised' if scaling == 'scaled' else 'raw units'}")
    figure.suptitle("Axis 4: units (green: right; orange: false 'solved' caught; grey: no claim; "
                    "red: the package's status was wrong)", fontsize=9)
    return figure


# axis 5
def _findings_poisson(rows: list[dict[str, Any]]) -> list[str]:
    out = []
    for case in dict.fromkeys(r["case"] for r in rows):
        pdas = sorted((r for r in rows if r["case"] == case and r["method"] == "pdas"),
                      key=lambda r: r["value"])
        if pdas and np.isfinite(pdas[0].get("p0_rel", np.nan)):
            out.append(f"**pdas on {case}** ({pdas[0]['dofs']:,.0f} dofs), Hertz p₀ error: " + ", ".join(
                f"ν={r['value']:g}: {100 * r['p0_rel']:.1f} %" for r in pdas)
                + "; pressure L2 error: " + ", ".join(
                f"{100 * r['pressure_l2_rel']:.1f} %" for r in pdas) + ".")
    mesh_a = [r for r in rows if r["case"] == "mesh A"]
    for nu in sorted({r["value"] for r in mesh_a}):
        mine = [r for r in mesh_a if r["value"] == nu]
        bad = [f"{r['method']} ({_cell(r)})" for r in mine if r["outcome"] != "right"
               and r["status"] != "refused"]
        text = f"ν = {nu:g}: {sum(r['outcome'] == 'right' for r in mine)}/{len(mine)} methods right"
        out.append(text + (("; not: " + ", ".join(bad)) if bad else "") + ".")
    uzawa = sorted((r for r in mesh_a if r["method"] == "uzawa"), key=lambda r: r["value"])
    if uzawa:
        out.append("uzawa iterations on mesh A: " + ", ".join(
            f"ν={r['value']:g}: {r['iterations']:,.0f} ({_SHORT.get(r['status'], r['status'])})"
            for r in uzawa) + ".")
    return out


def _table_poisson(rows: list[dict[str, Any]]) -> list[str]:
    mesh_a = [r for r in rows if r["case"] == "mesh A"]
    return _pivot(mesh_a, "method", "value",
                  lambda r: _cell(r, f"{_num(r.get('lam_rel'), 0)}"), corner="method \\ ν")


def _figure_poisson(rows: list[dict[str, Any]]):
    from matplotlib.figure import Figure

    from signorini.output import plots
    from signorini.studies.atlas import figures

    figure = Figure(figsize=(11, 4.4), layout="constrained")
    left, right = figure.subplots(1, 2)
    pdas = [dict(r, incompressibility=0.5 - r["value"]) for r in rows if r["method"] == "pdas"]
    figures.atlas_series(pdas, "incompressibility", "p0_rel", ax=left, group="case",
                       xlabel="0.5 − ν", ylabel="Hertz p₀ relative error (pdas, exact)")
    left.invert_xaxis()
    profiles = {r["value"]: r["profile"] for r in pdas if r["case"] == "mesh A"
                and isinstance(r.get("profile"), dict)}
    if profiles:
        low, high = min(profiles), max(profiles)
        scaled = {nu: (np.asarray(p["x"]) / p["a_ref"], np.asarray(p["pressure"]) / p["p0_ref"])
                  for nu, p in profiles.items()}
        plots.pressure_profile(scaled[low][0], scaled[low][1], a_ref=1.0, p0_ref=1.0,
                               label=f"ν = {low:g}", ax=right)
        right.plot(scaled[high][0], scaled[high][1], "x-", ms=4, lw=0.6, color="C3",
                   label=f"ν = {high:g}")
        right.legend(fontsize=7)
        right.set_xlim(0, 1.6)
        right.set_title("pressure at the nodes (pdas, mesh A)", fontsize=8)
    figure.suptitle("Axis 5: near-incompressibility — P1 locking in the contact pressure", fontsize=9)
    return figure


# axis 6
def _findings_force(rows: list[dict[str, Any]]) -> list[str]:
    out = []
    for case in ("singular K", f"regularised ε={REGULARISATION:g}"):
        mine = [r for r in rows if r["case"] == case]
        if not mine:
            continue
        right = [r["method"] for r in mine if r["outcome"] == "right"]
        raised = [r["method"] for r in mine if r["status"] == "raised"]
        other = [f"{r['method']} ({_cell(r)})" for r in mine
                 if r["outcome"] != "right" and r["status"] != "raised"]
        text = f"**{case}** ({mine[0].get('dofs', 0):,.0f} dofs): right: {', '.join(right) or 'none'}"
        if raised:
            text += (f"; the package raised instead of giving a status for {', '.join(raised)} "
                     f"(own answers: " + ", ".join(
                         f"{r['method']} {r['claimed_status']}, λ off {_num(r.get('lam_rel'))}"
                         for r in mine if r["status"] == "raised") + ")")
        if other:
            text += "; not right: " + ", ".join(other)
        diagnosis = next((r.get("diagnosis") for r in mine if r.get("diagnosis")), "")
        if diagnosis:
            text += f". Diagnosis: “{diagnosis}”"
        out.append(text + ".")
    sweep = [r for r in rows if str(r["case"]).startswith("ε=")]
    for method in dict.fromkeys(r["method"] for r in sweep):
        mine = sorted((r for r in sweep if r["method"] == method), key=lambda r: r["value"])
        out.append(f"**{method}, regularised**: λ off the exact patch solution by " + ", ".join(
            f"{_num(r.get('patch_lam_rel'))} at ε={r['value']:g}" for r in mine) + ".")
    return out


def _table_force(rows: list[dict[str, Any]]) -> list[str]:
    main = [r for r in rows if not str(r["case"]).startswith("ε=")]
    return _pivot(main, "method", "case",
                  lambda r: _cell(r, f"{_num(r.get('patch_lam_rel'), 0)}"), corner="method")


def _figure_force(rows: list[dict[str, Any]]):
    from matplotlib.figure import Figure

    from signorini.output import plots
    from signorini.studies.atlas import figures

    figure = Figure(figsize=(11, 4.8), layout="constrained")
    left, right = figure.subplots(1, 2, width_ratios=(1.0, 0.8))
    sweep = [r for r in rows if str(r["case"]).startswith("ε=")]
    figures.atlas_series(sweep, "value", "patch_lam_rel", ax=left, xlabel="regularisation ε",
                       ylabel="‖λ − λ_exact‖∞ / ‖λ_exact‖∞ (vs the unregularised patch solution)")
    main = [r for r in rows if not str(r["case"]).startswith("ε=")]
    figures.atlas_outcomes(main, column="case", ax=right, title="status per method")
    figure.suptitle("Axis 6: a block held only by contact (force control, singular K)", fontsize=9)
    return figure


# axis 7
def _findings_degenerate(rows: list[dict[str, Any]]) -> list[str]:
    out = []
    for case in dict.fromkeys(r["case"] for r in rows):
        mine = [r for r in rows if r["case"] == case]
        pdas = next((r for r in mine if r["method"] == "pdas"), mine[0])
        converged = [r for r in mine if r["status"] == "converged"]
        wolves = [r for r in converged if (r.get("misclassified") or 0) > 0]
        strict = [r for r in converged if (r.get("misclassified_strict") or 0) > 0]
        out.append(
            f"**{case}** ({pdas.get('candidates', 0):.0f} candidates, {_num(pdas.get('weak'), 0)} "
            f"weakly active in the exact answer): {len(converged)} methods converged; with weakly "
            f"active nodes left out, {len(wolves)} of them show a misclassified node; counting "
            f"strictly (weak tolerance 0), {len(strict)} would (up to "
            f"{_plural(_most_strict(mine), 'node')} each).")
    return out


def _most_strict(rows: list[dict[str, Any]]) -> float:
    return max((r.get("misclassified_strict") or 0 for r in rows), default=0)


def _table_degenerate(rows: list[dict[str, Any]]) -> list[str]:
    return _pivot(rows, "method", "case",
                  lambda r: _cell(r, f"{_num(r.get('misclassified'), 0)} / "
                                     f"{_num(r.get('misclassified_strict'), 0)} / {_num(r.get('weak'), 0)}"),
                  corner="method")


def _figure_degenerate(rows: list[dict[str, Any]]):
    from signorini.output import plots
    from signorini.studies.atlas import figures

    ax = figures.atlas_weak_nodes(rows)
    ax.figure.set_size_inches(11, 4.4)
    ax.set_title("Axis 7: degenerate contact — misclassified nodes with and without the weak label",
                 fontsize=9)
    return ax.figure


# axis 8
def _findings_ill_posed(rows: list[dict[str, Any]]) -> list[str]:
    out = []
    for case in dict.fromkeys(r["case"] for r in rows):
        build = next((r for r in rows if r["case"] == case and r["method"] == BUILD_ONLY), None)
        mine = [r for r in rows if r["case"] == case and r["method"] != BUILD_ONLY]
        text = f"**{case}** — {ILL_POSED_CASES.get(case, case)}: "
        if build is not None:
            if build["status"] == "input-error":
                text += f"refused when the problem is built: “{build['message']}”"
            else:
                text += ("built; the diagnosis says “" + build["diagnosis"] + "”"
                         if build.get("diagnosis") else "built; nothing to diagnose")
        if mine:
            counts: dict[str, list[str]] = {}
            for r in mine:
                counts.setdefault(_cell(r), []).append(r["method"])
            text += ". Methods: " + "; ".join(f"{k}: {', '.join(v)}" for k, v in counts.items())
            unclear = [r for r in mine if r["status"] == "failed"]
            if unclear:
                text += (". Failure messages: " + "; ".join(
                    f"{r['method']} “{str(r['message'])[:90]}”" for r in unclear[:3]))
        out.append(text + ".")
    return out


def _table_ill_posed(rows: list[dict[str, Any]]) -> list[str]:
    mine = [r for r in rows if r["method"] != BUILD_ONLY]
    return _pivot(mine, "method", "case", lambda r: _cell(r), corner="method")


def _figure_ill_posed(rows: list[dict[str, Any]]):
    from signorini.output import plots
    from signorini.studies.atlas import figures

    ax = figures.atlas_outcomes([r for r in rows if r["method"] != BUILD_ONLY], column="case",
                              title="Axis 8: infeasible and ill-posed input (green: the right "
                                    "status or answer)")
    ax.figure.set_size_inches(7, 5)
    return ax.figure


REPORTS: dict[str, tuple[Callable, Callable, Callable, str]] = {
    "uzawa-step": (_findings_step, _table_step, _figure_step,
                   "Cells: status and iterations."),
    "mesh": (_findings_mesh, _table_mesh, _figure_mesh, "Cells: status, iterations, time."),
    "tolerance": (_findings_tolerance, _table_tolerance, _figure_tolerance,
                  "Cells: status, λ error / misclassified nodes (`+kp`: k more nodes with zero "
                  "force that penetrate, which `kkt.classify` labels weakly active)."),
    "units": (_findings_units, _table_units, _figure_units, "Cells: status, λ error."),
    "poisson": (_findings_poisson, _table_poisson, _figure_poisson,
                "Mesh A; cells: status, λ error against PDAS on the same mesh."),
    "force-control": (_findings_force, _table_force, _figure_force,
                      "Cells: status, λ error against the exact patch solution."),
    "degenerate": (_findings_degenerate, _table_degenerate, _figure_degenerate,
                   "Cells: status, misclassified nodes (weak left out) / counted strictly / "
                   "weakly active nodes."),
    "ill-posed": (_findings_ill_posed, _table_ill_posed, _figure_ill_posed, "Cells: status."),
}

ADVICE = {
    "uzawa-step": "keep `step_fraction` below 1 (the default 0.9); `uzawa-nesterov` needs at most "
                  "0.5 (its default). Past the bound the package says `diverged` and names the "
                  "two-step cycle or the growth; lower `rho` or `step_fraction`.",
    "mesh": "on fine meshes use `pdas` (or `condensed` while the candidates are few): their "
            "iterations barely grow, while Uzawa's double with every halving of h. Of the QP "
            "backends only those shown right here reach tol 1e-8 honestly; check the status.",
    "tolerance": "ask for the accuracy you need (`--tol`) and trust `converged` only; a "
                 "backend's own 'solved' at its defaults or at a loose tolerance is no evidence "
                 "of the right contact zone. For exact contact use `pdas`, `condensed`, daqp or "
                 "quadprog (the last two on small problems).",
    "units": "keep the default non-dimensionalisation. Raw units (`--raw-units`, "
             "`nondimensionalise=False`) leave the exact methods unharmed but put the QP "
             "backends' absolute tolerances at the mercy of E and the length unit.",
    "poisson": "P1 triangles lock as ν → 0.5: the contact pressure oscillates from node to node "
               "and refining the mesh cures it only slowly. Keep ν ≤ 0.45 where the pressure "
               "matters, read p₀ from a smoothed or averaged pressure if you must go higher, and "
               "for rubber-like materials use a mixed (u–p) or higher-order element, which this "
               "package does not provide. The solvers are not the problem: the exact methods "
               "solve every ν; first-order methods slow down with the conditioning.",
    "force-control": "prescribe a displacement where you can (every scene of the package does). "
                     "For a body held only by contact, `signorini.diagnose.regularise(problem, "
                     "1e-8)` adds ε·mean(diag K) to the diagonal: PDAS, the condensed dual and "
                     "the QP backends then solve it with λ within about 100 ε of the exact answer on "
                     "the 8 × 8 block; "
                     "Uzawa does not (its W gains an eigenvalue of order 1/ε). Run "
                     "`signorini.diagnose.diagnose(problem)` to see whether K is singular.",
    "degenerate": "nothing: nodes that touch with zero force are labelled weakly active and left "
                  "out of active-set comparisons, so an inexact method is not blamed for them. "
                  "Look at their count (`weak`) when two answers seem to disagree.",
    "ill-posed": "run `signorini.diagnose.diagnose(problem)` on a problem you built yourself: it "
                 "names infeasible candidates, duplicated candidates and a singular K in words. "
                 "The package refuses an empty contact set and zero-weight candidates outright.",
}

SETUPS = {
    "uzawa-step": f"Hertz's cylinder {STEP_SCENES['hertz-cylinder']} and the block "
                  f"{STEP_SCENES['block']}; `uzawa` and `uzawa-nesterov` with "
                  "`step_fraction` = ρ/(2/λ_max(W)) from 0.05 to 2.5, tol 1e-8, at most "
                  f"{STEP_CAPS['uzawa']:,} (uzawa) and {STEP_CAPS['uzawa-nesterov']:,} "
                  "(uzawa-nesterov) iterations.",
    "mesh": f"Hertz's cylinder {MESH_BASE}, `refine` 0–3 (h halves each level); every method at "
            "tol 1e-8.",
    "tolerance": f"Hertz's cylinder {TOLERANCE_SCENE}; every QP backend and cvxpy at tol 1e-2 … "
                 "1e-10 and at its own defaults (quadprog has no tolerance: defaults only).",
    "units": f"Hertz's cylinder {UNITS_MESH}, a/R = 0.05, in six unit systems; each assembled "
             "non-dimensionalised (the default) and raw (`nondimensionalise=False`, "
             "`--raw-units`); every method at tol 1e-8; the exact answer is PDAS on the scaled "
             "problem, converted.",
    "poisson": f"Hertz's cylinder {POISSON_MESH} (mesh A) with every method, and PDAS alone on "
               "refine 1 (mesh B) and refine 2 (mesh C); ν = 0.3 … 0.4999, tol 1e-8.",
    "force-control": f"The block {FORCE_BLOCK} under a pressure q = 0.01 E on its top, only the "
                     "symmetry plane prescribed (`signorini.scenes.block.force_controlled_problem`); "
                     "the exact answer is the patch solution (p = q). Every method on the singular "
                     f"problem and on `regularise(problem, {REGULARISATION:g})`; PDAS and Clarabel "
                     "for ε from 1e-14 to 1e-2.",
    "degenerate": "The block (8 × 8) with `touching` = 0.25 and 0.5: the outer part of the bottom "
                  "meets an obstacle shaped exactly to where it goes unsupported, so those nodes "
                  "touch with zero force. Every method at tol 1e-8.",
    "ill-posed": "The block (4 × 4) made infeasible or ill-posed five ways "
                 "(`signorini.studies.problems.ill_posed_problem`); each problem is built and diagnosed "
                 "(`signorini.diagnose.diagnose`), then solved by every method where it builds.",
}


def reproduction(row: dict[str, Any]) -> str:
    """A Python line that repeats the run of ``row`` with the package's wrapper."""
    options = json.loads(row["options"]) if row.get("options") else {}
    arguments = f"tol={row['tol']!r}" if row.get("tol") is not None else "tol=None"
    max_iter = ITERATION_CAPS.get(row["method"]) if row.get("tol") is not None else None
    if row["axis"] == "uzawa-step":
        max_iter = STEP_CAPS.get(row["method"])
    if max_iter:
        arguments += f", max_iter={max_iter}"
    arguments += "".join(f", {k}={v!r}" for k, v in options.items())
    return ("from signorini.studies.problems import build_spec; from signorini.solvers.registry import solve; "
            f"solve(build_spec({row['problem']}), {row['method']!r}, {arguments})")


def _csv_text(rows: list[dict[str, Any]]) -> str:
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=COLUMNS, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: _csv_value(row.get(k)) for k in COLUMNS})
    return buffer.getvalue()


def _csv_value(value: Any) -> Any:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return ""
    return value


def figure_name(axis: Axis) -> str:
    """The file name of an axis's figure."""
    return f"axis{axis.number}-{axis.name}.png"


def write_report(result: AtlasResult, out: str | os.PathLike, command: str) -> dict[str, Path]:
    """Write ``out/stability.md``; the runs (CSV, JSON) and a figure per axis in ``out/stability/``.

    Every file is written whole or not at all (a temporary file, then a rename).
    """
    from signorini.files import atomic_write_text, save_figure, to_json, writable_directory
    from signorini.output.report import provenance

    directory = writable_directory(out)
    data = writable_directory(Path(out) / "stability")
    info = provenance()
    rows = result.rows
    paths = {"csv": data / "runs.csv", "json": data / "runs.json", "report": directory / "stability.md"}
    right, runs, faults = wrapper_record(rows)
    summary = method_summary(rows)
    atomic_write_text(paths["csv"], _csv_text(rows))
    atomic_write_text(paths["json"], to_json({
        "command": command, "provenance": info, "elapsed_s": result.elapsed_s,
        "axis_seconds": result.axis_seconds, "quick": result.quick,
        "axes": [a.name for a in result.axes], "wrapper": {"right": right, "runs": runs},
        "methods": summary, "verdicts": {f"{m} | {a}": v for (m, a), v in verdicts(rows).items()},
        "rows": rows}) + "\n")
    for axis in result.axes:
        mine = _axis_rows(rows, axis.name)
        if mine:
            figure = REPORTS[axis.name][2](mine)
            save_figure(figure, data / figure_name(axis))
            paths[axis.name] = data / figure_name(axis)
    atomic_write_text(paths["report"], report_markdown(result, command, info))
    return paths


def report_markdown(result: AtlasResult, command: str, info: dict[str, Any]) -> str:
    """The atlas as Markdown: summary, the package's record, method × axis, then each axis."""
    rows = result.rows
    right, runs, faults = wrapper_record(rows)
    minutes = result.elapsed_s / 60.0
    md = ["# signorini stability atlas", "",
          f"Command: `{command}`  ",
          f"Run time: {result.elapsed_s:.0f} s ({minutes:.1f} min) for {runs} runs"
          + (" (quick: tiny meshes, few methods)" if result.quick else "") + "; per axis: "
          + ", ".join(f"{name} {sec:.0f} s" for name, sec in result.axis_seconds.items()) + "  ",
          f"Machine: {info['cpu']}, {info['cores']} cores, Python {info['python']}, {info['date']}  ",
          "Versions: " + ", ".join(f"{k} {v}" for k, v in info["versions"].items()), "",
          "Every run is a method at a tolerance on one problem, in its own worker process with a "
          "time limit. Data: [`stability/runs.csv`](stability/runs.csv) and "
          "[`stability/runs.json`](stability/runs.json) (one row per run, with the problem's "
          "spec to repeat it).", "",
          "## How to read it", "",
          "- **own status** (`claimed_status`): what the method said before the package judged "
          "it; **status**: what `signorini.solvers.solve` returned.",
          "- **certificate**: the worst relative KKT residual of `signorini.kkt.certificate`; it "
          "passes when ≤ τ (the tolerance asked for; 1e-6 without one).",
          "- **exact answer**: PDAS at 1e-9 on the non-dimensionalised problem (or the patch "
          "solution where K is singular). An answer **agrees** when no contact node is "
          "misclassified (`kkt.compare`, weakly active nodes left out — but a node with zero "
          "force that penetrates the obstacle counts) and ‖λ − λ*‖∞ ≤ "
          f"min({AGREE_FACTOR:g} τ, {AGREE_CAP:g}) · max(‖λ*‖∞, 1e-5 ‖f‖∞) (the validation "
          "suite's ratio, capped so that a loose τ cannot excuse a wrong contact force).",
          "- a method's claim of success is **correct** when its answer passes the certificate "
          "and agrees; the **correct rate** is the share of its claims that were correct.",
          "- the package's status is **right** when it says `converged` only for answers that "
          "agree, grants `converged` whenever the claim was correct, and returns a status "
          "instead of raising.",
          "- outcomes: **right** (converged, agrees), **caught** (a false claim the package "
          "downgraded to `inaccurate`), **conservative** (a claim the certificate turned down "
          f"although λ is within {NEAR_FACTOR:g} τ of the exact answer), **failed** (no claim), "
          "**wrong** (the package's status was wrong: `converged` for an answer that does not "
          "agree, `infeasible` for a problem that has a solution, or an exception instead of a "
          "status).",
          "- in tables: `*` a false claim caught, `°` conservative, `!` the package's status was "
          "wrong; `n/a` a dense backend refusing a problem above 3000 dofs.", "",
          "## Per method", "",
          "| method | runs | own claims of success | correct claims | correct rate | right answers "
          "| package's status right | statuses |",
          "|---|---:|---:|---:|---:|---:|---:|---|"]
    for s in method_summary(rows):
        rate = "–" if not np.isfinite(s["correct_rate"]) else f"{100 * s['correct_rate']:.0f} %"
        statuses = ", ".join(f"{k} {v}" for k, v in sorted(s["statuses"].items()))
        md.append(f"| {s['method']} | {s['runs']} | {s['claims']} | {s['claims_correct']} | {rate} "
                  f"| {s['right']} | {s['wrapper_right']}/{s['runs']} | {statuses} |")
    md += ["", "## The package's status", "",
           f"**Right in {right} of {runs} runs ({100 * right / max(runs, 1):.1f} %).**", ""]
    if faults:
        md += ["Where it was not (each line repeats the run):", ""]
        for r in faults:
            detail = r.get("wrapper", "") if r["status"] == "raised" else r.get("message", "")
            md.append(f"- axis {r['axis']}, {r['case']}, `{r['method']}`: status `{r['status']}`, "
                      f"own `{r.get('claimed_status')}`; {str(detail)[:160]}; "
                      f"λ off {_num(r.get('lam_rel'))}, {_nodes_text(r)} misclassified.  \n"
                      f"  `{reproduction(r)}`")
        md.append("")
    conservative = [r for r in _method_rows(rows) if r.get("conservative")]
    if conservative:
        md += [f"{len(conservative)} runs were **conservative**: the method's answer agreed with the "
               f"exact one to within {NEAR_FACTOR:g} τ but missed τ on the certificate, so the "
               "package said `inaccurate` "
               "(methods: " + ", ".join(sorted({r["method"] for r in conservative})) + ").", ""]
    table = verdicts(rows)
    axes = [a for a in result.axes if any(r["axis"] == a.name for r in rows)]
    methods = list(dict.fromkeys(r["method"] for r in _method_rows(rows)))
    md += ["## Method × axis", "",
           "Right answers among the runs that count (inside the step bound on axis 1; not "
           "refused for size): works = all, degrades = some, fails = none.", "",
           "| method | " + " | ".join(f"{a.number}. {a.name}" for a in axes) + " |",
           "|---|" + "---|" * len(axes)]
    for method in methods:
        md.append(f"| {method} | " + " | ".join(table.get((method, a.name), "–") for a in axes) + " |")
    for axis in axes:
        mine = _axis_rows(rows, axis.name)
        findings, table_fn, _, legend = REPORTS[axis.name]
        here_right, here_runs, _ = wrapper_record(mine)
        md += ["", f"## {axis.number}. {axis.title}", "", f"*{axis.question}*", "",
               f"Set-up: {SETUPS[axis.name]} {here_runs} runs, "
               f"{result.axis_seconds.get(axis.name, float('nan')):.0f} s; the package's status "
               f"was right in {here_right} of them.", "", "Findings:", ""]
        md += [f"- {line}" for line in findings(mine)]
        md += ["", f"What to do: {ADVICE[axis.name]}", "", legend, ""] + table_fn(mine)
        md += ["", f"![axis {axis.number}](stability/{figure_name(axis)})"]
    md += ["", "## Known limitations", "",
           "- Times are single runs on a shared 2-core machine: compare them within one axis, "
           "not across reports.",
           "- The meshes are kept small so that the atlas runs in minutes; the mesh axis stops at "
           "about 31k dofs. The benchmark (`signorini bench`) goes further.",
           "- An answer is compared with one exact answer; at weakly active nodes any force "
           "between 0 and round-off is right, so those nodes are left out of the comparison.",
           "- Dense backends (daqp, quadprog, ECOS) refuse problems above 3000 dofs (`n/a`)."]
    return "\n".join(md) + "\n"
