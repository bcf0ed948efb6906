"""The ``signorini`` command: a thin shell over the library.

Bad input gives a one-line message on stderr and exit code 2; a failed
validation exits 1. Each command lives in its own module of this package and
registers its parser there; this one parses, sets up logging and maps errors
to exit codes.
"""

from __future__ import annotations

import argparse
import atexit
import contextlib
import ctypes
import errno
import logging
import os
import select
import signal
import stat
import sys
import threading
from typing import NoReturn, Sequence

from signorini import __version__
from signorini.cli import bench, crosscheck, explore, export, listing, solve, studies
from signorini.cli.common import EXIT_FAILED, EXIT_USAGE, Parser
from signorini.cli.progress import progress
from signorini.errors import DOCS_SITE, InputError, OutputError, SignoriniError, docs_page

COMMANDS = (solve, crosscheck, studies, bench, export, listing, explore)


def add_verbosity(parser: argparse.ArgumentParser, default) -> None:
    """``-v`` and ``-q``, before the command or after it (``default`` SUPPRESS on a command's
    parser, so that one given before the command is not reset by the command's parser)."""
    parser.add_argument("-v", "--verbose", action="store_true", default=default,
                        help="log each step of the library to stderr (no progress line)")
    parser.add_argument("-q", "--quiet", action="store_true", default=default,
                        help="errors only: no warnings, no progress line")


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="signorini", description="Frictionless contact as one QP, solved many ways. "
                    "On a terminal, a step that takes longer than a second shows a progress line "
                    "on stderr.", epilog=f"'signorini COMMAND --help' gives a command's examples "
                    f"and exit codes. Documentation: {DOCS_SITE}")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    add_verbosity(parser, False)
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for module in COMMANDS:
        module.add_parsers(sub)
    for command in set(sub.choices.values()):
        add_verbosity(command, argparse.SUPPRESS)
    return parser


def set_up_logging(args: argparse.Namespace) -> None:
    """Warnings on stderr; with -v every INFO line of the library, with -q errors only."""
    if args.verbose and args.quiet:
        raise InputError("-v (every step) and -q (errors only) contradict each other: give one")
    level = logging.INFO if args.verbose else logging.ERROR if args.quiet else logging.WARNING
    root = logging.getLogger()
    if not root.handlers:  # (a host that set up logging, pytest say, keeps its own)
        logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
        root.handlers[0].setLevel(level)  # the progress line lowers signorini's level, not this


def _check_distributed(args: argparse.Namespace, ranks: int) -> None:
    """Under mpirun only ``solve`` with a distributed (petsc-*) method makes sense."""
    from signorini.solvers.registry import get_method  # per command (start-up)

    if args.run is not solve.cmd_solve:
        raise InputError(f"under mpirun -n {ranks} only 'signorini solve' runs: run the other "
                         "commands without mpirun")
    if get_method(args.method).family != "petsc":
        raise InputError(f"under mpirun -n {ranks} only the petsc methods run distributed: give "
                         f"--method petsc-vi (or petsc-tron, petsc-gpcg), or run {args.method} "
                         "without mpirun")


def main(argv: Sequence[str] | None = None, *, process: bool = False) -> int:
    """Run one command; its exit code. ``process``: this call is the whole process
    (:func:`run`), so a solve's record counts the process's start-up among its stages."""
    from signorini.solvers import cluster  # per command (start-up)

    if cluster.launched_size() > 1:
        return _main_ranks(argv)
    return _main(argv, process=process)


