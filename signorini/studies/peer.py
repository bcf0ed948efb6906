"""A peer, side by side: Hertz's cylinder, sphere and two cylinders by GetFEM and by this package.

``signorini bench --peer getfem``. GetFEM runs in the system Python (Debian's
``python3-getfem`` and ``python3-gmsh``) through our own scripts,
``benchmarks/peers/getfem_hertz.py`` (one body on a rigid flat) and
``getfem_two_cylinders.py`` (two bodies, non-matching meshes) in a checkout of the
repository (:mod:`signorini.studies.peer_cases`; not part of the installed
package); this package runs as ``signorini solve SCENE --json -``. Each point is timed two ways
(:func:`run_peer`): whole process, from start to exit (interpreter, imports, meshing,
assembly, solve, output), and in process, each solve from the mesh to the answer's record
after a warm-up (the GetFEM script with ``"repeat"``, this package through
:func:`solve_repeatedly`).

Both codes' p₀ and a come from the same least-squares fit (:func:`fit_hertz`)
of their nodal pressures, and are compared with Hertz's values for the applied load.

The ladders (:mod:`signorini.studies.peer_cases`) differ by code; the report
(:mod:`signorini.studies.peer_report`) puts both on the same axes, accuracy and time.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

import signorini
from signorini.references.profile import hertz_fit
from signorini.studies.peer_cases import CASES, ONE_BODY, SCENES, hertz_reference, ladder_of
from signorini.studies.peer_report import NAMES, TARGETS, at_accuracy, peer_table, write_peer

__all__ = ["NAMES", "ONE_BODY", "SCENES", "SCRIPT", "TARGETS", "Point", "at_accuracy", "fit_hertz",
           "getfem_missing", "ladder", "our_command", "peer_table", "run_peer", "solve_repeatedly",
           "system_python", "time_in_process", "write_peer"]

#: the one-body GetFEM script (the two-body one beside it: :data:`signorini.studies.peer_cases.CASES`)
SCRIPT = CASES["hertz-cylinder"].path
#: the interpreter that has GetFEM (override with SIGNORINI_GETFEM_PYTHON)
SYSTEM_PYTHON = "/usr/bin/python3"
INSTALL = "apt-get install python3-getfem python3-gmsh"


def fit_hertz(x, p, rel: float = 1e-9) -> tuple[float, float, int]:
    """Hertz's p0 and a from nodal pressures, the same way for both codes.

    :func:`signorini.references.profile.hertz_fit` (least squares of p² = p0²(1 − x²/a²)
    over the active nodes but the outermost) with the nodes counted active by
    their pressure alone, p > rel · max p, since GetFEM returns no active set.
    Returns (p0, a, active nodes). The GetFEM script carries the same formula
    (``fit_hertz`` in :data:`SCRIPT`; a test holds them equal).
    """
    x, p = np.abs(np.asarray(x, dtype=float)), np.asarray(p, dtype=float)
    active = p > rel * p.max()
    p0, a = hertz_fit(x, p, active)
    return p0, a, int(active.sum())


def system_python() -> str:
    return os.environ.get("SIGNORINI_GETFEM_PYTHON", SYSTEM_PYTHON)


def getfem_missing(python: str | None = None) -> str | None:
    """None when the GetFEM script is here and ``python`` imports getfem and gmsh; otherwise
    one line saying what is missing (a checkout of the repository, or what to install)."""
    if not SCRIPT.is_file():
        return (f"the peer benchmark needs a checkout of the repository ({SCRIPT} is not there: "
                "this package was installed without benchmarks/)")
    python = python or system_python()
    try:
        done = subprocess.run([python, "-c", "import getfem, gmsh"], capture_output=True,
                              text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return f"GetFEM not found: {python} cannot run ({exc}); install it with `{INSTALL}`"
    if done.returncode == 0:
        return None
    lines = done.stderr.strip().splitlines()
    why = lines[-1] if lines else f"exit code {done.returncode}"
    return f"GetFEM is not installed for {python} ({why}): install it with `{INSTALL}`"


def our_command() -> list[str]:
    """The package's command line in this environment (the ``signorini`` script beside Python)."""
    script = Path(sys.executable).with_name("signorini")
    return [str(script)] if script.is_file() else [sys.executable, "-m", "signorini.cli"]


