"""Work as data: what a stage of a solve did, counted (tests count work instead of timing it).

A :class:`Work` record counts factorisations, back-solves (one per right-hand side), multigrid
hierarchies built, CG iterations and active-set steps of load control. A stage opens one with
:func:`counting`; the numerics add to every record open in the current context
(:func:`count`), so a stage inside another counts into both. The open records live in a
:class:`contextvars.ContextVar` (per thread and per task): two solves side by side never see
each other's work, and outside any ``counting`` block nothing is kept.

>>> with counting() as work:
...     count("back_solves", 2)
>>> work.as_dict()
{'back_solves': 2}

Time is the other record a solve carries: :func:`timed` adds a block's wall time to a stage
of a ``{stage: seconds}`` dict (``solution.seconds``), so the stages of one solve sum to its
wall time.
"""

from __future__ import annotations

import time
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import asdict, dataclass
from typing import Iterator

import numpy as np


@dataclass
class Work:
    """The work of one stage: every count starts at zero."""

    factorisations: int = 0
    back_solves: int = 0
    hierarchies: int = 0
    cg_iterations: int = 0
    load_steps: int = 0

    def as_dict(self) -> dict[str, int]:
        """The counts that are not zero, by name."""
        return {name: value for name, value in asdict(self).items() if value}

    def listed(self, steps: int | None = None) -> dict[str, int]:
        """The stage as ``solution.work`` lists it: its ``steps`` (given, else load control's
        active-set steps when there were any), factorisations, back-solves, CG iterations and
        hierarchies, the zero counts left out."""
        counts = {"factorisations": self.factorisations, "back_solves": self.back_solves,
                  "cg_iterations": self.cg_iterations, "hierarchies": self.hierarchies}
        listed = {key: value for key, value in counts.items() if value}
        if steps is None and not self.load_steps:
            return listed
        return {"steps": self.load_steps if steps is None else steps, **listed}


_OPEN: ContextVar[tuple[Work, ...]] = ContextVar("signorini_work", default=())


@contextmanager
def counting() -> Iterator[Work]:
    """A new :class:`Work` record that counts what the block does (and its inner stages)."""
    work = Work()
    token = _OPEN.set(_OPEN.get() + (work,))
    try:
        yield work
    finally:
        _OPEN.reset(token)


def count(kind: str, amount: int = 1) -> None:
    """Add ``amount`` of ``kind`` (a field of :class:`Work`) to every record open here."""
    for work in _OPEN.get():
        setattr(work, kind, getattr(work, kind) + amount)


def count_solves(b: np.ndarray) -> np.ndarray:
    """``b`` as floats, its right-hand sides (one, or its columns) counted as back-solves."""
    b = np.asarray(b, dtype=float)
    count("back_solves", 1 if b.ndim == 1 else b.shape[1])
    return b


#: the stages of a solve, in the order they run (the solve record's ``time``); ``startup`` is the
#: command's process before it builds the scene (interpreter, imports, parsing): 0 in a library call
STAGES = ("startup", "mesh", "assemble", "load control", "prediction", "method", "certificate",
          "estimate", "output")


def stage_key(stage: str) -> str:
    """The record's key of a stage's seconds: ``load_control_s``."""
    return f"{stage.replace(' ', '_')}_s"


def stage_times(seconds: dict[str, float]) -> dict[str, float]:
    """Every stage of :data:`STAGES` by its key (0 for one that did not run) and their sum,
    ``total_s``."""
    stages = {stage_key(stage): seconds.get(stage, 0.0) for stage in STAGES}
    return {**stages, "total_s": sum(stages.values())}


def time_line(times: dict[str, float], parts: int = 3) -> str:
    """``time 0.31 s: mesh 0.23, method 0.03, assemble 0.02``: the total of :func:`stage_times`
    and its ``parts`` largest stages."""
    largest = sorted(((times.get(stage_key(stage), 0.0), stage) for stage in STAGES),
                     reverse=True)[:parts]
    return f"time {times['total_s']:.2f} s: " + ", ".join(f"{stage} {s:.2f}" for s, stage in largest)


@contextmanager
def timed(seconds: dict[str, float], stage: str) -> Iterator[None]:
    """Add the wall time of the block to ``seconds[stage]`` (seconds, :func:`time.perf_counter`)."""
    start = time.perf_counter()
    try:
        yield
    finally:
        seconds[stage] = seconds.get(stage, 0.0) + time.perf_counter() - start


__all__ = ["STAGES", "Work", "count", "count_solves", "counting", "stage_key", "stage_times", "time_line",
           "timed"]
