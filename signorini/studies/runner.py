"""One runner for every study: a task, run in an isolated, time-limited worker, measured into a row.

A :class:`Task` is a method at a tolerance on a problem spec
(:mod:`signorini.studies.problems`), with a reference policy saying which
exact answer it is held to. :func:`run_task` runs it and measures one row:

- the method's own word (``claimed_status``) and the package's status;
- the independent certificate :func:`signorini.kkt.certificate` and whether
  its worst relative residual is within the accepted tolerance ``τ``
  (``ACCEPT_FACTOR · tol``, or ``DEFAULT_ACCEPT`` without a tolerance);
- the distance from the trusted exact answer ``(u*, λ*)``:
  ``‖λ − λ*‖∞ / max(‖λ*‖∞, 1e-5 ‖f‖∞)`` and the misclassified contact
  nodes (weakly active nodes left out, :func:`signorini.kkt.compare`, plus
  nodes with zero force that penetrate, which that comparison misses);
- the Hertz errors of a and p₀ on Hertz's cylinder.

An answer **agrees** with the exact one when no node is misclassified and
the force error is at most ``min(AGREE_FACTOR · τ, AGREE_CAP)`` (λ within
1e-6 at a tolerance of 1e-9, capped). A method's claim of success is
**correct** when its answer passes the certificate and agrees; the package's
status is **right** when it says ``converged`` only for answers that agree,
grants it whenever the claim was correct, calls no solvable problem
``infeasible``, and never raises on a problem that was built.

:func:`run_tasks` runs a list of tasks in a :class:`Worker` process with a
time limit: a backend that hangs or crashes costs one row, the worker is
restarted and the study goes on.
"""

from __future__ import annotations

import json
import logging
import os
import select
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

from signorini.diagnose import diagnose
from signorini.errors import InputError
from signorini.files import plain
from signorini.kkt import (WEAK, WEAK_TOL, active_set, certificate, classify, compare, force_scale,
                           gap_scale)
from signorini.numerics.lcp import delassus
from signorini.pressure import compare_hertz, contact_profile
from signorini.problem import ContactProblem, ContactSolution
from signorini.scenes.block import force_controlled_exact
from signorini.solvers.registry import ACCEPT_FACTOR, DEFAULT_ACCEPT, get_method, solve
from signorini.studies.problems import build_spec, reference_solution

log = logging.getLogger(__name__)

#: an answer agrees with the exact one when λ is within AGREE_FACTOR × the accepted tolerance
#: (the validation suite's ratio: 1e-6 at 1e-9), and never further off than AGREE_CAP
AGREE_FACTOR = 1e3
AGREE_CAP = 0.1
#: a right answer turned down by the certificate is "conservative" when λ is within NEAR_FACTOR × τ
NEAR_FACTOR = 10.0
#: the tolerance of a task unless it says otherwise
ATLAS_TOL = 1e-8
#: seconds a run may take (problem assembly and the reference included) before it is stopped
DEFAULT_TIME_LIMIT = 30.0
#: iteration caps for first-order backends at tight tolerances (every study uses these)
ITERATION_CAPS = {"qp-osqp": 20_000, "qp-scs": 20_000}
#: columns that hold numbers (NaN when not measured)
NUMERIC = ("dofs", "candidates", "iterations", "time_s", "kkt_worst", "lam_rel", "u_rel",
           "misclassified", "weak", "misclassified_strict", "weak_penetrating", "a_rel", "p0_rel",
           "pressure_l2_rel", "ref_a_rel", "ref_p0_rel", "ref_pressure_l2_rel", "rho_over_bound",
           "lambda_max", "bound_at_solution", "patch_lam_rel")
#: the "method" of a task that only builds (and diagnoses) its problem
BUILD_ONLY = "(build)"
#: the statuses a run can end with besides :data:`signorini.problem.STATUSES`
EXTRA_STATUSES = ("built", "refused", "input-error", "raised", "timeout", "crashed")