@dataclass
class Point:
    """One code at one rung of its ladder on one scene."""

    scene: str
    code: str                       # "getfem" or "signorini"
    rung: int
    mesh: dict[str, Any]
    params: dict[str, float]
    row: dict[str, Any] = field(default_factory=dict)
    walls: list[float] = field(default_factory=list)
    solves: list[float] = field(default_factory=list)   # in process, the first a warm-up
    solves_message: str = ""

    @property
    def given(self) -> dict[str, Any]:
        """The point's parameters as its code takes them (the script's JSON, the scene's --set)."""
        if self.code == "getfem":
            name = CASES[self.scene].name  # the one-body script's scene key
            return {**self.params, **self.mesh, **({"scene": name} if name else {})}
        return {**self.params, **self.mesh}

    @property
    def settings(self) -> list[str]:
        """The package's ``--set KEY=VALUE`` arguments: numbers to the last digit, names as they are."""
        return [arg for k, v in self.given.items()
                for arg in ("--set", f"{k}={v if isinstance(v, str) else repr(v)}")]

    @property
    def label(self) -> str:
        if self.code == "getfem":
            return f"h = a/{1 / self.mesh['h_contact']:.0f}"
        return " ".join(f"{k}={v}" for k, v in self.mesh.items())


def _environment() -> dict[str, str]:
    """Both codes run as on a user's machine: Python caches byte code (an environment that
    turns that off, as this project's sandbox does, would recompile the package at every run)."""
    return {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def _timed(argv: list[str], timeout: float) -> tuple[subprocess.CompletedProcess | None, float, str]:
    tic = time.perf_counter()
    try:
        done = subprocess.run(argv, capture_output=True, text=True, timeout=timeout,
                              env=_environment())
    except subprocess.TimeoutExpired:
        return None, time.perf_counter() - tic, f"killed after {timeout:g} s"
    except OSError as exc:  # the interpreter or script is not there (any more)
        return None, time.perf_counter() - tic, f"{argv[0]} cannot run ({exc})"
    return done, time.perf_counter() - tic, ""


def _decode(done: subprocess.CompletedProcess | None, why: str) -> tuple[dict | None, str]:
    if done is None:
        return None, why
    try:  # the package writes indented JSON, the script one line after GetFEM's own output
        text = done.stdout.strip()
        return json.loads(text if text.startswith("{") else text.splitlines()[-1]), ""
    except (ValueError, IndexError):
        tail = (done.stderr.strip().splitlines() or [f"exit code {done.returncode}"])[-1]
        return None, f"no JSON (exit code {done.returncode}): {tail}"


def run_point(point: Point, *, python: str, command: list[str], timeout: float) -> None:
    """Run ``point`` once: its whole-process wall time appended, its row kept if the fastest."""
    if point.code == "getfem":
        argv = [python, str(CASES[point.scene].path), json.dumps(point.given)]
    else:
        argv = [*command, "solve", point.scene, "--json", "-"]
        argv += point.settings
    done, wall, why = _timed(argv, timeout)
    point.walls.append(wall)
    record, message = _decode(done, why)
    P, p0_ref, a_ref = hertz_reference(point.scene, **point.params)
    row: dict[str, Any] = {"scene": point.scene, "code": point.code, "rung": point.rung,
                           "mesh": point.label, "p0_ref": p0_ref, "a_ref": a_ref, "load": P,
                           "status": "failed", "message": message}
    if record is not None:
        if point.code == "getfem":
            x, p = record["x"], record["pressure"]
            row.update(dofs=record["dofs"], contact_nodes=record["contact_nodes"],
                       total_force=record["total_force"], inner_s=record["time"]["total_s"],
                       versions=record["versions"],
                       status="converged" if record["converged"] else "not converged",
                       message=f"{record['newton_iterations']} Newton iterations")
        else:
            x, p = record["contact"]["x"], record["contact"]["pressure"]
            row.update(dofs=record["dofs"], contact_nodes=record["contact_candidates"],
                       total_force=record["total_force"], status=record["status"],
                       inner_s=record["time"]["total_s"], message=record["message"])
        row["phases"] = record["time"]
        p0, a, active = fit_hertz(x, p)
        row.update(p0=p0, a=a, active_nodes=active, p0_rel=p0 / p0_ref - 1.0,
                   a_rel=a / a_ref - 1.0, force_rel=row["total_force"] / P - 1.0)
    # keep the fastest run that answered (its own phase times go with its wall time)
    if not point.row or ("p0" in row and ("p0" not in point.row or wall < point.row["wall_s"])):
        point.row = {**row, "wall_s": wall}


#: what :func:`time_in_process` runs in a fresh Python for this package
IN_PROCESS = "import sys; from signorini.studies.peer import solve_repeatedly; solve_repeatedly(sys.argv[1])"


def solve_repeatedly(given: str) -> None:
    """This package's in-process measure, run by :func:`time_in_process` in a fresh Python.

    ``given`` is JSON: ``scene``, ``params`` and ``repeat``. Solves the scene with
    :func:`signorini.solve` ``repeat`` times, each timed from the call to the record
    ``signorini solve --json`` writes (:meth:`signorini.api.Result.to_dict`: the mesh,
    assembly, solve, certificate, estimate and profile; not the writing), and prints one
    JSON line: every solve's wall time (``runs_s``), the last one's dofs and status.
    """
    point = json.loads(given)
    runs, record = [], {}
    for _ in range(point["repeat"]):
        tic = time.perf_counter()
        record = signorini.solve(point["scene"], params=point["params"]).to_dict()
        runs.append(time.perf_counter() - tic)
    print(json.dumps({"runs_s": runs, "dofs": record.get("dofs"), "status": record.get("status")}))


def time_in_process(point: Point, solves: int, *, python: str, timeout: float) -> list[float]:
    """Solve ``point`` ``solves`` times in one fresh process of its code; each solve's wall
    time, the first a warm-up (kept in ``point.solves``; empty, with ``point.solves_message``
    saying why, when the process gave none)."""
    if point.code == "getfem":
        argv = [python, str(CASES[point.scene].path), json.dumps({**point.given, "repeat": solves})]
    else:
        argv = [sys.executable, "-c", IN_PROCESS,
                json.dumps({"scene": point.scene, "params": point.given, "repeat": solves})]
    done, _, why = _timed(argv, timeout * solves)
    record, message = _decode(done, why)
    record = record or {}
    point.solves = [float(t) for t in record.get("runs_s", [])]
    status = record.get("status") or ("converged" if record.get("converged") else "not converged")
    dofs, whole = record.get("dofs"), point.row.get("dofs")
    point.solves_message = message
    if not message and (len(point.solves) != solves or status != "converged"):
        point.solves_message = f"{len(point.solves)} of {solves} solves timed, {status}"
    elif not message and whole is not None and dofs != whole:  # both measures time one model
        point.solves_message = f"{dofs} dofs in process, {whole} in the whole process"
    return point.solves


def ladder(scenes: list[str], sizes: list[int] | None,
           params: dict[str, Any]) -> list[Point]:
    """The points to run: per scene, both codes at the chosen rungs (default: every rung;
    :func:`signorini.studies.peer_cases.ladder_of` checks the choice)."""
    return [Point(scene, code, i, mesh, values)
            for scene, i, theirs, ours, values in ladder_of(scenes, sizes, params)
            for code, mesh in (("getfem", theirs), ("signorini", ours))]


def run_peer(points: list[Point], *, repeat: int = 5, in_process: int = 5, timeout: float = 600.0,
             python: str | None = None, command: list[str] | None = None,
             progress: Callable[[str], None] | None = None) -> list[dict[str, Any]]:
    """Time every point both ways. Whole process: ``repeat`` runs each, interleaved (so that
    load on the machine hits both codes alike); the row is that of the fastest run that
    answered (``wall_s``), with every run's time in ``walls_s``. In process (unless
    ``in_process`` is 0): one process per point solving it ``1 + in_process`` times, every
    solve's time in ``in_process_runs_s`` and the fastest after the warm-up in ``in_process_s``."""
    python, command = python or system_python(), command or our_command()
    for turn in range(repeat):
        for point in points:
            run_point(point, python=python, command=command, timeout=timeout)
            if progress:
                row = point.row
                progress(f"[{turn + 1}/{repeat}] {point.scene} {point.code} {point.label}: "
                         f"{row['status']} {row.get('dofs', '–')} dofs, p0 "
                         f"{100 * row.get('p0_rel', math.nan):+.3f} %, a "
                         f"{100 * row.get('a_rel', math.nan):+.3f} %, {point.walls[-1]:.2f} s")
    for point in points if in_process else ():
        time_in_process(point, 1 + in_process, python=python, timeout=timeout)
        if progress:
            progress(f"[in process] {point.scene} {point.code} {point.label}: "
                     + (", ".join(f"{t:.3f}" for t in point.solves) + " s" if point.solves else "")
                     + (f" ({point.solves_message})" if point.solves_message else ""))
    return [{**p.row, "walls_s": list(p.walls), **_in_process(p)} for p in points]


def _in_process(point: Point) -> dict[str, Any]:
    """A row's in-process fields (none when the point was not timed in process)."""
    if not point.solves and not point.solves_message:
        return {}
    after = point.solves[1:]
    fields = {"in_process_runs_s": list(point.solves), "in_process_s": min(after) if after else None}
    return {**fields, "in_process_message": point.solves_message} if point.solves_message else fields
