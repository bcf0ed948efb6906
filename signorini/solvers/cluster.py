"""Running under ``mpirun``: rank 0 builds and reports, the other ranks serve.

Under ``mpirun -n N signorini solve …`` every rank starts the same program.
Rank 0 parses the command, assembles the problem serially and, when a
distributed method solves it, sends each rank its block of rows
(:func:`distribute`); ranks 1…N−1 wait in :func:`serve`, take part in the
solve and send their part of the answer back, until rank 0 releases them
(:func:`release`). Only rank 0 writes files or prints.

Without ``mpirun`` (no launcher in the environment) the world is one rank
and nothing here imports MPI.
"""

from __future__ import annotations

import importlib
import logging
import os
import resource
import time
from typing import Any, Callable

from signorini.errors import InputError

log = logging.getLogger(__name__)

#: environment variables by which Open MPI, MPICH / Hydra and PMIx launchers announce the world size
_SIZE_VARIABLES = ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS")
_PIECE_TAG = 17
#: how often a waiting rank looks for work (s): waiting in a blocking MPI call would spin a
#: core at 100 % and slow rank 0's serial assembly and factorisations on a small machine
_POLL_S = 0.01


def launched_size() -> int:
    """The number of ranks ``mpirun`` started (1 without a launcher); imports no MPI."""
    for name in _SIZE_VARIABLES:
        value = os.environ.get(name, "")
        if value.isdigit():
            return int(value)
    return 1


def mpirun_command(ranks: int, argv: list[str]) -> tuple[list[str], dict[str, str]]:
    """``mpirun -n ranks argv…`` and its environment; refuses more ranks than cores.

    Oversubscribed runs (more ranks than cores) are many times slower (docs/petsc.md), so
    they are never started.
    Open MPI refuses to run as root unless told to (containers and CI run as root).
    """
    import shutil

    cores = os.cpu_count() or 1
    if ranks > cores:
        raise InputError(f"{ranks} ranks on {cores} cores would oversubscribe the machine: "
                         f"give at most {cores} ranks")
    mpirun = shutil.which("mpirun")
    if mpirun is None:
        raise InputError("no mpirun on the PATH: install an MPI (Debian: openmpi-bin, which "
                         "`make` installs with petsc-dev) or run with 1 rank")
    env = dict(os.environ)
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return [mpirun, "-n", str(ranks), *argv], env


def _comm():
    from mpi4py import MPI  # optional (MPI): only under mpirun

    return MPI.COMM_WORLD


def size() -> int:
    """Ranks in the world (1 without ``mpirun``)."""
    return _comm().Get_size() if launched_size() > 1 else 1


def rank() -> int:
    """This process's rank (0 without ``mpirun``)."""
    return _comm().Get_rank() if launched_size() > 1 else 0


def peak_memory_mb() -> float:
    """This process's peak resident memory so far, in MB."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _runner(job: dict[str, Any]) -> Callable[[dict[str, Any], dict[str, Any]], dict[str, Any]]:
    module, _, name = job["run"].partition(":")
    return getattr(importlib.import_module(module), name)


def _run_piece(job: dict[str, Any], piece: dict[str, Any]) -> dict[str, Any]:
    """Run this rank's part of a job; an exception becomes an ``error`` entry, not a hang."""
    start = time.perf_counter()
    try:
        result = _runner(job)(job, piece)
    except Exception as exc:  # reported to rank 0, which turns it into a failed solution
        log.warning("rank %d: %s: %s", rank(), type(exc).__name__, exc)
        result = {"error": f"rank {rank()}: {type(exc).__name__}: {exc}"}
    result["rank"] = rank()
    result["rank_s"] = time.perf_counter() - start
    result["peak_memory_mb"] = peak_memory_mb()
    return result


def distribute(job: dict[str, Any], pieces: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """On rank 0: send ``job`` to every rank with its piece, run piece 0, gather every result.

    ``job["run"]`` names the function (``module:function``) each rank calls
    as ``function(job, piece)``; it must take part in the same collective
    calls on every rank. Returns the results in rank order.
    """
    if len(pieces) != size():
        raise ValueError(f"{len(pieces)} pieces for {size()} ranks")
    if size() == 1:
        return [_run_piece(job, pieces[0])]
    comm = _comm()
    comm.Ibarrier().Wait()
    comm.bcast(job, root=0)
    for other in range(1, len(pieces)):
        comm.send(pieces[other], dest=other, tag=_PIECE_TAG)
    mine = _run_piece(job, pieces[0])
    return comm.gather(mine, root=0)


def serve() -> int:
    """On ranks 1…N−1: run every job rank 0 distributes until it releases the ranks."""
    comm = _comm()
    while True:
        arrived = comm.Ibarrier()
        while not arrived.Test():
            time.sleep(_POLL_S)
        job = comm.bcast(None, root=0)
        if job is None:
            return 0
        piece = comm.recv(source=0, tag=_PIECE_TAG)
        comm.gather(_run_piece(job, piece), root=0)


def release() -> None:
    """On rank 0: tell the serving ranks there is no more work (they then exit)."""
    if size() > 1 and rank() == 0:
        comm = _comm()
        comm.Ibarrier().Wait()
        comm.bcast(None, root=0)


__all__ = ["launched_size", "mpirun_command", "size", "rank", "peak_memory_mb", "distribute",
           "serve", "release"]