def run(argv: Sequence[str] | None = None) -> NoReturn:
    """The ``signorini`` command as a process: :func:`main`, then the exit.

    Once the command is done (outputs written, workers stopped), what is buffered is flushed
    and the exit handlers run; then the process ends without the interpreter's teardown,
    which frees every object one by one (at 10⁶ dofs, gigabytes of arrays and a
    factorisation). When MPI was loaded by a process ``mpirun`` started, or when the output
    cannot be flushed, it exits as usual; a process alone finalises PETSc and MPI first.
    """
    keep_freed_memory()
    code = main(argv, process=True)
    if "mpi4py" in sys.modules and not _finalised_alone():  # MPI finalised by the usual exit
        sys.exit(code)
    try:
        for stream in (sys.stdout, sys.stderr):
            if stream is not None:
                stream.flush()
    except (OSError, ValueError):  # a closed or full output: the usual exit says it once
        sys.exit(code)
    atexit._run_exitfuncs()  # logging's flush and whatever a library registered
    os._exit(code)


def _finalised_alone() -> bool:
    """Whether PETSc and MPI, when loaded, are finalised here: only in a process that is the
    whole MPI world (not started by ``mpirun``, which waits for the usual exit)."""
    from signorini.solvers import cluster  # per command (start-up)

    if cluster.launched_size() > 1:
        return False
    PETSc, MPI = sys.modules.get("petsc4py.PETSc"), sys.modules.get("mpi4py.MPI")
    try:
        if PETSc is not None and not PETSc.Sys.isFinalized():
            PETSc._finalize()
        if MPI is not None and MPI.Is_initialized() and not MPI.Is_finalized():
            MPI.Finalize()
    except Exception:  # noqa: BLE001 - the usual exit finalises what is left
        return False
    return True


#: glibc's ``mallopt`` parameters (malloc.h): the most blocks served by ``mmap``, and the free
#: memory at the heap's top beyond which it is given back to the system
M_MMAP_MAX, M_TRIM_THRESHOLD = -4, -1


def keep_freed_memory() -> None:
    """This process (the command alone) reuses the memory it frees: glibc serves every block
    from its heap and gives none back (``mallopt``), and NumPy asks for no transparent huge
    pages. A large solve allocates and frees arrays of hundreds of megabytes again and again;
    served by ``mmap`` each is mapped afresh, and each first touch of a page is a fault (with
    huge pages, a compaction on a busy machine). The peak memory grows a little (the heap
    fragments). Elsewhere than glibc, or with another NumPy, nothing changes."""
    with contextlib.suppress(OSError, AttributeError, TypeError):
        libc = ctypes.CDLL(None)
        libc.mallopt(M_MMAP_MAX, 0)
        libc.mallopt(M_TRIM_THRESHOLD, 2 ** 31 - 1)
    with contextlib.suppress(ImportError, AttributeError):
        from numpy._core.multiarray import _set_madvise_hugepage  # per process (its entry)

        _set_madvise_hugepage(False)


def _main_ranks(argv: Sequence[str] | None) -> int:
    """Under ``mpirun -n N``: rank 0 runs the command, the other ranks serve its solves."""
    from signorini.solvers import cluster  # per command (start-up)

    try:
        if cluster.rank() != 0:
            return cluster.serve()
    except ImportError:
        print("signorini: error: started by mpirun but mpi4py is not installed: "
              f"pip install 'signorini[petsc]' (see {docs_page('performance', 'petsc-and-mpi')})",
              file=sys.stderr)
        return EXIT_USAGE
    try:
        return _main(argv, ranks=cluster.size())
    finally:
        cluster.release()


class Stopped(KeyboardInterrupt):
    """SIGTERM or SIGHUP, raised where the command was, so that its clean-up runs."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


def _stop(signum: int, frame) -> None:
    raise Stopped(signum)


def _main(argv: Sequence[str] | None, ranks: int = 1, process: bool = False) -> int:
    handled = (signal.SIGTERM, signal.SIGHUP)
    main_thread = threading.current_thread() is threading.main_thread()
    before = {s: signal.signal(s, _stop) for s in handled} if main_thread else {}
    try:
        return _run(argv, ranks, process)
    finally:
        _clean_up()
        for number, handler in before.items():
            signal.signal(number, handler)


def _clean_up() -> None:
    """No worker process outlives the command; no file is left half-written; no folder it made
    stays empty."""
    worker = sys.modules.get("signorini.studies.worker")
    if worker is not None:
        worker.stop_all()
    files = sys.modules.get("signorini.files")
    if files is not None:
        files.remove_partial_files()
        files.remove_empty_folders()


def _say(message: str) -> None:
    with contextlib.suppress(OSError, ValueError, AttributeError):
        print(f"signorini: {message}", file=sys.stderr)


def _stdout_closed() -> bool:
    try:
        os.fstat(1)
    except OSError:
        return True
    return sys.stdout is None or sys.stdout.closed


def _output_full(exc: OSError) -> bool:
    """Whether ``exc`` is a write to stdout or stderr that found no space: a file's write names
    the file (the library says those as OutputError), a print's does not."""
    return exc.filename is None and exc.errno in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO)


