"""One runner for every study: a task, run in an isolated, time-limited worker, measured into a row.

A :class:`Task` is a method at a tolerance on a problem spec
(:mod:`signorini.studies.problems`), with a reference policy
(:data:`signorini.studies.problems.REFERENCE_POLICIES`) saying which exact
answer it is held to. :func:`run_task` runs it and measures one :class:`Row`:

- the method's own word (``claimed_status``) and the package's status;
- the independent certificate :func:`signorini.certification.kkt.certificate` and whether
  its worst relative residual is within the accepted tolerance ``τ``
  (:func:`signorini.solvers.base.acceptance`: ``tol``, or ``DEFAULT_TOL`` without one);
- the distance from the trusted exact answer ``(u*, λ*)``:
  ``‖λ − λ*‖∞ / max(‖λ*‖∞, 1e-5 ‖f‖∞)`` and the misclassified contact
  nodes (weakly active nodes left out, :func:`signorini.certification.comparison.compare`, plus
  nodes with zero force that penetrate, which that comparison misses);
- the Hertz errors of a and p₀ on Hertz's cylinder;
- whatever else the task asks for by name in ``measure`` (:data:`MEASURES`).

An answer **agrees** with the exact one when no node is misclassified and
the force error is at most ``min(AGREE_FACTOR · τ, AGREE_CAP)``; whether the
method's claim and the package's status were right:
:func:`signorini.studies.task.verdict`.

:func:`run_tasks` runs a list of tasks in a :class:`Worker` process with a
time limit: a backend that hangs or crashes costs one row, the worker is
restarted and the study goes on. A ``fresh`` task gets a process of its own
(the benchmark's timing), a task with ``ranks`` > 1 a process under ``mpirun``.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import os
import sys
import time
from typing import Any, Callable, Sequence

import numpy as np

from signorini.api import solve
from signorini.crosschecking import crosscheck
from signorini.certification.diagnosis import diagnose
from signorini.errors import InputError
from signorini.files import plain
from signorini.certification.comparison import compare
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.references.catalogue import reference_metrics
from signorini.scenes.block import force_controlled_exact
from signorini.solvers import cluster
from signorini.solvers.base import acceptance
from signorini.solvers.registry import get_method
from signorini.studies.measures import (
    answer_record,
    bound_at_solution,
    certificate_of,
    energy_error,
    estimate_record,
    factor_memory,
    factorisation_time,
    force_error,
    forward_error,
    whole_process,
    hertz_errors,
    pressure_profile,
    weak_but_penetrating,
)
from signorini.studies.problems import build_spec, candidate_spacing, exact_attempt, trusted
from signorini.studies.task import (
    ATLAS_TOL,
    BUILD_ONLY,
    COMMAND,
    CROSSCHECK,
    DEFAULT_TIME_LIMIT,
    MEASURES,
    Row,
    Task,
    failed_row,
    task_row,
    verdict,
)
from signorini.studies.worker import Worker, die_with_parent, in_worker, solve_within

log = logging.getLogger(__name__)

#: an answer agrees with the exact one when λ is within AGREE_FACTOR × the accepted tolerance
#: (the validation suite's ratio: 1e-6 at 1e-9), and never further off than AGREE_CAP
AGREE_FACTOR = 1e3
AGREE_CAP = 0.1
#: a right answer turned down by the certificate is "conservative" when λ is within NEAR_FACTOR × τ
NEAR_FACTOR = 10.0
#: iteration caps for first-order backends at tight tolerances (every study uses these)
ITERATION_CAPS = {"qp-osqp": 20_000, "qp-scs": 20_000}
#: columns that hold numbers (NaN when not measured)
NUMERIC = ("dofs", "candidates", "iterations", "time_s", "kkt_worst", "lam_rel", "u_rel",
           "misclassified", "weak", "misclassified_strict", "weak_penetrating", "a_rel", "p0_rel",
           "pressure_l2_rel", "ref_a_rel", "ref_p0_rel", "ref_pressure_l2_rel", "rho_over_bound",
           "lambda_max", "bound_at_solution", "patch_lam_rel")

__all__ = ["AGREE_CAP", "AGREE_FACTOR", "ATLAS_TOL", "BUILD_ONLY", "COMMAND", "CROSSCHECK", "DEFAULT_TIME_LIMIT",
           "ITERATION_CAPS", "MEASURES", "NEAR_FACTOR", "NUMERIC", "Row", "Task",
           "Worker", "in_worker", "measure_answer", "run_on", "run_task", "run_tasks", "serve_worker", "solve_within", "task_row"]


class _Cache:
    """Problems and references built in this process, the most recent few kept."""

    def __init__(self, size: int = 4):
        self.size = size
        self.items: dict[str, Any] = {}

    def get(self, key: str, make: Callable[[], Any]) -> Any:
        if key in self.items:
            self.items[key] = self.items.pop(key)  # the most recently used is kept longest
        else:
            value = make()  # may raise: nothing is stored then
            self.items[key] = value
            while len(self.items) > self.size:
                self.items.pop(next(iter(self.items)))
        return self.items[key]


def _key(*parts: Any) -> str:
    return json.dumps(parts, sort_keys=True, default=str)


def run_task(task: Task, cache: _Cache | None = None) -> Row:
    """Run one task in this process and measure it: one row."""
    cache = cache or _Cache()
    row = task_row(task)
    if task.method == COMMAND:
        found = whole_process(task.options["argv"], bool(task.options.get("record")),
                              int(task.options.get("ranks", 1)))
        row.update(status="ran", wrapper="returned", claimed_status="", process=found,
                   message=found["said"] or f"exit {found['returncode']}", time_s=found["wall_s"])
        return verdict(row, task)
    try:
        problem = cache.get(_key("problem", task.problem), lambda: build_spec(task.problem))
    except InputError as exc:
        row.update(status="input-error", wrapper="input-error", claimed_status="",
                   message=str(exc), scene=task.problem.get("scene", "block"))
        return verdict(row, task)
    row.update(scene=problem.name, dofs=problem.n, candidates=problem.m)
    if "matrix" in task.measure:
        row["nonzeros"] = int(problem.K.nnz)
    if "factor_memory" in task.measure:
        row["factor_memory"] = factor_memory(problem)
    if "mesh" in task.measure:
        made = problem.model  # None for a QP given as arrays (a problem file)
        row.update(h=candidate_spacing(problem),
                   assemble_s=float("nan") if made is None else made.assemble_s)
    if "diagnosis" in task.measure:
        row["diagnosis"] = " | ".join(diagnose(problem))

    def exact(own: ContactSolution | None = None) -> ContactSolution | None:
        """The trusted exact answer (measured into the row), computed once per problem."""
        def make():
            other = None
            if task.reference.get("problem") is not None:
                other = cache.get(_key("problem", task.reference["problem"]),
                                  lambda: build_spec(task.reference["problem"]))
            return exact_attempt(problem, task.reference, other, own)

        attempt = cache.get(_key("reference", task.problem, task.reference), make)
        if attempt is not None and "exact" in task.measure:
            row["exact"] = answer_record(attempt)
        reference = trusted(attempt)
        if reference is not None:
            row.update(hertz_errors(problem, reference, "ref_"))
            if "bound" in task.measure:
                row["bound_at_solution"] = cache.get(_key("bound", task.problem),
                                                     lambda: bound_at_solution(problem, reference))
        return reference

    if task.method == CROSSCHECK:
        check = crosscheck(problem, task.options["methods"], tol=task.tol,
                           options=task.options.get("options"))
        row.update(status="checked", wrapper="returned", claimed_status="", crosscheck=check.to_dict(),
                   message="every judged pair agrees" if check.passed else "a pair disagrees")
        return verdict(row, task)
    if task.method == BUILD_ONLY:
        if "exact" in task.measure:
            exact()
        row.update(status="built", wrapper="returned", claimed_status="",
                   message="the problem was built: " + (row.get("diagnosis") or "no finding"))
        return verdict(row, task)
    if "factorisation" in task.measure:
        row["factor_s"] = factorisation_time(problem)
    reference = None if task.fresh else exact()
    solved = run_on(problem, task, row)
    if solved is None:
        return verdict(row, task)
    problem, solution = solved
    if task.fresh:
        reference = exact(solution if task.is_policy_run else None)
    measure_answer(problem, task, row, solution, reference)
    if "finer" in task.measure and solution.success:
        row["finer"] = {str(level): _against_finer(problem, solution, task, level, cache)
                        for level in task.reference["finer"]["levels"]}
    return verdict(row, task)


def _against_finer(problem: ContactProblem, solution: ContactSolution, task: Task, level: int,
                   cache: _Cache) -> dict[str, Any]:
    """The ``finer`` measure at one level: the same scene ``level`` uniform refinements in, solved
    as ``task.reference["finer"]`` says (once per worker while it is cached)."""
    how = task.reference["finer"]
    spec = {**task.problem, "params": {**(task.problem.get("params") or {}), "refine": level}}

    def make() -> tuple[ContactProblem, ContactSolution]:
        result = solve(build_spec(spec), how["method"], tol=how.get("tol"))
        return result.problem, result.solution

    fine, answer = cache.get(_key("finer", spec, how), make)
    if answer.status != "converged":
        return {"status": answer.status, "dofs": fine.n}
    steps = level - (task.problem.get("params") or {}).get("refine", 0)
    return {"status": answer.status, **energy_error(problem, solution, fine, answer, steps)}


def run_on(problem: ContactProblem, task: Task,
           row: Row) -> tuple[ContactProblem, ContactSolution] | None:
    """Solve ``problem`` as ``task`` says and record what the method said: the problem solved (at
    the load matched, for a target load left to the method) and the answer; None when refused."""
    start = time.perf_counter()
    wrapper = "returned"
    try:
        # as signorini.solve: the scene's predictions reach the methods that take them
        result = solve(problem, task.method, tol=task.tol, max_iter=task.max_iter,
                       **task.options)
        problem, solution = result.problem, result.solution
    except InputError as exc:
        row.update(status="refused", wrapper="input-error", claimed_status="", message=str(exc),
                   time_s=time.perf_counter() - start)
        return None
    except Exception as exc:  # the wrapper gave no status: record it, then ask the method itself
        wrapper = f"raised {type(exc).__name__}: {exc}"
        solution = _own_answer(problem, task)
    elapsed = time.perf_counter() - start
    row.update(status=solution.status if wrapper == "returned" else "raised",
               claimed_status=solution.own_status, wrapper=wrapper, iterations=solution.iterations,
               time_s=elapsed)
    if "times" in task.measure or "factorisation" in task.measure:
        method_s = float(solution.seconds.get("method", elapsed))
        row.update(build_s=solution.build_time, solve_s=solution.solve_time, method_s=method_s)
        if "factor_s" in row:
            row["ratio_to_factor"] = method_s / row["factor_s"]
    return problem, solution


def _own_answer(problem: ContactProblem, task: Task) -> ContactSolution:
    """The method called directly, without the package's wrapper (when the wrapper raised)."""
    try:
        solution = get_method(task.method).function(problem, tol=task.tol, max_iter=task.max_iter,
                                                   **task.options)
    except Exception as exc:
        return ContactSolution.failure(task.method, problem, "failed",
                                       f"{type(exc).__name__}: {exc}")
    return solution


