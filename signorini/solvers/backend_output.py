"""What some QP backends print from C whatever their verbosity, sent nowhere: the library never prints."""

from __future__ import annotations

import contextlib
import ctypes
import functools
import os
import sys

__all__ = ["c_output_discarded", "silence_highs_banner"]


@contextlib.contextmanager
def c_output_discarded():
    """The process's stdout and stderr sent nowhere, at the file descriptors and in Python: for
    backends that print whatever their verbosity, from C or through Python's ``sys.stdout``
    (HiGHS's banner; OSQP's "Polishing not needed")."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    sink = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(sink, 1)
        os.dup2(sink, 2)
        with open(os.devnull, "w") as nowhere, contextlib.redirect_stdout(nowhere), \
                contextlib.redirect_stderr(nowhere):
            yield
    finally:
        ctypes.CDLL(None).fflush(None)  # what C buffered goes where it was meant to: nowhere
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in saved + [sink]:
            os.close(fd)


@functools.cache
def silence_highs_banner() -> None:
    """HiGHS prints its banner from C on the first ``Highs()`` of a process, whatever the
    options (highspy 1.16): make that first one with the process's output sent nowhere."""
    import highspy

    with c_output_discarded():
        highspy.Highs()
