"""What an axis of the atlas is, and the helpers its axes share.

An :class:`Axis` carries everything about one sweep: the question it asks,
its tasks, the sentences, table and figure that report its rows, what to do
about it and how it was set up. Each axis is one module of this package
(:mod:`~signorini.studies.atlas.step`, :mod:`~signorini.studies.atlas.mesh`,
…) ending in ``AXIS = Axis(...)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
from matplotlib.figure import Figure

from signorini.reprs import markdown_table
from signorini.studies.runner import ITERATION_CAPS
from signorini.studies.task import ATLAS_TOL, Task

#: rows of one axis (as :func:`signorini.studies.runner.run_task` writes them)
Rows = list[dict[str, Any]]

#: the small Hertz mesh of a quick atlas (and of the mesh axis's coarsest level)
TINY_HERTZ = {"n_contact": 8, "grading": 0.5}


def _every_run(row: dict[str, Any]) -> bool:
    return True


@dataclass(frozen=True)
class Axis:
    """One sweep of the atlas: its tasks, what it asks and how it is reported.

    Attributes
    ----------
    number, name, title, question : how the report names the axis and what it asks.
    setup : the set-up in words (the report adds the count of runs and the time).
    advice : what to do, in words.
    legend : what a cell of its table shows.
    tasks : ``(quick, methods) → tasks``, in the order they run.
    findings : ``rows → sentences``.
    table : ``rows → Markdown lines``.
    figure : ``rows → Figure``.
    counts : ``row → bool``: whether a run counts for the method × axis verdict.
    headline : ``rows → paragraph``: the axis's finding as docs/results.md states it
        (:func:`signorini.studies.atlas.findings.findings`).
    caps : iteration caps the axis's tasks use instead of :data:`ITERATION_CAPS`.
    """

    number: int
    name: str
    title: str
    question: str
    setup: str
    advice: str
    legend: str
    tasks: Callable[[bool, list[str]], list[Task]]
    findings: Callable[[Rows], list[str]]
    table: Callable[[Rows], list[str]]
    figure: Callable[[Rows], Figure]
    counts: Callable[[dict[str, Any]], bool] = _every_run
    caps: dict[str, int] | None = field(default=None, compare=False)
    headline: Callable[[Rows], str] | None = None

    @property
    def figure_name(self) -> str:
        """The file name of the axis's figure."""
        return f"axis{self.number}-{self.name}.png"

    def rows(self, rows: Rows) -> Rows:
        """The rows of this axis."""
        return [r for r in rows if r["axis"] == self.name]

    def max_iter(self, method: str, tol: float | None) -> int | None:
        """The iteration cap a task of this axis gives ``method`` at ``tol``."""
        return self.caps.get(method) if self.caps is not None else capped(method, tol)


# --- tasks ---------------------------------------------------------------------------------------


def scene_spec(scene: str, params: dict[str, Any] | None = None, *, nondimensionalise: bool = True,
               cold: bool = False) -> dict[str, Any]:
    """The problem spec of a scene of the package (:func:`signorini.studies.problems.build_spec`).

    ``params`` are the scene's parameters by name. ``cold`` drops what load targeting learnt
    (its answer, its zone), so that a method starts from nothing and its own iterations are
    measured.
    """
    return {"kind": "scene", "scene": scene, "params": dict(params or {}),
            "nondimensionalise": nondimensionalise, "cold": cold}


def capped(method: str, tol: float | None) -> int | None:
    """:data:`ITERATION_CAPS` of ``method`` when a tolerance is asked for."""
    return ITERATION_CAPS.get(method) if tol is not None else None


def every_method(axis: str, case: str, value: Any, problem: dict[str, Any], methods: list[str],
                 **extra: Any) -> list[Task]:
    """One task per method on ``problem`` (at :data:`ATLAS_TOL` unless ``tol`` is given)."""
    tol = extra.pop("tol", ATLAS_TOL)
    return [Task(axis, case, value, problem, method, tol=tol, max_iter=capped(method, tol), **extra)
            for method in methods]


# --- words and tables ----------------------------------------------------------------------------

#: statuses as a table cell shows them
SHORT = {"converged": "conv", "inaccurate": "inacc", "max_iter": "max_it", "diverged": "div",
         "infeasible": "infeas", "failed": "fail", "refused": "n/a", "input-error": "error",
         "raised": "RAISED", "timeout": "timeout", "crashed": "crash", "built": "built"}


def num(value: Any, digits: int = 1) -> str:
    """A number for the report: ``–`` when missing, integers with separators, else ``1.0e-03``."""
    if value is None or (isinstance(value, float) and not np.isfinite(value)):
        return "–"
    if isinstance(value, (int, np.integer)) or (isinstance(value, float) and value.is_integer()
                                                 and abs(value) < 1e6 and digits == 0):
        return f"{int(value):,}"
    return f"{value:.{digits}e}"


def plural(count: float, noun: str) -> str:
    """``1 node``, ``3 nodes``, ``– nodes``."""
    if not np.isfinite(count):
        return f"– {noun}s"
    return f"{count:.0f} {noun}{'' if count == 1 else 's'}"


def cell(row: dict[str, Any] | None, detail: str = "") -> str:
    """Status, ``*`` for a false claim the package caught, ``°`` for a right answer it turned
    down, ``!`` where the package's status was wrong; then ``detail``."""
    if row is None:
        return ""
    text = SHORT.get(row["status"], row["status"])
    if row.get("outcome") == "caught":
        text += "*"
    if row.get("conservative"):
        text += "°"
    if not row.get("wrapper_right", True):
        text += "!"
    return f"{text} {detail}".strip()


def pivot(rows: Rows, row_key: str, col_key: str, show: Callable[[dict[str, Any]], str],
          corner: str = "", col_label: Callable[[Any], str] = str) -> list[str]:
    """A Markdown table: one line per value of ``row_key``, one column per value of ``col_key``."""
    row_values = list(dict.fromkeys(r[row_key] for r in rows))
    col_values = list(dict.fromkeys(r[col_key] for r in rows))
    index = {(r[row_key], r[col_key]): r for r in rows}
    return markdown_table([corner, *map(col_label, col_values)], "l" * (len(col_values) + 1),
                          ([value, *(show(index[value, c]) if (value, c) in index else ""
                                     for c in col_values)] for value in row_values))


def wrong_nodes(row: dict[str, Any]) -> float:
    """Misclassified nodes, counting those the package labels weak although they penetrate."""
    values = [row.get("misclassified"), row.get("weak_penetrating")]
    values = [v for v in values if isinstance(v, (int, float)) and np.isfinite(v)]
    return float(sum(values)) if values else float("nan")


def nodes_text(row: dict[str, Any]) -> str:
    """Misclassified nodes, and ``+kp`` for k more with zero force that penetrate."""
    hidden = row.get("weak_penetrating")
    text = num(row.get("misclassified"), 0)
    if isinstance(hidden, (int, float)) and np.isfinite(hidden) and hidden > 0:
        text += f"+{hidden:.0f}p"
    return text


__all__ = ["Axis", "scene_spec", "capped", "every_method", "num", "plural", "cell", "pivot",
           "wrong_nodes", "nodes_text", "Rows", "TINY_HERTZ", "SHORT"]
