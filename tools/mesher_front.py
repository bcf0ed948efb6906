"""Accuracy against in-process time for each mesher of the Hertz discs, over a family of sizes.

    .venv/bin/python tools/mesher_front.py        # a few minutes; writes docs/mesher/front.json
                                                   # and docs/mesher/front.png

For hertz-cylinder and hertz-sphere (a/R = 0.05, ν = 0.3) and
each mesher (``signorini.scenes.meshing.MESHERS``), the scene is solved by the public API
(``signorini.solve(scene, params=...)``, the default route: mesh, assembly, load control, the
method, the certificate, the estimate) on a grid of meshes, :data:`GRID`: ``n_contact`` from
about 0.6 to 1.4 times the former default (40 and 60) and the grading from 0.15 down to 0.07 (a
finer far field), each scene's default mesh among them (marked ◆ in the table).
The time is the best of :data:`REPEAT` solves' CPU time in this process (other work on the
cores stretches the wall time, not the CPU time), the meshers taken in turn at each size so that they share the machine's load; the error is the larger of Hertz's
a and p₀ errors (the ``hertz`` comparison of the result). A point is on the front when no
other point of its scene is both faster and more accurate. ``table`` renders the run for
docs/mesher.md (tools/readme.py writes it).
"""

from __future__ import annotations

import json
import os
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

import signorini
from signorini.files import atomic_write_text, to_json
from signorini.scenes import SCENES as SCENE_FAMILIES
from signorini.scenes.meshing import MESHERS, graded_unit_disc

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "mesher" / "front.json"
FIGURE = ROOT / "docs" / "mesher" / "front.png"
#: (n_contact values, gradings) per scene
GRID = {"hertz-cylinder": ((24, 40, 56), (0.15, 0.11, 0.1, 0.07)),
        "hertz-sphere": ((36, 48, 60, 84), (0.15, 0.1, 0.07))}
RATIO, NU, REPEAT = 0.05, 0.3, 3


def solve_timed(scene: str, params: dict) -> tuple[signorini.Result, float]:
    """The result and the best of :data:`REPEAT` in-process CPU times of the whole solve (the
    process's: other work sharing the cores stretches the wall time, not this), each meshed afresh
    (the graded disc's cache cleared: a repeated solve would re-use the mesh)."""
    times, result = [], None
    for _ in range(REPEAT):
        graded_unit_disc.cache_clear()
        start = time.process_time()
        result = signorini.solve(scene, params=params)
        times.append(time.process_time() - start)
    return result, min(times)


def run() -> list[dict]:
    rows = []
    for scene, (contacts, gradings) in GRID.items():
        signorini.solve(scene)  # imports and first-call caches out of the timings
        for n_contact, grading in ((n, g) for n in contacts for g in gradings):
            for mesher in MESHERS:
                params = {"mesher": mesher, "n_contact": n_contact,
                          "grading": grading, "a_over_R": RATIO, "nu": NU}
                result, seconds = solve_timed(scene, params)
                hertz = result.hertz
                rows.append({"scene": scene, **params, "status": result.status,
                             "dofs": result.problem.n, "seconds": seconds,
                             "a_err": hertz.a / hertz.a_ref - 1, "p0_err": hertz.p0 / hertz.p0_ref - 1})
                print(f"{scene} {mesher} n_contact {params['n_contact']} grading {grading}: "
                      f"{result.problem.n} dofs {seconds:.3f} s, a {rows[-1]['a_err']:+.2e} p0 {rows[-1]['p0_err']:+.2e}",
                      file=sys.stderr)
    return rows


def error(row: dict) -> float:
    return max(abs(row["a_err"]), abs(row["p0_err"]))


def on_front(rows: list[dict]) -> list[dict]:
    """The rows of each scene that no other row of it beats in both time and error."""
    return [r for r in rows if not any(
        o["scene"] == r["scene"] and o["seconds"] <= r["seconds"] and error(o) <= error(r)
        and (o["seconds"] < r["seconds"] or error(o) < error(r)) for o in rows)]


def is_default(row: dict) -> bool:
    """The row is its scene's default mesh (at this a/R and ν)."""
    default = SCENE_FAMILIES[row["scene"]].parse({})
    return all(row[k] == default[k] for k in ("mesher", "n_contact", "grading"))


def table(rows: list[dict]) -> str:
    """One row per scene, size and mesher; a star marks the points on the front, a ◆ the default."""
    front = {id(r) for r in on_front(rows)}
    lines = ["| scene | n_contact | grading | mesher | dofs | CPU time in process | a error | p₀ error "
             "| front |", "|---|---:|---:|---|---:|---:|---:|---:|:---:|"]
    lines += [f"| {r['scene']} | {r['n_contact']} | {r['grading']:g} | {r['mesher']} | {r['dofs']:,} | "
              f"{1000 * r['seconds']:.0f} ms | {100 * r['a_err']:+.3f} % | {100 * r['p0_err']:+.3f} % | "
              f"{'★' if id(r) in front else ''}{' ◆' if is_default(r) else ''} |" for r in rows]
    return "\n".join(lines)


def figure(rows: list[dict], path: Path = FIGURE) -> None:
    """Error against time, one panel per scene, one line per mesher, the front circled."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    fig, axes = plt.subplots(1, len(scenes), figsize=(5 * len(scenes), 4), squeeze=False)
    front = on_front(rows)
    for ax, scene in zip(axes[0], scenes):
        for mesher in MESHERS:
            group = [r for r in rows if r["scene"] == scene and r["mesher"] == mesher]
            ax.loglog([1000 * r["seconds"] for r in group], [100 * error(r) for r in group],
                      "o", label=mesher)
        best = sorted((r for r in front if r["scene"] == scene), key=lambda r: r["seconds"])
        ax.loglog([1000 * r["seconds"] for r in best], [100 * error(r) for r in best], "k--",
                  lw=0.8, label="front")
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set(title=scene, xlabel="whole solve in process, CPU [ms]",
               ylabel="max(|a error|, |p₀ error|) [%]")
        ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def load(path: Path = OUT) -> list[dict]:
    return json.loads(path.read_text())["rows"]


def machine_load(path: Path = OUT) -> str:
    run_ = json.loads(path.read_text())
    return (f"Measured {run_['measured']} on the machine's {run_['cores']} cores at a one-minute load "
            f"average of {run_['load_average'][0]:.1f} before and {run_['load_average'][1]:.1f} after "
            f"(`{run_['command']}`).")


if __name__ == "__main__":
    before = os.getloadavg()[0]
    measured = run()
    atomic_write_text(OUT, to_json({
        "command": "python tools/mesher_front.py", "cores": os.cpu_count(),
        "measured": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "load_average": [before, os.getloadavg()[0]], "rows": measured}))
    figure(measured)
    print(f"written: {OUT}, {FIGURE}", file=sys.stderr)