@dataclass(frozen=True)
class Task:
    """One run of the atlas: a method at a tolerance on a problem, and what to compare it with.

    ``expect`` is ``"solve"`` when a right answer exists, ``"refuse"`` when
    the right outcome is an error or a non-converged status (infeasible
    input). ``answer`` says whether answers are compared by ``"lambda"``
    or, where λ is not unique, by ``"displacement"``.
    """

    axis: str
    case: str
    value: float | str
    problem: dict[str, Any]
    method: str
    tol: float | None = ATLAS_TOL
    options: dict[str, Any] = field(default_factory=dict)
    max_iter: int | None = None
    reference: dict[str, Any] = field(default_factory=lambda: {"kind": "pdas"})
    expect: str = "solve"
    answer: str = "lambda"
    measure: tuple[str, ...] = ()

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


class _Cache:
    """Problems and references built in this process, the most recent few kept."""

    def __init__(self, size: int = 4):
        self.size = size
        self.items: dict[str, Any] = {}

    def get(self, key: str, make: Callable[[], Any]) -> Any:
        if key not in self.items:
            value = make()  # may raise: nothing is stored then
            self.items[key] = value
            while len(self.items) > self.size:
                self.items.pop(next(iter(self.items)))
        return self.items[key]


def _key(*parts: Any) -> str:
    return json.dumps(parts, sort_keys=True, default=str)


def _certificate(problem: ContactProblem, solution: ContactSolution):
    """The certificate; without the duality gap when K cannot be factorised."""
    try:
        return certificate(problem, solution)
    except (np.linalg.LinAlgError, ArithmeticError, RuntimeError):
        return certificate(problem, solution, duality_gap=False)


def _own_answer(problem: ContactProblem, task: Task) -> ContactSolution:
    """The method called directly, without the package's wrapper (when the wrapper raised)."""
    try:
        solution = get_method(task.method).function(problem, tol=task.tol, max_iter=task.max_iter,
                                                   **task.options)
    except Exception as exc:
        return ContactSolution.failure(task.method, problem, "failed",
                                       f"{type(exc).__name__}: {exc}")
    return solution


def _hertz(problem: ContactProblem, solution: ContactSolution, prefix: str = "") -> dict[str, float]:
    if problem.reference != "hertz-2d" or not np.all(np.isfinite(solution.lam)):
        return {}
    try:
        h = compare_hertz(problem, solution)
    except Exception:  # an answer too wrong to measure (no contact at all)
        return {}
    return {f"{prefix}a_rel": h.a_rel, f"{prefix}p0_rel": h.p0_rel,
            f"{prefix}pressure_l2_rel": h.pressure_l2_rel}


def _bound_at_solution(problem: ContactProblem, reference: ContactSolution) -> float:
    """``λ_max(W) / λ_max(W_AA)`` with A the exact active set: Uzawa's effective step bound.

    Once the active set has settled, the iteration only sees the block
    ``W_AA``, so steps up to ``2/λ_max(W_AA)`` (≥ ``2/λ_max(W)``) still
    contract; returned as a multiple of the textbook bound ``2/λ_max(W)``.
    """
    W = delassus(problem.N, problem.factor())
    active = active_set(problem, reference)
    if not active.any():
        return float("nan")
    return float(np.linalg.eigvalsh(W)[-1] / np.linalg.eigvalsh(W[np.ix_(active, active)])[-1])


def _force_error(problem: ContactProblem, reference: ContactSolution,
                 solution: ContactSolution) -> float:
    """``‖λ − λ*‖∞ / max(‖λ*‖∞, FORCE_FLOOR ‖f‖∞)``: the force error, judged as the certificate does.

    The floor keeps the measure meaningful when the exact answer has no
    contact force at all (λ* = 0), where a relative difference is 1 for any λ ≠ 0.
    """
    if not np.all(np.isfinite(solution.lam)):
        return float("inf")
    return float(np.max(np.abs(solution.lam - reference.lam), initial=0.0)
                 / force_scale(problem, reference.lam))


