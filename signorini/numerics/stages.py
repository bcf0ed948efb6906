"""The stages of a solve and their wall time: a solve record's ``time``.

:func:`timed` adds a block's wall time to a stage of a ``{stage: seconds}`` dict
(``solution.seconds``), so that the stages of one solve sum to its wall time; the work each
stage did is counted apart (:class:`signorini.numerics.factor.Work`).
"""

from __future__ import annotations

import time
from contextlib import contextmanager
from typing import Iterator


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


__all__ = ["STAGES", "stage_key", "stage_times", "time_line", "timed"]