def _drop_stdout() -> None:
    """What is still buffered for a stdout that fails goes nowhere: no second error at exit."""
    with contextlib.suppress(OSError, ValueError, AttributeError):
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())


def _reader_gone() -> bool:
    """Whether stdout is a pipe whose reader has closed it (``| head`` stopped reading)."""
    try:
        if not stat.S_ISFIFO(os.fstat(1).st_mode):
            return False
        poll = select.poll()
        poll.register(1, 0)  # POLLERR is always reported: the read end is closed
        return any(events & select.POLLERR for _, events in poll.poll(0))
    except (OSError, ValueError, AttributeError):
        return False


def _run(argv: Sequence[str] | None, ranks: int, process: bool = False) -> int:
    try:
        if _stdout_closed():  # nothing printed would be seen, and fd 1 could be a file's
            raise InputError("standard output is closed: run with it open (> /dev/null "
                             "discards what is printed)")
        args = build_parser().parse_args(argv)
        args.process = process
        set_up_logging(args)
        if ranks > 1:
            _check_distributed(args, ranks)
        with progress(quiet=args.quiet, verbose=args.verbose):
            code = args.run(args)
        sys.stdout.flush()
        if _reader_gone():  # written into the pipe's buffer, yet never read: as a broken pipe
            raise BrokenPipeError
        return code
    except InputError as exc:
        _say(f"error: {exc}")
        return EXIT_USAGE
    except OutputError as exc:
        _say(f"error: {exc}")
        return EXIT_FAILED
    except SignoriniError as exc:
        _say(f"{type(exc).__name__}: {exc}")
        return EXIT_FAILED
    except KeyboardInterrupt as exc:  # SIGINT, or SIGTERM and SIGHUP through _stop
        signum = getattr(exc, "signum", signal.SIGINT)
        for number in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):  # one stop is enough
            with contextlib.suppress(ValueError):
                signal.signal(number, signal.SIG_IGN)
        _clean_up()
        _say(f"stopped by {signal.Signals(signum).name}: worker processes ended, "
             "no output left half-written")
        return 128 + signum
    except BrokenPipeError:  # e.g. piped into `head`: say so once, on stderr, and fail
        _drop_stdout()
        _say("error: standard output was closed before the output was written")
        return EXIT_FAILED
    except OSError as exc:  # stdout on a full disk (> /dev/full): one line, not a traceback
        if not _output_full(exc):
            raise
        _drop_stdout()
        _say(f"error: standard output cannot be written ({exc.strerror}): free some space or "
             "send it elsewhere")
        return EXIT_FAILED
    except ValueError:
        if not _stdout_closed():
            raise
        _say("error: standard output was closed while the command ran (by a method?): "
             "the output was not written")
        return EXIT_FAILED
    except (Exception, SystemExit, GeneratorExit):  # a bug shows its traceback; --help exits
        raise
    except BaseException as exc:  # not an Exception: raised by a method of the user's
        _say(f"error: the run was ended by {type(exc).__name__}: {exc} (a method raised it; "
             "it must return a ContactSolution)")
        return EXIT_FAILED


__all__ = ["add_verbosity", "build_parser", "set_up_logging", "main", "run", "keep_freed_memory",
           "Stopped"]
