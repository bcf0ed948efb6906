"""The validation suite: default scenes × every installed method → tidy runs and checks.

Each case is one scene, declared by its family (``SceneFamily.validation``);
each run is one method at one tolerance. Runs record what the method said
(status, iterations, times) and what the package measured independently
(the KKT certificate, the distance from the exact ``pdas`` answer, the error
against the analytic reference). Checks are the
claims the suite stands behind (:mod:`signorini.studies.suite_checks`); any failed check fails
the suite.

Every run goes through the study runner (:mod:`signorini.studies.runner`):
one worker process rebuilds each case's problem from its spec, finds the
exact answer once (the reference policy :data:`REFERENCE`: PDAS at
:data:`TIGHT_TOL`) and runs every method on it, each within
:data:`TIME_LIMIT`. A method that hangs or crashes costs its own row.
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from signorini.errors import InputError
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.scenes import portable_scene
from signorini.scenes.base import Case
from signorini.scenes.registry import ValidationCases
from signorini.solvers.registry import BACKENDS, Method, get_method, methods
from signorini.studies.measures import answer_from
from signorini.studies.problems import build_spec
from signorini.studies.runner import (
    BUILD_ONLY,
    ITERATION_CAPS,
    Row,
    Task,
    measure_answer,
    run_on,
    run_tasks,
    task_row,
)
from signorini.studies.suite_checks import (LIMITS, REFERENCE_LABEL, REFERENCE_METHOD, TIGHT_TOL,
                                           CaseResult, Check, case_checks, label)

__all__ = ["DEFAULT_CASES", "REFERENCE", "SuiteResult", "TIME_LIMIT", "case_result", "case_tasks",
           "portable", "problem_case", "run_one", "run_suite", "run_task_of", "select_cases",
           "suite_row"]

log = logging.getLogger(__name__)

#: the exact answer every run is held to (a reference policy, :mod:`signorini.studies.problems`)
REFERENCE = {"kind": REFERENCE_METHOD, "tol": TIGHT_TOL}
#: methods also run at their backend's own default tolerance, to show what it gives
DEFAULT_TOLERANCE_RUNS = ("qp-osqp", "qp-clarabel")
#: seconds one run may take (its worker is then stopped and the run is a "timeout")
TIME_LIMIT = 600.0
#: what the suite measures of each run besides the runner's row
MEASURES = ("kkt", "times", "vs_reference", "reference", "answer")
#: the columns of a run in report.json, in order; a method that refused the problem is "skipped"
RUN_COLUMNS = ("method", "label", "tol", "status", "claimed_status", "message", "iterations",
               "build_s", "solve_s", "time_s", "kkt", "kkt_worst", "vs_reference", "reference",
               "case", "scene", "dofs", "candidates")
SKIPPED_COLUMNS = ("method", "label", "tol", "status", "message", "time_s", "kkt_worst", "case",
                   "scene", "dofs", "candidates")
#: what a run that stopped before it was measured (a timeout, a crash) shows in the measured columns
UNMEASURED = {"build_s": float("nan"), "solve_s": float("nan"),
              "kkt": {}, "kkt_worst": float("nan"), "vs_reference": {}, "dofs": float("nan"),
              "candidates": float("nan")}

#: every registered family's validation cases, in the order of registration (a live view of
#: :attr:`SceneFamily.validation <signorini.scenes.base.SceneFamily>`)
DEFAULT_CASES = ValidationCases()


def run_task_of(case: Case, method: str, tol: float | None,
                options: dict[str, Any] | None = None) -> Task:
    """The task of one run: ``method`` at ``tol`` (with ``options``) on the case, held to
    :data:`REFERENCE`."""
    cap = ITERATION_CAPS.get(method) if tol is not None else None
    return Task("validation", case.name, label(method, tol), case.spec, method, tol=tol,
                options=dict(options or {}), max_iter=cap, reference=REFERENCE, measure=MEASURES)


def case_tasks(case: Case, chosen: list[Method], tol: float = TIGHT_TOL,
               options: dict[str, dict[str, Any]] | None = None) -> list[Task]:
    """Build the case's problem and find its exact answer, then run every method on it at ``tol``
    (``options``: each method's options by its name)."""
    options = options or {}
    tasks = [Task("validation", case.name, "exact", case.spec, BUILD_ONLY, tol=TIGHT_TOL,
                  reference=REFERENCE, measure=("exact", "mesh"))]
    for method in chosen:
        tolerances = [tol] + ([None] if method.name in DEFAULT_TOLERANCE_RUNS else [])
        tasks += [run_task_of(case, method.name, t, options.get(method.name)) for t in tolerances]
    return tasks


def suite_row(row: Row, case: Case | None = None) -> Row:
    """A runner row as the report writes a run (:data:`RUN_COLUMNS`); a refusal is ``skipped``,
    and a run stopped before it was measured has :data:`UNMEASURED` in the measured columns."""
    values = {**UNMEASURED, **row, "label": row["value"]}
    if case is not None:
        values.update(case=case.name, scene=case.scene)
    if row["status"] == "refused":  # e.g. a dense backend refusing a large problem
        values.update(status="skipped", time_s=0.0, kkt_worst=float("nan"))
        return {k: values[k] for k in SKIPPED_COLUMNS if k in values}
    return {k: values[k] for k in RUN_COLUMNS if k in values}


def run_one(problem: ContactProblem, method: Method, tol: float | None,
            reference: ContactSolution | None) -> tuple[Row, ContactSolution | None]:
    """Solve a built problem with one method at one tolerance in this process and measure it.

    The runner's measurement of a suite run, for scripts that hold their own
    problems (``docs/punch/punch_study.py``).
    """
    task = run_task_of(Case("", problem.name), method.name, tol)
    row = task_row(task)
    solved = run_on(problem, task, row)
    if solved is None:
        return suite_row(row), None
    problem, solution = solved
    measure_answer(problem, task, row, solution, reference)
    return suite_row(row), solution


def case_result(case: Case, rows: list[Row]) -> CaseResult:
    """A case's runs (``rows``: its exact answer first) with the problem rebuilt for the checks."""
    problem = build_spec(case.spec)
    exact = rows[0].get("exact")
    reference = answer_from(exact) if exact else ContactSolution.failure(
        REFERENCE_METHOD, problem, "failed", rows[0].get("message") or "no answer")
    solutions = {row["value"]: answer_from(row["answer"]) for row in rows[1:] if "answer" in row}
    return CaseResult(case, problem, reference, solutions,
                      [suite_row(row, case) for row in rows[1:]])



@dataclass
class SuiteResult:
    results: list[CaseResult]
    checks: list[Check]
    elapsed_s: float
    #: what its report shows: the acceptance limits the checks were held to
    limits: dict[str, float] = field(default_factory=lambda: dict(LIMITS))

    #: the label of the reference runs
    reference_label = REFERENCE_LABEL

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    @property
    def runs(self) -> list[dict[str, Any]]:
        return [row for result in self.results for row in result.runs]


def select_cases(names: list[str] | None) -> tuple[Case, ...]:
    """The default cases named in ``names`` (all when empty); unknown names list the known."""
    if not names:
        return tuple(DEFAULT_CASES)
    known = {case.name: case for case in DEFAULT_CASES}
    unknown = [n for n in names if n not in known]
    if unknown:
        raise InputError(f"unknown case {unknown[0]!r}: --case takes {', '.join(known)}")
    chosen = [known[n] for n in names]
    # a case compared with another needs that one too
    for case in list(chosen):
        for other in (getattr(case, "same_as", None), getattr(case, "agrees_with", None)):
            if other and known[other] not in chosen:
                chosen.insert(0, known[other])
    return tuple(chosen)


def portable(method: Method) -> bool:
    """A worker process finds this method by its name: a backend's, or ``module:function``.

    A method known in this process only (a function defined in a notebook, given by
    :func:`~signorini.solvers.registry.given`) is not.
    """
    return ":" in method.name or any(method.name == m.name for b in BACKENDS for m in b.METHODS)


def run_suite(cases: Sequence[Case] = DEFAULT_CASES, method_names: list[str] | None = None,
              progress: Callable[[str], None] | None = None, *, isolate: bool | None = None,
              time_limit: float = TIME_LIMIT, tol: float = TIGHT_TOL,
              options: dict[str, dict[str, Any]] | None = None,
              limits: dict[str, float] | None = None) -> SuiteResult:
    """Run every case with every installed method (or ``method_names``) and check it.

    Every method runs at ``tol`` (the exact answer it is held to stays PDAS at
    :data:`TIGHT_TOL`), with its ``options`` (by method name); ``limits``
    replaces some of :data:`LIMITS` (:func:`read_limits`). Methods named in
    ``method_names`` must converge at ``tol`` on every case: a user's method
    that only claims success fails the suite.
    The runs go to one worker process, each within ``time_limit`` seconds;
    ``isolate=False`` runs them in this process without a limit, as happens
    by default when a method or a case's scene family was registered in this
    process only (:func:`portable`, :func:`signorini.scenes.portable_scene`).
    """
    start = time.perf_counter()
    say = progress or (lambda message: None)
    chosen = [get_method(name) for name in method_names] if method_names else \
        [m for m in methods(installed_only=True) if m.family != "user"]
    if isolate is None:
        isolate = all(portable(m) for m in chosen) and all(portable_scene(c.scene) for c in cases)
        if not isolate:
            log.info("a method or scene family registered in this process only: the suite runs "
                     "here, no time limit")
    limits = {**LIMITS, **(limits or {})}
    tasks = [task for case in cases for task in case_tasks(case, chosen, tol, options)]

    def report(index: int, count: int, task: Task, row: Row) -> None:
        if task.method == BUILD_ONLY:
            say(f"{task.case}: {row.get('dofs')} dofs, {row.get('candidates')} contact candidates "
                + ("(read from a file)" if row.get("assemble_s") is None  # NaN in JSON: None
                   else f"(assembled in {row['assemble_s']:.2f} s)"))
        else:
            time_s = 0.0 if row["status"] == "refused" else row.get("time_s", 0.0)
            say(f"  {task.value:<26} {suite_row(row)['status']:<10} {time_s:7.2f} s")

    rows = run_tasks(tasks, isolate=isolate, time_limit=time_limit, progress=report)
    results: list[CaseResult] = []
    by_name: dict[str, CaseResult] = {}
    checks: list[Check] = []
    for case in cases:
        result = case_result(case, [row for task, row in zip(tasks, rows) if task.case == case.name])
        results.append(result)
        by_name[case.name] = result
        checks.extend(case_checks(result, by_name, tuple(method_names or ()), tol, limits))
    return SuiteResult(results, checks, time.perf_counter() - start, limits)


def problem_case(path: str, taken: Sequence[str] = ()) -> Case:
    """A user's problem file (:mod:`signorini.problem.files`) as a case of the suite.

    Named after the file (its stem, numbered when ``taken`` has the name
    already); its spec reads the file in the worker by its absolute path.
    """
    name, number = Path(path).stem or "problem", 2
    while name in taken or any(name == case.name for case in DEFAULT_CASES):
        name, number = f"{Path(path).stem}-{number}", number + 1
    return Case(name, os.path.abspath(path))