def _weak_but_penetrating(problem: ContactProblem, solution: ContactSolution) -> int:
    """Nodes :func:`signorini.kkt.classify` calls weakly active although they penetrate.

    ``classify`` measures the gap as ``(d − Nu)⁺``, so a node with zero force
    that overlaps the obstacle by more than the weak tolerance is labelled
    weak and left out of :func:`signorini.kkt.compare` — a misclassification
    the comparison does not count. The atlas counts it here.
    """
    if not (np.all(np.isfinite(solution.u)) and np.all(np.isfinite(solution.lam))):
        return 0
    labels = classify(problem, solution)
    violation = (problem.N @ solution.u - problem.d) / gap_scale(problem, solution.u)
    return int(np.sum((labels == WEAK) & (violation > WEAK_TOL)))


def run_task(task: Task, cache: _Cache | None = None) -> dict[str, Any]:
    """Run one task in this process and measure it: one row of the atlas."""
    cache = cache or _Cache()
    row: dict[str, Any] = {"axis": task.axis, "case": task.case, "value": task.value,
                           "method": task.method, "tol": task.tol, "expect": task.expect,
                           "options": json.dumps(task.options, sort_keys=True) if task.options else "",
                           "problem": json.dumps(task.problem, sort_keys=True)}
    try:
        problem = cache.get(_key("problem", task.problem), lambda: build_spec(task.problem))
    except InputError as exc:
        row.update(status="input-error", wrapper="input-error", claimed_status="",
                   message=str(exc), scene=task.problem.get("scene", "block"))
        return _verdict(row, task)
    row.update(scene=problem.scene, dofs=problem.n, candidates=problem.m)
    if "diagnosis" in task.measure:
        row["diagnosis"] = " | ".join(diagnose(problem))
    if task.method == BUILD_ONLY:
        row.update(status="built", wrapper="returned", claimed_status="",
                   message="the problem was built: " + (row.get("diagnosis") or "no finding"))
        return _verdict(row, task)

    def make_reference():
        other = None
        if task.reference.get("problem") is not None:
            other = cache.get(_key("problem", task.reference["problem"]),
                              lambda: build_spec(task.reference["problem"]))
        return reference_solution(problem, task.reference, other)

    reference = cache.get(_key("reference", task.problem, task.reference), make_reference)
    if reference is not None:
        row.update(_hertz(problem, reference, "ref_"))
        if "bound" in task.measure:
            row["bound_at_solution"] = cache.get(_key("bound", task.problem),
                                                 lambda: _bound_at_solution(problem, reference))
    start = time.perf_counter()
    wrapper = "returned"
    try:
        solution = solve(problem, task.method, tol=task.tol, max_iter=task.max_iter, **task.options)
    except InputError as exc:
        row.update(status="refused", wrapper="input-error", claimed_status="", message=str(exc),
                   time_s=time.perf_counter() - start)
        return _verdict(row, task)
    except Exception as exc:  # the wrapper gave no status: record it, then ask the method itself
        wrapper = f"raised {type(exc).__name__}: {exc}"
        solution = _own_answer(problem, task)
    elapsed = time.perf_counter() - start
    claimed = solution.own_status
    cert = _certificate(problem, solution)
    worst_name, worst = cert.worst()
    accept = ACCEPT_FACTOR * task.tol if task.tol is not None else DEFAULT_ACCEPT
    row.update(status=solution.status if wrapper == "returned" else "raised",
               claimed_status=claimed, wrapper=wrapper, iterations=solution.iterations,
               time_s=elapsed, kkt_worst=worst, kkt_name=worst_name,
               cert_ok=bool(np.isfinite(worst) and worst <= accept), message=solution.message)
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
        lam_rel = _force_error(problem, reference, solution)
        hidden = _weak_but_penetrating(problem, solution)
        same = vs.misclassified == 0 and hidden == 0
        row.update(lam_rel=lam_rel, u_rel=vs.u_rel, misclassified=vs.misclassified,
                   weak=vs.weak, misclassified_strict=strict.misclassified,
                   weak_penetrating=hidden,
                   exact_ok=bool(same and lam_rel <= min(AGREE_FACTOR * accept, AGREE_CAP)),
                   near_exact=bool(same and lam_rel <= NEAR_FACTOR * accept))
    row.update(_hertz(problem, solution))
    if "patch" in task.measure:
        row["patch_lam_rel"] = compare(problem, force_controlled_exact(problem), solution).lam_rel
    if "profile" in task.measure and np.all(np.isfinite(solution.lam)):
        profile = contact_profile(problem, solution)
        hertz = compare_hertz(problem, solution)
        row["profile"] = {"x": profile.x.tolist(), "pressure": profile.pressure.tolist(),
                          "a_ref": hertz.a_ref, "p0_ref": hertz.p0_ref}
    return _verdict(row, task)