def measure_answer(problem: ContactProblem, task: Task, row: Row, solution: ContactSolution,
                   reference: ContactSolution | None) -> None:
    """The certificate, the distance from the exact answer and what ``task.measure`` asks for."""
    cert = certificate_of(problem, solution)
    worst_name, worst = cert.worst()
    accept = acceptance(task.tol)
    row.update(kkt_worst=worst, kkt_name=worst_name,
               cert_ok=bool(np.isfinite(worst) and worst <= accept), message=solution.message)
    if "kkt" in task.measure:
        row["kkt"] = cert.as_dict()
    for name in ("rho_over_bound", "lambda_max"):
        if name in solution.extras:
            row[name] = float(solution.extras[name])
    if reference is not None and task.answer == "displacement":
        u_rel = compare(problem, reference, solution).u_rel
        row.update(u_rel=u_rel, exact_ok=bool(u_rel <= AGREE_FACTOR * accept))
    elif reference is not None and not np.all(np.isfinite(solution.lam)):
        row.update(lam_rel=float("inf"), exact_ok=False, near_exact=False)  # no answer to compare
    elif reference is not None:
        vs = compare(problem, reference, solution)
        strict = compare(problem, reference, solution, weak_tol=0.0)
        lam_rel = force_error(problem, reference, solution)
        hidden = weak_but_penetrating(problem, solution)
        same = vs.misclassified == 0 and hidden == 0
        row.update(lam_rel=lam_rel, u_rel=vs.u_rel, misclassified=vs.misclassified,
                   weak=vs.weak, misclassified_strict=strict.misclassified,
                   weak_penetrating=hidden,
                   exact_ok=bool(same and lam_rel <= min(AGREE_FACTOR * accept, AGREE_CAP)),
                   near_exact=bool(same and lam_rel <= NEAR_FACTOR * accept))
    if reference is not None and "vs_reference" in task.measure:
        row["vs_reference"] = compare(problem, reference, solution).as_dict()
    row.update(hertz_errors(problem, solution))
    if "reference" in task.measure:
        row["reference"] = reference_metrics(problem, solution)
    found = estimate_record(problem, solution) if "estimate" in task.measure and solution.success \
        else None
    if found is not None:
        row["estimate"] = found
    if "patch" in task.measure:
        row["patch_lam_rel"] = compare(problem, force_controlled_exact(problem), solution).lam_rel
    finite = bool(np.all(np.isfinite(solution.lam)))
    if "profile" in task.measure and finite:
        row["profile"] = pressure_profile(problem, solution)
    if reference is not None and "forward_error" in task.measure:
        row["forward_error"] = forward_error(problem, reference, solution)
    if "lam" in task.measure:
        row["lam"] = solution.lam.tolist()
    if "answer" in task.measure:  # with the push it was solved at, and its certificate
        push = problem.model.push
        row["answer"] = {**answer_record(solution), **({} if push is None else {"push": push.scale}),
                         "certificate": {name: value if np.isfinite(value) else str(value)
                                         for name, value in dataclasses.asdict(cert).items()}}


