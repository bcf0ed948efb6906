"""The explorer's latency: one slider move of each lesson, timed in process.

    .venv/bin/python tools/lesson_latency.py      # ~30 s; prints a Markdown table

A move is one call of the lesson's function at a value the slider can take (what the app runs
on release, before drawing), then its figure drawn and written as the page's PNG; each is the
median of ``REPEAT`` moves across the slider's range, after one warm-up move (imports, the
bogie's pdas answer, the race's cylinder, the prices' energy curve). The browser's round trip
(websocket, image decode) comes on top. docs/tutorials.md quotes the table.
"""

from __future__ import annotations

import statistics
import time

from signorini.output import lessons
from signorini.output.lesson_figures import hertz_figure, prices_figure, race_figure, uzawa_figure
from signorini.output.lesson_html import figure_image

REPEAT = 5

#: (lesson, its slider's values, the lesson's function of one value, its figure)
MOVES = (
    ("Uzawa on the bogie (ρ below the bound)", [0.1, 0.15, 0.2, 0.22, 0.24],
     lessons.uzawa_lesson, uzawa_figure),
    ("Uzawa on the bogie (ρ past the bound)", [0.26, 0.28, 0.3, 0.33, 0.36],
     lessons.uzawa_lesson, uzawa_figure),
    ("Hertz live (load P)", [0.002, 0.004, 0.008, 0.012, 0.016],
     lessons.hertz_lesson, hertz_figure),
    ("Prices (gap d₂)", [-0.1, 0.3, 0.8, 1.5, 2.2], lessons.prices_lesson, prices_figure),
    ("Methods race (pdas, uzawa, qp-clarabel, qp-osqp; tolerance)", [1e-6, 1e-7, 1e-8, 1e-9, 1e-10],
     lambda tol: lessons.race_lesson(["pdas", "uzawa", "qp-clarabel", "qp-osqp"], tol), race_figure),
)


def timed(function, figure, value) -> tuple[float, float, float]:
    """Seconds to solve at ``value``, to draw and encode its figure, and the CPU seconds of both
    (the work, less sensitive than the wall time to other processes on the machine)."""
    start, cpu = time.perf_counter(), time.process_time()
    lesson = function(value)
    solved = time.perf_counter()
    figure_image(figure(lesson), "move", "move")
    return solved - start, time.perf_counter() - solved, time.process_time() - cpu


def main() -> None:
    print("| lesson: one slider move | solve | figure | CPU of both |")
    print("| --- | ---: | ---: | ---: |")
    for label, values, function, figure in MOVES:
        timed(function, figure, values[0])
        runs = [timed(function, figure, value) for value in values[:REPEAT]]
        solve, draw, cpu = (statistics.median(r[k] for r in runs) for k in range(3))
        print(f"| {label} | {solve:.3f} s | {draw:.3f} s | {cpu:.3f} s |")


if __name__ == "__main__":
    main()
