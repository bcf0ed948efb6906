"""Work as data: what a stage of a solve did, counted (tests count work instead of timing it).

A :class:`Work` record counts factorisations, back-solves (one per right-hand
side), multigrid hierarchies built, CG solves and iterations, and active-set
steps of load control. A stage opens one with :func:`counting`; the numerics
add to every record open in the current context (:func:`count`), so a stage
inside another counts into both. The open records live in a
:class:`contextvars.ContextVar`, which is per thread and per task: two solves
running side by side never see each other's work, and outside any
``counting`` block nothing is kept.

>>> with counting() as work:
...     count("back_solves", 2)
>>> work.as_dict()
{'back_solves': 2}
"""

from __future__ import annotations

from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import asdict, dataclass
from typing import Iterator


@dataclass
class Work:
    """The work of one stage: every count starts at zero."""

    factorisations: int = 0
    back_solves: int = 0
    hierarchies: int = 0
    cg_solves: int = 0
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


__all__ = ["Work", "count", "counting"]
