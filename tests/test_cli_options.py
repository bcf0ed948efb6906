"""The command line's conventions: --version, -v and -q on either side of the command, and the
progress line on a terminal (the library's step, after a second, on stderr only)."""

from __future__ import annotations

import io
import logging

import pytest

import signorini
from signorini.cli import build_parser, main
from signorini.cli.progress import StepProgress, progress, wanted


class FakeTerminal(io.StringIO):
    def isatty(self) -> bool:
        return True


class Clock:
    def __init__(self):
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def test_version_is_the_packages(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.split() == ["signorini", signorini.__version__]


@pytest.mark.parametrize("argv", [["-v", "solve", "block"], ["solve", "block", "-v"],
                                  ["solve", "-v", "block"], ["--verbose", "methods"],
                                  ["methods", "--verbose"]])
def test_verbose_before_or_after_the_command(argv):
    args = build_parser().parse_args(argv)
    assert args.verbose is True and args.quiet is False


@pytest.mark.parametrize("argv", [["-q", "solve", "block"], ["solve", "block", "-q"],
                                  ["scenes", "--quiet"], ["crosscheck", "block", "-q"]])
def test_quiet_before_or_after_the_command(argv):
    args = build_parser().parse_args(argv)
    assert args.quiet is True and args.verbose is False


@pytest.mark.parametrize("argv", [["solve", "block"], ["methods"]])
def test_neither_by_default(argv):
    args = build_parser().parse_args(argv)
    assert args.quiet is False and args.verbose is False


def test_verbose_and_quiet_together_are_refused(capsys):
    assert main(["-v", "methods", "-q"]) == 2
    err = capsys.readouterr().err
    assert "-v" in err and "-q" in err and len(err.strip().splitlines()) == 1


def test_both_are_in_the_commands_help(capsys):
    with pytest.raises(SystemExit):
        main(["solve", "--help"])
    out = capsys.readouterr().out
    assert "--verbose" in out and "--quiet" in out


@pytest.mark.parametrize("stream, quiet, verbose, shown", [
    (FakeTerminal(), False, False, True), (io.StringIO(), False, False, False),
    (FakeTerminal(), True, False, False), (FakeTerminal(), False, True, False)])
def test_progress_only_on_a_terminal_without_q_or_v(stream, quiet, verbose, shown):
    assert wanted(stream, quiet, verbose) is shown
    with progress(quiet=quiet, verbose=verbose, stream=stream) as handler:
        assert (handler is not None) is shown
        if shown:
            assert handler in logging.getLogger("signorini").handlers
    assert not any(isinstance(h, StepProgress) for h in logging.getLogger("signorini").handlers)


def test_the_progress_line_follows_the_librarys_steps_after_a_second():
    clock = Clock()
    handler = StepProgress(show_after=1.0, clock=clock)
    with progress(stream=FakeTerminal(), handler=handler):
        signorini.solve("block", params={"nx": 4, "ny": 4})
        assert handler.step is not None  # the library's last step, logged as it started
        assert handler.line() == ""  # no time has passed on this clock: nothing shown
        clock.now += 2.5
        assert handler.line().startswith(handler.step) and handler.line().endswith("(2 s)")
    seen = []
    handler.emit = lambda record: seen.append(record.getMessage())
    signorini.solve("block", params={"nx": 4, "ny": 4})
    assert seen == []  # removed when the block ends


def test_the_library_logs_where_its_long_steps_start(caplog):
    with caplog.at_level(logging.INFO, logger="signorini"):
        signorini.solve("hertz-cylinder", params={"n_contact": 10})
    messages = [r.getMessage() for r in caplog.records]
    starts = ("meshing hertz-cylinder", "assembling K", "matching the target load",
              "factorising K", "solving", "pdas step 1", "checking")
    first = [next((i for i, m in enumerate(messages) if m.startswith(s)), None) for s in starts]
    assert None not in first, (dict(zip(starts, first)), messages)
    assert first[:3] == sorted(first[:3]) and first[-1] == max(first), messages  # in this order


def test_pdas_amg_logs_each_active_set_step(caplog):
    with caplog.at_level(logging.INFO, logger="signorini"):
        result = signorini.solve("hertz-cylinder", method="pdas-amg", params={"n_contact": 10})
    steps = [r.getMessage() for r in caplog.records if r.getMessage().startswith("pdas-amg step")]
    assert len(steps) == result.iterations >= 1, steps
