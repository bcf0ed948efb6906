"""A peer, side by side: Hertz's cylinder and sphere by GetFEM and by this package.

``signorini bench --peer getfem``. GetFEM runs in the system Python (Debian's
``python3-getfem`` and ``python3-gmsh``) through our own script,
``benchmarks/peers/getfem_hertz.py`` in a checkout of the repository (:data:`SCRIPT`;
not part of the installed package); this package runs as ``signorini solve SCENE
--json -``. Each point is timed two ways:

- whole process: each code in its own process, timed from start to exit
  (interpreter, imports, meshing, assembly, solve, output), ``repeat`` runs
  interleaved over the points and the fastest kept;
- in process: one fresh process per code and point that imports the code once
  and then solves the same point ``1 + in_process`` times, each solve timed from
  the mesh to the answer's record (the GetFEM script with ``"repeat"``, this
  package through :func:`solve_repeatedly`, which calls :func:`signorini.solve`);
  the first solve is a warm-up, the fastest of the others kept.

Both codes' p₀ and a come from the same least-squares fit (:func:`fit_hertz`)
of their nodal pressures, and are compared with Hertz's values for the applied load.

The ladders differ by code: GetFEM refines its gmsh size field at the contact
(``h_contact``, a fraction of a), this package its scene parameters
(``n_contact``, ``refine``; ``grading`` the scene's default). Each ladder spans
about 2k to 60k dofs; the chart puts both on the same axes (accuracy and time).
"""

from __future__ import annotations

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
from signorini.analytic import (contact_modulus, hertz_cylinder_load, hertz_cylinder_peak,
                                hertz_sphere_load, hertz_sphere_peak)
from signorini.errors import InputError
from signorini.files import atomic_write_text, save_figure, to_json, writable_directory
from signorini.output import plots
from signorini.pressure import hertz_fit
from signorini.scenes.meshing import MESHERS

#: the standalone GetFEM script, run by the system Python: in the repository's checkout,
#: beside the package's source tree (an installed package has none)
SCRIPT = Path(signorini.__file__).parents[1] / "benchmarks" / "peers" / "getfem_hertz.py"
#: the interpreter that has GetFEM (override with SIGNORINI_GETFEM_PYTHON)
SYSTEM_PYTHON = "/usr/bin/python3"
INSTALL = "apt-get install python3-getfem python3-gmsh"
#: the package's scene and the script's name for it
SCENES = {"hertz-cylinder": "cylinder", "hertz-sphere": "sphere"}
#: parameters both codes take (passed to the script and as --set to the package)
SHARED = ("R", "E", "nu", "a_over_R")
#: parameters only the package takes, added to each of its rungs (e.g. --set mesher=triangle)
OURS_ONLY = ("mesher",)
DEFAULTS = {"R": 1.0, "E": 1.0, "nu": 0.3, "a_over_R": 0.05}
#: GetFEM's ladder: the element size at the contact, a fraction of a
GETFEM_LADDER = ({"h_contact": 1 / 16}, {"h_contact": 1 / 24}, {"h_contact": 1 / 40},
                 {"h_contact": 1 / 64}, {"h_contact": 1 / 112})
#: this package's ladder per scene (the grading is the scene's default)
OUR_LADDER = {
    "hertz-cylinder": ({"n_contact": 10}, {"n_contact": 20}, {"n_contact": 40},
                       {"n_contact": 80}, {"n_contact": 80, "refine": 1}),
    "hertz-sphere": ({"n_contact": 12}, {"n_contact": 25}, {"n_contact": 50},
                     {"n_contact": 100}, {"n_contact": 100, "refine": 1}),
}
#: accuracies at which the report compares the codes' fastest runs: p₀ and a within 0.3 % and 0.1 %
TARGETS = (0.003, 0.001)


def fit_hertz(x, p, rel: float = 1e-9) -> tuple[float, float, int]:
    """Hertz's p0 and a from nodal pressures, the same way for both codes.

    :func:`signorini.pressure.hertz_fit` (least squares of p² = p0²(1 − x²/a²)
    over the active nodes but the outermost) with the nodes counted active by
    their pressure alone, p > rel · max p, since GetFEM returns no active set.
    Returns (p0, a, active nodes). The GetFEM script carries the same formula
    (``fit_hertz`` in :data:`SCRIPT`; a test holds them equal).
    """
    x, p = np.abs(np.asarray(x, dtype=float)), np.asarray(p, dtype=float)
    active = p > rel * p.max()
    p0, a = hertz_fit(x, p, active)
    return p0, a, int(active.sum())


