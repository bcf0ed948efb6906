"""The stability atlas: where each method fails, and whether the package says so.

Each **axis** sweeps one thing — Uzawa's step, the mesh, the tolerance, the
units, Poisson's ratio, a singular K, degenerate contact, ill-posed input —
and runs every installed method at each point, through the one study runner
(:mod:`signorini.studies.runner`, which measures and judges each run into a
row: the method's own word, the package's status, the certificate, the
distance from the exact answer; a backend that hangs or crashes costs one row).

Layout: one module per axis, each holding its constants, tasks, findings (the
report's lines and docs/results.md's paragraph), table, figure, advice and set-up,
and ending in ``AXIS``
(:class:`~signorini.studies.atlas.axis.Axis`):

========================================  ==========================================
:mod:`~signorini.studies.atlas.step`        1. Uzawa's step ρ
:mod:`~signorini.studies.atlas.mesh`        2. mesh refinement
:mod:`~signorini.studies.atlas.tolerance`   3. solver tolerance
:mod:`~signorini.studies.atlas.units`       4. units and scaling
:mod:`~signorini.studies.atlas.poisson`     5. near-incompressibility
:mod:`~signorini.studies.atlas.force`       6. a body held only by contact
:mod:`~signorini.studies.atlas.degenerate`  7. degenerate contact
:mod:`~signorini.studies.atlas.ill_posed`   8. infeasible and ill-posed input
========================================  ==========================================

:mod:`~signorini.studies.atlas.summary` sums the rows up (per method, the
package's record, method × axis), :mod:`~signorini.studies.atlas.report`
writes ``stability.md`` with the runs and figures,
:mod:`~signorini.studies.atlas.findings` holds what the axes' paragraphs share
and writes docs/results.md's findings, and
:mod:`~signorini.studies.atlas.figures` draws the plots the axes share.
This module collects :data:`AXES` and runs them (:func:`run_atlas`).
"""

from __future__ import annotations

import logging
import math
import time
from typing import Any, Callable, Iterable, Sequence

from signorini.errors import InputError
from signorini.solvers import registry
from signorini.studies.atlas import degenerate, force, ill_posed, mesh, poisson, step, tolerance, units
from signorini.studies.atlas.axis import Axis
from signorini.studies.atlas.report import report_markdown, reproduction, write_report
from signorini.studies.atlas.summary import AtlasResult, method_summary, verdicts, wrapper_record
from signorini.studies.runner import run_tasks
from signorini.studies.task import DEFAULT_TIME_LIMIT, Task

__all__ = ["AXES", "QUICK_METHODS", "AtlasResult", "Axis", "atlas_methods", "method_summary",
           "report_markdown", "reproduction", "run_atlas", "select_axes", "verdicts", "wrapper_record",
           "write_report"]

log = logging.getLogger(__name__)

#: methods of a --quick atlas
QUICK_METHODS = ("pdas", "uzawa", "qp-osqp", "qp-clarabel")

#: the axes, in the order they run and are reported
AXES: tuple[Axis, ...] = tuple(module.AXIS for module in (step, mesh, tolerance, units, poisson,
                                                          force, degenerate, ill_posed))


def atlas_methods(quick: bool = False) -> list[str]:
    """Installed methods, exact ones first; a quick atlas takes :data:`QUICK_METHODS`."""
    order = {"active set": 0, "dual": 1, "qp": 2, "cvxpy": 3}
    found = sorted((m for m in registry.methods(installed_only=True) if m.family != "user"),
                   key=lambda m: (order.get(m.family, 4), m.name))
    names = [m.name for m in found]
    return [n for n in names if n in QUICK_METHODS] if quick else names


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
