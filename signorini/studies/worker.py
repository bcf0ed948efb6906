"""A worker process for the study runner: tasks in, rows out, a time limit on each.

The child runs :func:`signorini.studies.runner.serve_worker`; a task that
takes longer than the limit, or a child that dies, costs one row and a new child.
"""

from __future__ import annotations

import contextlib
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

from signorini.errors import InputError
from signorini.files import plain
from signorini.solvers import cluster
from signorini.studies.task import DEFAULT_TIME_LIMIT, Row, Task, task_row, verdict

log = logging.getLogger(__name__)
#: the workers of this process that may have a child running (see :func:`stop_all`)
_LIVE: "weakref.WeakSet[Worker]" = weakref.WeakSet()


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
            try:
                self._proc.stdin.close()
                if grace > 0:
                    self._proc.wait(timeout=grace)
            except (OSError, subprocess.TimeoutExpired):
                pass
            if self._proc.poll() is None:
                try:
                    os.killpg(self._proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
            self._proc.wait()
            try:
                self._proc.stdout.close()
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
                ready, _, _ = select.select([fd], [], [], None if remaining == float("inf")
                                            else remaining)
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
            if task.fresh:
                self.stop()
            return row

    def _lost(self, task: Task, status: str, message: str = "") -> Row:
        detail = self._last_error_line() if status == "crashed" else ""
        self.stop(grace=0.0)
        if not message:
            message = (f"no answer within {self.time_limit:g} s: the run was stopped"
                       if status == "timeout" else
                       f"the worker process died ({detail or 'no message'})")
        row = Row(**task_row(task), status=status, claimed_status="", wrapper=status,
                  message=message,
                  time_s=self.time_limit if status == "timeout" else float("nan"))
        return verdict(row, task)