def hertz_reference(scene: str, *, R: float, E: float, nu: float,
                    a_over_R: float) -> tuple[float, float, float]:
    """(load P, p0, a) of Hertz's solution for ``a_over_R`` (P per unit thickness for the cylinder)."""
    a = a_over_R * R
    E_star = contact_modulus(E, nu)
    if scene == "hertz-cylinder":
        P = hertz_cylinder_load(a, R, E_star)
        return P, hertz_cylinder_peak(P, a), a
    P = hertz_sphere_load(a, R, E_star)
    return P, hertz_sphere_peak(P, a), a


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
            return {**self.params, **self.mesh, "scene": SCENES[self.scene]}
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
    import json

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
    import json

    if point.code == "getfem":
        argv = [python, str(SCRIPT), json.dumps(point.given)]
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
    import json

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
    import json

    if point.code == "getfem":
        argv = [python, str(SCRIPT), json.dumps({**point.given, "repeat": solves})]
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
           params: dict[str, float]) -> list[Point]:
    """The points to run: per scene, both codes at the chosen rungs (default: every rung)."""
    unknown = [s for s in scenes if s not in SCENES]
    if unknown:
        raise InputError(f"--scene {unknown[0]!r} has no peer model: choose from {', '.join(SCENES)}")
    extra = sorted(set(params) - set(SHARED) - set(OURS_ONLY))
    if extra:
        raise InputError(f"--set {extra[0]} is not shared by both codes: the peer benchmark "
                         f"takes {', '.join(SHARED)}, and mesher for the package alone")
    ours = {k: v for k, v in params.items() if k in OURS_ONLY}
    if "mesher" in ours and ours["mesher"] not in MESHERS:
        raise InputError(f"--set mesher={ours['mesher']} is not a mesher of the Hertz discs: "
                         f"choose one of {', '.join(MESHERS)}")
    params = {k: v for k, v in params.items() if k not in OURS_ONLY}
    rungs = range(len(GETFEM_LADDER)) if sizes is None else sizes
    bad = [i for i in rungs if not 0 <= i < len(GETFEM_LADDER)]
    if bad:
        raise InputError(f"--sizes {bad[0]} is not a rung of the peer ladder: give numbers in "
                         f"0..{len(GETFEM_LADDER) - 1}")
    values = {**DEFAULTS, **{k: float(v) for k, v in params.items()}}
    return [Point(scene, code, i, dict(mesh), values)
            for scene in scenes for i in rungs
            for code, mesh in (("getfem", GETFEM_LADDER[i]),
                               ("signorini", {**OUR_LADDER[scene][i], **ours}))]


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


def _pct(value: Any) -> str:
    return "–" if value is None or not np.isfinite(value) else f"{100 * value:+.3f} %"


def _error(row: dict[str, Any]) -> float:
    """The larger of the p₀ and a errors (inf when the run gave none)."""
    worst = max(abs(row.get("p0_rel", math.nan)), abs(row.get("a_rel", math.nan)))
    return worst if np.isfinite(worst) else math.inf


NAMES = {"getfem": "GetFEM", "signorini": "signorini"}
#: the two measures of time: a row's key and its name in the tables
MEASURES = {"wall_s": "whole process", "in_process_s": "in process"}


def _seconds(value: Any) -> str:
    return "–" if value is None else f"{value:.2f}"


def at_accuracy(rows: list[dict[str, Any]], scene: str, target: float,
                by: str = "wall_s") -> dict[str, dict | None]:
    """Per code, its fastest run by the time ``by`` (a key of :data:`MEASURES`) with p₀ and a
    both within ``target`` of Hertz; rows without that time (not measured) are left out."""
    best: dict[str, dict | None] = {}
    for code in NAMES:
        good = [r for r in rows if r["scene"] == scene and r["code"] == code and r.get(by) is not None
                and r["status"] == "converged" and _error(r) <= target]
        best[code] = min(good, key=lambda r: r[by]) if good else None
    return best


def _fastest_cells(rows: list[dict[str, Any]], scene: str, target: float, by: str) -> list[str]:
    """The summary's cells for one scene, target and measure: each code's fastest run ("–" for a
    code whose runs carry no such time) and the ratio of their times."""
    best = at_accuracy(rows, scene, target, by)
    measured = {r["code"] for r in rows if r["scene"] == scene and r.get(by) is not None}
    cells = [f"{r['dofs']:,} dofs, {r[by]:.2f} s" if r else "not reached" if code in measured else "–"
             for code, r in best.items()]
    ratio = f"{best['signorini'][by] / best['getfem'][by]:.2f}" if all(best.values()) else "–"
    return [*cells, ratio]


