"""What every command shares: the parser that fails in one line, ``key=value`` pairs, exits."""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
import textwrap
import time
from typing import Any, Iterator, Sequence

from signorini.errors import DOCS_SITE, InputError

EXIT_FAILED, EXIT_USAGE = 1, 2
#: what a problem file is, in every command's help
PROBLEM_FILES = ".npz (save's or plain) or Matrix Market (the documentation's page problem-files)"
#: the positional input of solve and crosscheck
SCENE_HELP = f"scene name (see 'signorini scenes'), a .toml scene file, or a problem file: {PROBLEM_FILES}"


#: what every command's exit codes share
EXITS = {EXIT_USAGE: "bad input: one line on stderr says which and how to fix it",
         130: "stopped by SIGINT (143 SIGTERM, 129 SIGHUP): no output left half-written"}


def add_command(sub, name: str, summary: str, description: str, examples: Sequence[str],
                exits: dict[int, str]):
    """The parser of one command: its one-line ``summary`` in ``signorini --help``; in its own
    help the ``description``, ``examples`` and exit codes (``exits`` before the shared ones)."""
    codes = {**exits, **EXITS}
    epilog = "\n".join(["examples:", *(f"  {line}" for line in examples), "", "exit codes:",
                        *(f"  {code:<3} {meaning}" for code, meaning in codes.items()), "",
                        f"documentation: {DOCS_SITE}"])
    return sub.add_parser(name, help=summary, description=textwrap.fill(description, 79),
                          epilog=epilog, formatter_class=argparse.RawDescriptionHelpFormatter)


class Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line and exit 2, like every other bad input
        raise InputError(f"{message} (see 'signorini {self.prog.split()[-1]} --help')"
                         if " " in self.prog else f"{message} (see 'signorini --help')")


def pairs(items: Sequence[str], flag: str) -> dict[str, Any]:
    """``key=value`` strings to a dict; values parsed as int, float, bool or left as text."""
    out: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise InputError(f"{flag} {item!r} is not key=value: write {flag} name=value")
        _set_once(out, key.strip(), value.strip(), flag)
    return out


def _set_once(out: dict[str, Any], key: str, value: str, flag: str) -> None:
    """``out[key] = value``; InputError when ``key`` already holds another value (the command
    line would otherwise keep whichever came last, without a word)."""
    if key in out and out[key] != value:
        raise InputError(f"{flag} {key} is given twice ({out[key]} and {value}): give it once")
    out[key] = value


#: the one spelling of a method's option on every command
OPT_METAVAR = "[METHOD:]KEY=VALUE"


def method_options(items: Sequence[str], methods: Sequence[str]) -> dict[str, dict[str, str]]:
    """``--opt [METHOD:]KEY=VALUE`` strings to each method's options (values as text):
    ``METHOD:KEY=VALUE`` names its method, ``KEY=VALUE`` alone is for the one method named."""
    out: dict[str, dict[str, str]] = {}
    for item in items:
        head, sep, value = item.partition("=")
        method, colon, key = head.rpartition(":")
        if not sep or not key.strip() or colon and not method:
            raise InputError(f"--opt {item!r} is not [METHOD:]key=value: write e.g. --opt "
                             "qp-osqp:eps_abs=1e-10 (or --opt eps_abs=1e-10 with one --method)")
        if not colon and len(methods) != 1:
            raise InputError(f"--opt {item!r} names no method: write --opt METHOD:key=value, "
                             f"here --opt METHOD:{item} (or name one --method)")
        _set_once(out.setdefault(method if colon else methods[0], {}), key.strip(), value.strip(),
                  "--opt")
    stray = sorted(set(out) - set(methods)) if methods else []
    if stray:
        raise InputError(f"--opt for {stray[0]!r}, which is not among the --method: add "
                         f"--method {stray[0]} (or drop the option)")
    return out


def parse_tol(text: str) -> float:
    from signorini.solvers.base import check_tol  # per command (start-up)

    try:
        value = float(text)
    except ValueError:
        raise InputError(f"--tol {text!r} is not a number: give e.g. --tol 1e-9") from None
    return check_tol(value, "--tol")  # the API's rule, said about the option


def parse_time_limit(text: str | None, flag: str = "--time-limit") -> float | None:
    """Seconds as a finite positive float (None stays None), or InputError naming ``flag``."""
    if text is None:
        return None
    try:
        seconds = float(text)
    except ValueError:
        seconds = float("nan")
    if not (seconds > 0 and seconds != float("inf")):
        raise InputError(f"{flag} {text!r} must be a positive number of seconds, e.g. {flag} 30")
    return seconds


