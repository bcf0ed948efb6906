"""The peer benchmark's report: its tables, its chart and its files (``signorini bench --peer``).

The rows are :func:`signorini.studies.peer.run_peer`'s, one per code and rung of a
scene's ladder: the table lists every run, then each code's fastest run at the
accuracies :data:`TARGETS`, by each measure of time (:data:`MEASURES`).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from signorini.files import atomic_write_text, save_figure, to_json, writable_directory
from signorini.output import plots
from signorini.reprs import csv_text, markdown_table, number

__all__ = ["MEASURES", "NAMES", "TARGETS", "at_accuracy", "matching_table", "peer_figure", "peer_table",
           "write_peer"]

#: accuracies at which the report compares the codes' fastest runs: p₀ and a within 0.3 % and 0.1 %
TARGETS = (0.003, 0.001)


def _pct(value: Any) -> str:
    return "–" if value is None or not np.isfinite(value) else f"{100 * value:+.3f} %"


def _error(row: dict[str, Any]) -> float:
    """The larger of the p₀ and a errors (inf when the run gave none)."""
    worst = max(abs(row.get("p0_rel", math.nan)), abs(row.get("a_rel", math.nan)))
    return worst if np.isfinite(worst) else math.inf


NAMES = {"getfem": "GetFEM", "signorini": "signorini"}
#: the two measures of time: a row's key and its name in the tables
MEASURES = {"wall_s": "whole process", "in_process_s": "in process"}


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
    runs = markdown_table(
        ["scene", "code", "mesh", "dofs", "contact nodes (active)", "p₀ − Hertz", "a − Hertz",
         "force − P", "whole process [s]", "in process [s]", "inside [s]", "status"], "lllrrrrrrrrl",
        ([r["scene"], NAMES[r["code"]], r["mesh"], f"{r.get('dofs', 0):,}",
          f"{r.get('contact_nodes', '–')} ({r.get('active_nodes', '–')})", _pct(r.get("p0_rel")),
          _pct(r.get("a_rel")), _pct(r.get("force_rel")), f"{r['wall_s']:.2f}",
          number(r.get("in_process_s"), ".2f"), f"{r.get('inner_s', math.nan):.2f}", r["status"]]
         for r in rows))
    # a run recorded before the in-process measure (or with --in-process 0) has no such rows
    measures = {by: name for by, name in MEASURES.items() if any(r.get(by) is not None for r in rows)}
    return runs + [""] + markdown_table(
        ["scene", "p₀ and a within", "time", "GetFEM: fastest run", "signorini: fastest run",
         "signorini / GetFEM"], "lrlllr",
        ([scene, f"{100 * target:g} %", measure, *_fastest_cells(rows, scene, target, by)]
         for scene in dict.fromkeys(r["scene"] for r in rows) for target in TARGETS
         for by, measure in measures.items()))


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
    directory = writable_directory(out)
    paths = {k: directory / f"peer.{k}" for k in ("csv", "json", "md", "png")}
    # every run's times in one cell each, separated by spaces
    atomic_write_text(paths["csv"], csv_text(({k: " ".join(f"{t:.6f}" for t in v) if isinstance(v, list)
                                               else v for k, v in r.items()} for r in rows), CSV_COLUMNS))
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


def matching_table(rows: list[dict[str, Any]]) -> list[str]:
    """GetFEM's two-body rungs on matching and non-matching meshes (``master_ratio`` 1 against
    another), from the script's records: docs/peer-two/master-ratio.json."""
    lines = ["| h at the contact | master / slave size | dofs | slave nodes facing a master node "
             "| p₀ − Hertz | a − Hertz | Newton steps |", "|---|---:|---:|---:|---:|---:|---:|"]
    lines += [f"| {r['h_contact']} | {r['master_ratio']:g} | {r['dofs']:,} | {r['facing_nodes']} of "
              f"{r['contact_nodes']} | {_pct(r['p0_rel'])} | {_pct(r['a_rel'])} | {r['newton_iterations']} |"
              for r in rows]
    return lines
