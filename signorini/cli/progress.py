"""Progress on a terminal: the step the library is on, once it has taken longer than a second.

The library only logs (each long step logs an INFO line as it starts, e.g. "assembling
…", "solving … with pdas"); this handler, installed by the command line alone, shows the
latest such line with a spinner and its elapsed time on stderr, through rich. Nothing is shown
while a step is shorter than :data:`SHOW_AFTER`, when stderr is not a terminal, or with ``-q``
or ``-v`` (``-v`` prints the log lines themselves). The line is erased when the command ends.
"""

from __future__ import annotations

import contextlib
import logging
import sys
import time
from typing import Callable, Iterator, TextIO

#: seconds a step runs before the progress line appears
SHOW_AFTER = 1.0


class StepProgress(logging.Handler):
    """Remembers the library's latest INFO message and when it came: the step in progress."""

    def __init__(self, show_after: float = SHOW_AFTER, clock: Callable[[], float] = time.monotonic):
        super().__init__(level=logging.INFO)
        self.show_after, self.clock = show_after, clock
        self.step: str | None = None
        self.started = clock()

    def emit(self, record: logging.LogRecord) -> None:
        self.step, self.started = record.getMessage(), self.clock()

    def line(self) -> str:
        """What the terminal shows now: empty until the current step has run ``show_after`` s."""
        elapsed = self.clock() - self.started
        if self.step is None or elapsed < self.show_after:
            return ""
        return f"{self.step} ({elapsed:.0f} s)"

    def renderable(self):
        from rich.spinner import Spinner  # rich: only on a terminal
        from rich.text import Text

        text = self.line()
        return Spinner("dots", Text(text)) if text else Text("")


def wanted(stream: TextIO, quiet: bool, verbose: bool) -> bool:
    """Progress only on a terminal, and neither with -q nor with -v."""
    isatty = getattr(stream, "isatty", None)
    return not (quiet or verbose) and bool(isatty and isatty())


@contextlib.contextmanager
def progress(quiet: bool = False, verbose: bool = False, stream: TextIO | None = None,
             handler: StepProgress | None = None) -> Iterator[StepProgress | None]:
    """While the block runs, show the library's step in progress on ``stream`` (default stderr)
    when :func:`wanted`; yields the handler, or None when nothing is shown."""
    stream = sys.stderr if stream is None else stream
    if not wanted(stream, quiet, verbose):
        yield None
        return
    from rich.console import Console  # rich: only on a terminal
    from rich.live import Live

    handler = handler or StepProgress()
    logger = logging.getLogger("signorini")
    level = logger.level
    logger.addHandler(handler)
    logger.setLevel(logging.INFO)
    live = Live(console=Console(file=stream), transient=True, refresh_per_second=4,
                redirect_stdout=False, redirect_stderr=False, get_renderable=handler.renderable)
    try:
        with live:
            yield handler
    finally:
        logger.removeHandler(handler)
        logger.setLevel(level)


__all__ = ["StepProgress", "wanted", "progress"]