def write_output(path: str, text: str) -> None:
    """``text`` to the file at ``path`` whole, or to stdout for ``-``."""
    from signorini.files import STDOUT, atomic_write_text, write_stdout  # per command (start-up)

    if path == STDOUT:
        write_stdout(text)
    else:
        atomic_write_text(path, text)


def out_folder(path: str, inputs: dict[str, str] | None = None) -> str:
    """The absolute path of the ``--out`` folder, checked before any work (nothing created)."""
    from signorini.files import check_outputs  # per command (start-up)

    return check_outputs(folders={"--out": path}, inputs=inputs or {})["--out"]


def input_files(scene: str | None = None, methods: Sequence[str] = ()) -> dict[str, str]:
    """The command's input files (a scene file, a problem file, a method's file) by what they are.

    InputError for one that exists but is not a regular file (a FIFO would
    wait forever); outputs are later checked not to be one of them.
    """
    from signorini.files import check_input_file  # per command (start-up)
    from signorini.problem.files import is_problem_file, problem_file_paths  # as above

    found = {"scene file": scene} if scene and scene.lower().endswith(".toml") else {}
    if scene and is_problem_file(scene):
        found.update({f"problem file {path}": path for path in problem_file_paths(scene)})
    found.update({f"file of --method {m}": m.rpartition(":")[0] for m in methods
                  if m.rpartition(":")[0].endswith(".py")})
    for what, path in found.items():
        check_input_file(path, what.removesuffix(f" {path}"))
    return found


@contextlib.contextmanager
def user_methods_in_workers(names: Sequence[str]) -> Iterator[None]:
    """While the block runs, each user method (``file.py:function``) named runs in a worker
    process (:func:`signorini.studies.runner.in_worker`): a method that ends its process,
    closes stdout or raises what is not an Exception cannot take this run down or fake its exit."""
    from signorini.solvers import user  # per command (start-up)
    from signorini.solvers.registry import REGISTRY, get_method, given  # per command (start-up)
    from signorini.studies.runner import in_worker  # per command (start-up)

    # a user's method is imported in its worker, not here (its import cannot take the run down)
    found = {name: user.deferred(name) if ":" in name else get_method(name)
             for name in dict.fromkeys(names) if name not in REGISTRY}
    with given({name: in_worker(method) for name, method in found.items()
                if method.family == "user"}):
        yield


@contextlib.contextmanager
def stdout_to_stderr(active: bool = True) -> Iterator[None]:
    """While the work runs, whatever prints goes to stderr (file descriptor 1 too): stdout is
    left to the result (``--json -``)."""
    if not active:
        yield
        return
    sys.stdout.flush()
    saved, real = os.dup(1), sys.stdout
    os.dup2(2, 1)
    sys.stdout = os.fdopen(os.dup(2), "w", buffering=1)  # closing it closes no one else's
    try:
        yield
    finally:
        with contextlib.suppress(OSError, ValueError):
            sys.stdout.close()
        os.dup2(saved, 1)
        os.close(saved)
        sys.stdout = real


def process_seconds() -> float | None:
    """Wall seconds since this process started: its start in ``/proc/self/stat`` (to the clock
    tick) against the boot-time clock; None where the system does not say (not Linux)."""
    try:
        with open("/proc/self/stat", "rb") as stat_file:
            fields = stat_file.read().rsplit(b")", 1)[1].split()  # from the 3rd field on
        started = int(fields[19]) / os.sysconf("SC_CLK_TCK")  # field 22: the start, in ticks
        return max(time.clock_gettime(time.CLOCK_BOOTTIME) - started, 0.0)
    except (OSError, ValueError, IndexError, AttributeError):
        return None


def family_of(scene: str, params: dict[str, Any], command: str) -> tuple[str, dict[str, Any]]:
    """``(scene family, parameters)`` of a scene name, or of a scene file that names its family
    (``scene = "hertz-cylinder"``, its values under ``params``): what a command that refines a
    family by its ``refine`` parameter takes. InputError for a mesh scene file."""
    if not scene.lower().endswith(".toml"):
        return scene, params
    from signorini.scenes.scenefile import family_scene_values  # per command (start-up)

    found = family_scene_values(scene, params)
    if found is None:
        raise InputError(f"scene file {scene!r} meshes its own body, which {command} cannot "
                         "refine: give a scene name (see 'signorini scenes') or a scene file "
                         "that names one (scene = \"hertz-cylinder\")")
    return found


__all__ = ["add_command", "Parser", "pairs", "method_options", "parse_tol", "parse_time_limit",
           "write_output", "out_folder", "input_files", "user_methods_in_workers",
           "stdout_to_stderr", "process_seconds", "family_of", "EXIT_FAILED", "EXIT_USAGE",
           "PROBLEM_FILES", "SCENE_HELP", "OPT_METAVAR"]
