"""A worker process for the study runner: tasks in, rows out, a time limit on each.

The child runs :func:`signorini.studies.runner.serve_worker`; a task that
takes longer than the limit, or a child that dies, costs one row and a new child.
Each child leads a process group of its own, killed whole when the child is stopped:
what a method started ends with it. :func:`solve_within` is one solve in a child of its
own (a user's method: its traceback and what it wrote come back to be shown).
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import logging
import os
import select
import signal
import subprocess
import sys
import tempfile
import time
import weakref
from typing import Any

from signorini.errors import InputError
from signorini.files import plain
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.solvers.base import Method
from signorini.solvers import cluster
from signorini.studies.measures import answer_from
from signorini.studies.task import DEFAULT_TIME_LIMIT, Row, Task, task_row, verdict

log = logging.getLogger(__name__)
#: the workers of this process that may have a child running (see :func:`stop_all`)
_LIVE: "weakref.WeakSet[Worker]" = weakref.WeakSet()
#: the most of a task's output kept to be shown (its last bytes)
OUTPUT_KEPT = 1 << 16


def stop_all() -> None:
    """Kill every worker child of this process at once, with its process group (on a signal)."""
    for worker in list(_LIVE):
        worker.stop(grace=0.0)


def die_with_parent() -> None:
    """In a worker: be killed when the parent process dies, however it dies (Linux).

    A parent that died before this took hold closed the worker's input: the
    worker then ends by itself.
    """
    if not sys.platform.startswith("linux"):
        return
    import ctypes

    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG


def descendants(pid: int) -> list[int]:
    """Every living process below ``pid`` (children first), by the parent each names in
    ``/proc`` (Linux; elsewhere none): a method's process that left the group (``setsid``)
    is found too while the worker lives."""
    parents: dict[int, int] = {}
    for entry in os.scandir("/proc") if os.path.isdir("/proc") else ():
        if entry.name.isdigit():
            with contextlib.suppress(OSError, IndexError, ValueError):
                with open(f"/proc/{entry.name}/stat", "rb") as stat:
                    parents[int(entry.name)] = int(stat.read().rsplit(b")", 1)[1].split()[1])
    found, frontier = [], [pid]
    while frontier:
        children = [child for child, parent in parents.items() if parent in frontier]
        found += children
        frontier = children
    return found


class Worker:
    """A child process that runs tasks, stopped and replaced when one exceeds ``time_limit``.

    A ``fresh`` task gets a process of its own (started for it, stopped after
    it); a task with ``ranks`` > 1 a process started by ``mpirun``.
    """

    def __init__(self, time_limit: float = DEFAULT_TIME_LIMIT):
        self.time_limit = time_limit
        self._proc: subprocess.Popen | None = None
        self._stderr = None
        self._buffer = b""
        self._ranks = 1
        self._written = 0
        #: what the last task wrote on stdout and stderr (a method's prints, its warnings)
        self.output = ""

    def _start(self, ranks: int) -> None:
        command = [sys.executable, "-c",
                   "from signorini.studies.runner import serve_worker; serve_worker()"]
        env = None
        if ranks > 1:
            command, env = cluster.mpirun_command(ranks, command)
        self._stderr = tempfile.TemporaryFile()
        # a session of its own: stopping it stops mpirun's ranks too
        self._proc = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                      stderr=self._stderr, env=env, start_new_session=True)
        self._buffer = b""
        self._ranks = ranks
        _LIVE.add(self)

    def stop(self, grace: float = 10.0) -> None:
        """Stop the worker (it is restarted by the next task): end of input, then a kill."""
        _LIVE.discard(self)
        if self._proc is not None:
            # what a method started and moved out of the group (setsid), found while the worker
            # lives and its descendants are still known as such; the group is killed below
            for pid in descendants(self._proc.pid):
                with contextlib.suppress(ProcessLookupError, PermissionError):
                    if os.getpgid(pid) != self._proc.pid:
                        os.kill(pid, signal.SIGKILL)
            with contextlib.suppress(OSError, subprocess.TimeoutExpired):
                self._proc.stdin.close()
                if grace > 0:
                    self._proc.wait(timeout=grace)
            # the whole process group, also when the worker ended by itself: what a method
            # started (a forked child, a shell) ends with it
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(self._proc.pid, signal.SIGKILL)
            self._proc.wait()
            with contextlib.suppress(OSError):
                self._proc.stdout.close()
            self._proc = None
        if self._stderr is not None:
            self._stderr.close()
            self._stderr = None

    def _written_since(self, start: int) -> str:
        """What the child wrote from byte ``start`` on (read without moving the offset the
        child writes at)."""
        if self._stderr is None:
            return ""
        fd = self._stderr.fileno()
        size = os.fstat(fd).st_size
        start = max(start, size - OUTPUT_KEPT)
        return os.pread(fd, size - start, start).decode(errors="replace") if size > start else ""

    def _last_error_line(self) -> str:
        lines = self._written_since(0).strip().splitlines()
        return lines[-1] if lines else ""

    def _task_output(self) -> None:
        self.output = self._written_since(self._written)

    def run(self, task: Task) -> Row:
        """The row of ``task``, or a ``timeout``/``crashed`` row.

        Interrupted (a signal, Ctrl-C), the child is killed before the
        interruption goes on.
        """
        try:
            return self._run(task)
        except BaseException:
            self.stop(grace=0.0)
            raise

    def _run(self, task: Task) -> Row:
        alive = self._proc is not None and self._proc.poll() is None
        if task.fresh or task.ranks != self._ranks or not alive:
            self.stop()
            try:
                self._start(task.ranks)
            except InputError as exc:  # no mpirun, or more ranks than cores
                return self._lost(task, "input-error", str(exc))
        self._written = os.fstat(self._stderr.fileno()).st_size
        try:
            self._proc.stdin.write((json.dumps(plain(task.as_dict())) + "\n").encode())
            self._proc.stdin.flush()
        except BrokenPipeError:
            return self._lost(task, "crashed")
        deadline = time.monotonic() + self.time_limit
        fd = self._proc.stdout.fileno()
        while True:
            while b"\n" not in self._buffer:
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return self._lost(task, "timeout")
                # at most a day per wait: select takes no timeout past the platform's time_t
                ready, _, _ = select.select([fd], [], [], min(remaining, 86400.0))
                if not ready:
                    continue
                chunk = os.read(fd, 1 << 16)
                if not chunk:
                    return self._lost(task, "crashed")
                self._buffer += chunk
            line, self._buffer = self._buffer.split(b"\n", 1)
            try:
                row = json.loads(line)
            except ValueError:  # not a row: something else printed under mpirun
                log.debug("worker output: %s", line[:200])
                continue
            self._task_output()
            if task.fresh:
                self.stop()
            return row

    def _lost(self, task: Task, status: str, message: str = "") -> Row:
        detail = self._last_error_line() if status == "crashed" else ""
        if self._stderr is not None:
            self._task_output()
        self.stop(grace=0.0)
        if not message:
            message = (f"no answer within {self.time_limit:g} s: the run was stopped"
                       if status == "timeout" else
                       f"the worker process died ({detail or 'no message'})")
        row = Row(**task_row(task), status=status, claimed_status="", wrapper=status,
                  message=message,
                  time_s=self.time_limit if status == "timeout" else float("nan"))
        return verdict(row, task)


def solve_within(problem: ContactProblem, spec: dict[str, Any], method: str, time_limit: float, *,
                 tol: float | None = None, max_iter: int | None = None,
                 options: dict[str, Any] | None = None) -> ContactSolution:
    """One solve in a worker process of its own, stopped after ``time_limit`` seconds.

    ``spec`` describes ``problem`` (:func:`~signorini.studies.problems.build_spec`)
    so that the worker can build it again. Returns the package's answer, judged
    in the worker, or a ``failed`` solution saying that the run was stopped or
    that the worker died (a method that hangs or ends the process costs its
    limit, not the run); InputError when the worker refused the input.
    """
    task = Task(axis="solve", case=str(spec.get("scene", spec["kind"])), value="", problem=spec,
                method=method, tol=tol, max_iter=max_iter, options=dict(options or {}),
                reference={"kind": "none"}, measure=("answer",), fresh=True)
    worker = Worker(time_limit)
    row = worker.run(task)
    if row.get("wrapper") == "input-error":
        raise InputError(row.get("message", "the worker refused the input"))
    solution = answer_from(row["answer"]) if "answer" in row else ContactSolution.failure(
        method, problem, "failed", row.get("message") or f"the run ended {row.get('status')}")
    if "traceback" in solution.extras:  # shown with -v, as for a method run in this process
        log.info("the traceback of method %s:\n%s", method, solution.extras["traceback"])
    if worker.output.strip():  # what the method printed: shown when it failed, else with -v
        log.log(logging.INFO if solution.status == "converged" else logging.WARNING,
                "method %s wrote:\n%s", method, worker.output.rstrip())
    return solution


def in_worker(method: Method, time_limit: float = float("inf")) -> Method:
    """``method`` run in a worker process of its own on a stored copy of each problem.

    Whatever the method does to its process (ends it, closes stdout, prints,
    changes the working folder) costs its run only: the answer is then a
    ``failed`` solution saying so.
    """
    def function(problem: ContactProblem, *, tol: float | None = None,
                 max_iter: int | None = None, **options: Any) -> ContactSolution:
        with tempfile.TemporaryDirectory(prefix="signorini-") as folder:
            path = os.path.join(folder, "problem.npz")
            problem.save(path)
            solution = solve_within(problem, {"kind": "stored", "path": path}, method.name,
                                    time_limit, tol=tol, max_iter=max_iter, options=options)
        for said in ("push", "certificate"):  # the problem is matched, and the caller certifies
            solution.extras.pop(said, None)
        return solution

    return dataclasses.replace(method, function=function)


__all__ = ["OUTPUT_KEPT", "Worker", "descendants", "die_with_parent", "in_worker", "solve_within", "stop_all"]