def _verdict(row: dict[str, Any], task: Task) -> dict[str, Any]:
    """Whether the method's claim and the package's status were right; the run's outcome.

    ``exact_ok``: the answer agrees with the exact one (unknown without one: the
    certificate stands in). ``claim_correct``: the method did not claim
    success, or its answer passes the certificate and agrees. ``wrapper_right``:
    ``converged`` only for an answer that agrees, and granted whenever the
    method claimed success and the answer passes and agrees. ``conservative``:
    the certificate turned down a claim whose answer does agree.
    """
    status, claimed = row.get("status"), row.get("claimed_status")
    exact_ok = row.get("exact_ok")
    if exact_ok is None:
        exact_ok = row.get("cert_ok")
    exact_ok = bool(exact_ok) and task.expect == "solve"
    near_exact = bool(row.get("near_exact", exact_ok)) and exact_ok
    cert_ok = bool(row.get("cert_ok"))
    claimed_success = claimed == "converged"
    row["claim_correct"] = (not claimed_success) or (cert_ok and exact_ok)
    row["conservative"] = claimed_success and not cert_ok and near_exact
    if status in ("input-error", "refused", "built", "timeout", "crashed"):
        row["wrapper_right"] = True  # a clear error, or a method that never answered
    elif status == "raised":
        row["wrapper_right"] = False
    elif status == "infeasible" and task.expect == "solve":
        row["wrapper_right"] = False  # "infeasible" for a problem that has a solution
    elif status == "converged":
        row["wrapper_right"] = exact_ok
    else:
        row["wrapper_right"] = not (claimed_success and cert_ok and exact_ok)
    if task.method == BUILD_ONLY:
        flagged = status == "input-error" or bool(row.get("diagnosis"))
        row["outcome"] = "right" if flagged == (task.expect == "refuse") else "wrong"
    elif task.expect == "refuse":
        row["outcome"] = "right" if status not in ("converged", "raised") else "wrong"
    elif status == "converged":
        row["outcome"] = "right" if exact_ok else "wrong"
    elif status == "raised" or not row["wrapper_right"]:
        row["outcome"] = "wrong"
    elif row["conservative"]:
        row["outcome"] = "conservative"  # a right answer the certificate did not accept
    elif claimed_success:
        row["outcome"] = "caught"  # the method claimed success; the certificate said no
    else:
        row["outcome"] = "failed"
    return row


# --- running many tasks: in this process or in a worker with a time limit ------------------------


def serve_worker() -> None:
    """The worker's loop: one JSON task per line on stdin, one JSON row per line back.

    Anything a backend prints goes to stderr; the rows go to a private copy of
    the original stdout.
    """
    channel = os.fdopen(os.dup(1), "w", buffering=1)
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    logging.disable(logging.WARNING)
    cache = _Cache()
    for line in sys.stdin:
        task = Task(**json.loads(line))
        try:
            row = run_task(task, cache)
        except Exception as exc:  # a bug of the atlas itself: one row says so
            row = {"axis": task.axis, "case": task.case, "method": task.method,
                   "status": "crashed", "wrapper": "atlas error", "outcome": "failed",
                   "message": f"atlas error {type(exc).__name__}: {exc}"}
        channel.write(json.dumps(plain(row)) + "\n")