def peer_table(rows: list[dict[str, Any]]) -> list[str]:
    """The Markdown tables: every run, then both codes at the target accuracies by each measure
    of time the runs carry (whole process always, in process when it was measured)."""
    lines = ["| scene | code | mesh | dofs | contact nodes (active) | p₀ − Hertz | a − Hertz "
             "| force − P | whole process [s] | in process [s] | inside [s] | status |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    for r in rows:
        lines.append(
            f"| {r['scene']} | {NAMES[r['code']]} | {r['mesh']} | {r.get('dofs', 0):,} "
            f"| {r.get('contact_nodes', '–')} ({r.get('active_nodes', '–')}) | {_pct(r.get('p0_rel'))} "
            f"| {_pct(r.get('a_rel'))} | {_pct(r.get('force_rel'))} | {r['wall_s']:.2f} "
            f"| {_seconds(r.get('in_process_s'))} | {r.get('inner_s', math.nan):.2f} | {r['status']} |")
    lines += ["", "| scene | p₀ and a within | time | GetFEM: fastest run | signorini: fastest run "
              "| signorini / GetFEM |", "|---|---:|---|---|---|---:|"]
    # a run recorded before the in-process measure (or with --in-process 0) has no such rows
    measures = {by: name for by, name in MEASURES.items() if any(r.get(by) is not None for r in rows)}
    for scene in dict.fromkeys(r["scene"] for r in rows):
        for target in TARGETS:
            for by, measure in measures.items():
                cells = " | ".join(_fastest_cells(rows, scene, target, by))
                lines.append(f"| {scene} | {100 * target:g} % | {measure} | {cells} |")
    return lines


def peer_figure(rows: list[dict[str, Any]]):
    """Time against accuracy, whole process (left) and in process (right), a row per scene."""
    from matplotlib.figure import Figure

    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    figure = Figure(figsize=(10, 3.8 * len(scenes)), layout="constrained")
    grid = figure.subplots(len(scenes), len(MEASURES), squeeze=False, sharex="row",
                           sharey="row")
    for scene, panels in zip(scenes, grid):
        mine = [dict(r, error=_error(r)) for r in rows if r["scene"] == scene]
        for ax, (by, measure) in zip(panels, MEASURES.items()):
            plots.peer_times(mine, by=by, label=f"{measure} wall time [s]", targets=TARGETS,
                             names=NAMES, ax=ax).set_title(f"{scene}: {measure}", fontsize=9)
    return figure


CSV_COLUMNS = ("scene", "code", "rung", "mesh", "dofs", "contact_nodes", "active_nodes", "p0",
               "p0_ref", "p0_rel", "a", "a_ref", "a_rel", "total_force", "load", "force_rel",
               "wall_s", "in_process_s", "inner_s", "status", "message", "walls_s", "in_process_runs_s")


def write_peer(rows: list[dict[str, Any]], out: str | os.PathLike, command: str,
               meta: dict[str, Any]) -> dict[str, Path]:
    """peer.csv, peer.json, peer.md and peer.png in ``out``, each written whole or not at all."""
    import csv
    import io

    directory = writable_directory(out)
    paths = {k: directory / f"peer.{k}" for k in ("csv", "json", "md", "png")}
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=CSV_COLUMNS, extrasaction="ignore",
                            lineterminator="\n")
    writer.writeheader()
    # every run's times in one cell each, separated by spaces
    writer.writerows({k: " ".join(f"{t:.6f}" for t in v) if isinstance(v, list) else v
                      for k, v in r.items()} for r in rows)
    atomic_write_text(paths["csv"], buffer.getvalue())
    atomic_write_text(paths["json"], to_json({"command": command, **meta, "rows": rows}) + "\n")
    save_figure(peer_figure(rows), paths["png"])
    machine = meta.get("machine", {})
    head = [f"# Peer benchmark: GetFEM and signorini on Hertz's contact", "",
            f"`{command}` — {machine.get('date', '')}, {machine.get('cpu', '')} "
            f"({machine.get('cores', '?')} cores), GetFEM {meta.get('getfem', '?')}, "
            f"signorini {machine.get('versions', {}).get('signorini', '?')}.", "",
            f"Whole-process wall time: the fastest of {meta.get('repeat', '?')} runs, each from "
            "process start to exit, with Python's byte-code cache on as on a user's machine. "
            + (f"In process: the fastest of {meta['in_process']} solves after one warm-up, in one "
               "process per code and rung, each solve from the mesh to the answer's record (the "
               "imports not counted). " if meta.get("in_process") else "In process: not measured. ")
            + "'inside' is the time the code reports for its own phases (the fastest whole-process run's). "
            "p₀ and a: one least-squares fit of each code's nodal pressures "
            "(`signorini.studies.peer.fit_hertz`), against Hertz for the applied load. "
            "GetFEM's dofs are all its displacement dofs; signorini's its free dofs.", ""]
    if "load_average" in meta:
        before, after = (", ".join(f"{v:.1f}" for v in meta["load_average"][k]) for k in ("before", "after"))
        head += [f"Load average of the machine (1, 5, 15 min) before the runs: {before}; after: "
                 f"{after} (other work on the machine slows both codes alike).", ""]
    atomic_write_text(paths["md"], "\n".join(head + peer_table(rows) + [
        "", "![time against accuracy, whole process and in process](peer.png)", ""]))
    return paths