# --- running many tasks: in this process or in a worker with a time limit ------------------------


def serve_worker() -> None:
    """The worker's loop: one JSON task per line on stdin, one JSON row per line back.

    Anything a backend prints goes to stderr; the rows go to a private copy of
    the original stdout. Under ``mpirun`` rank 0 runs the tasks and the other
    ranks serve its distributed solves until stdin closes.
    """
    logging.disable(logging.WARNING)
    die_with_parent()
    if cluster.launched_size() > 1 and cluster.rank() != 0:
        os.dup2(2, 1)  # nothing of this rank may reach the rows
        cluster.serve()
        return
    channel = os.fdopen(os.dup(1), "w", buffering=1)
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    cache = _Cache()
    try:
        for line in sys.stdin:
            row = _run_here(Task(**json.loads(line)), cache)
            channel.write(json.dumps(plain(row)) + "\n")
    finally:
        cluster.release()


def _run_here(task: Task, cache: _Cache) -> Row:
    """:func:`run_task` (a fresh task with a cache of its own); an error of the runner itself
    becomes one row."""
    try:
        return run_task(task, _Cache() if task.fresh else cache)
    except Exception as exc:  # a bug of the runner itself: one row says so
        return failed_row(task, exc)


def run_tasks(tasks: Sequence[Task], *, isolate: bool = True, time_limit: float = DEFAULT_TIME_LIMIT,
              progress: Callable[[int, int, Task, Row], None] | None = None) -> list[Row]:
    """Run ``tasks`` in order: in a worker process with a time limit, or in this process.

    ``progress(index, count, task, row)`` hears of each row as it arrives.
    """
    rows = []
    worker = Worker(time_limit) if isolate else None
    cache = None if isolate else _Cache()
    try:
        for index, task in enumerate(tasks, start=1):
            row = worker.run(task) if worker is not None else _run_here(task, cache)
            if worker is not None and ":" in task.method and worker.output.strip() \
                    and row.get("status") != "converged":  # what a user's method wrote, shown
                log.warning("method %s wrote:\n%s", task.method, worker.output.rstrip())
            row = {k: (float("nan") if v is None and k in NUMERIC else v) for k, v in row.items()}
            rows.append(row)
            if progress is not None:
                progress(index, len(tasks), task, row)
    finally:
        if worker is not None:
            worker.stop()
    return rows