class Worker:
    """A child process that runs tasks, stopped and replaced when one exceeds ``time_limit``."""

    def __init__(self, time_limit: float = DEFAULT_TIME_LIMIT):
        self.time_limit = time_limit
        self._proc: subprocess.Popen | None = None
        self._stderr = None
        self._buffer = b""

    def _start(self) -> None:
        self._stderr = tempfile.TemporaryFile()
        self._proc = subprocess.Popen(
            [sys.executable, "-c", "from signorini.studies.runner import serve_worker; serve_worker()"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self._stderr)
        self._buffer = b""

    def stop(self) -> None:
        """Stop the worker (it is restarted by the next task)."""
        if self._proc is not None:
            if self._proc.poll() is None:
                self._proc.kill()
            self._proc.wait()
            for stream in (self._proc.stdin, self._proc.stdout):
                try:
                    stream.close()
                except OSError:
                    pass
            self._proc = None
        if self._stderr is not None:
            self._stderr.close()
            self._stderr = None

    def _last_error_line(self) -> str:
        if self._stderr is None:
            return ""
        self._stderr.seek(0)
        lines = self._stderr.read().decode(errors="replace").strip().splitlines()
        return lines[-1] if lines else ""

    def run(self, task: Task) -> dict[str, Any]:
        """The row of ``task``, or a ``timeout``/``crashed`` row."""
        if self._proc is None or self._proc.poll() is not None:
            self.stop()
            self._start()
        try:
            self._proc.stdin.write((json.dumps(plain(task.as_dict())) + "\n").encode())
            self._proc.stdin.flush()
        except BrokenPipeError:
            return self._lost(task, "crashed")
        deadline = time.monotonic() + self.time_limit
        fd = self._proc.stdout.fileno()
        while b"\n" not in self._buffer:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return self._lost(task, "timeout")
            ready, _, _ = select.select([fd], [], [], remaining)
            if not ready:
                continue
            chunk = os.read(fd, 1 << 16)
            if not chunk:
                return self._lost(task, "crashed")
            self._buffer += chunk
        line, self._buffer = self._buffer.split(b"\n", 1)
        return json.loads(line)

    def _lost(self, task: Task, status: str) -> dict[str, Any]:
        detail = self._last_error_line() if status == "crashed" else ""
        self.stop()
        message = (f"no answer within {self.time_limit:g} s: the run was stopped"
                   if status == "timeout" else f"the worker process died ({detail or 'no message'})")
        row = {"axis": task.axis, "case": task.case, "value": task.value, "method": task.method,
               "tol": task.tol, "expect": task.expect, "status": status, "claimed_status": "",
               "problem": json.dumps(task.problem, sort_keys=True),
               "options": json.dumps(task.options, sort_keys=True) if task.options else "",
               "wrapper": status, "message": message, "time_s": self.time_limit
               if status == "timeout" else float("nan")}
        return _verdict(row, task)


def _run_here(task: Task, cache: _Cache) -> dict[str, Any]:
    """:func:`run_task` in this process; an error of the atlas itself becomes one row."""
    try:
        return run_task(task, cache)
    except Exception as exc:
        log.exception("the atlas failed on %s / %s", task.case, task.method)
        return _verdict({"axis": task.axis, "case": task.case, "value": task.value,
                         "method": task.method, "tol": task.tol, "status": "crashed",
                         "claimed_status": "", "wrapper": "atlas error",
                         "problem": json.dumps(task.problem, sort_keys=True),
                         "message": f"atlas error {type(exc).__name__}: {exc}"}, task)


def run_tasks(tasks: Sequence[Task], *, isolate: bool = True, time_limit: float = DEFAULT_TIME_LIMIT,
              progress: Callable[[int, int, Task, dict[str, Any]], None] | None = None
              ) -> list[dict[str, Any]]:
    """Run ``tasks`` in order: in a worker process with a time limit, or in this process."""
    rows = []
    worker = Worker(time_limit) if isolate else None
    cache = None if isolate else _Cache()
    try:
        for index, task in enumerate(tasks, start=1):
            row = worker.run(task) if worker is not None else _run_here(task, cache)
            row = {k: (float("nan") if v is None and k in NUMERIC else v) for k, v in row.items()}
            rows.append(row)
            if progress is not None:
                progress(index, len(tasks), task, row)
    finally:
        if worker is not None:
            worker.stop()
    return rows
