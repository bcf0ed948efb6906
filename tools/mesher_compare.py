"""The three meshers of the Hertz discs side by side at equal dofs: time, triangle shape, Hertz errors.

    .venv/bin/python tools/mesher_compare.py      # several minutes; writes docs/mesher/runs.json

For hertz-cylinder and hertz-sphere (a/R = 0.05, ν = 0.3) and three meshes each
(the scene's default, about 2× and 4× its dofs), every choice of the scene
parameter ``mesher`` (``signorini.scenes.meshing.MESHERS``: relaxed, bisection,
triangle) meshes the quarter disc, and the scene is solved with pdas at tol 1e-10
through the public API. The relaxation moves the bisection mesh's nodes and keeps
their number; Triangle's size factor (``signorini.scenes.triangulated.TRIANGLE_SIZE``,
nodes ∝ factor⁻²) is tuned on each mesh until its node count is within 2 % of the
bisection mesh's, so that the errors compare at equal dofs. Meshing time is the
best of three calls of ``graded_quarter_disc`` in this process; triangle shape is
each triangle's smallest angle and its radius ratio 2r/R (1 for equilateral). The
machine's load average before and after is kept with every row. docs/mesher.md
quotes the tables that ``table`` and ``summary`` render (tools/readme.py writes them).
"""

from __future__ import annotations

import json
import os
import sys
import time
from contextlib import contextmanager
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

import signorini
from signorini.files import atomic_write_text, to_json
from signorini.scenes import triangulated
from signorini.scenes.meshing import MESHERS, GradedDisc, graded_quarter_disc

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "mesher" / "runs.json"
#: the first run, made on the branch that replaced the relaxation by Triangle (its meshing code
#: then differed in details: docs/mesher.md); the same measurement, and the same table
FIRST = ROOT / "docs" / "mesher" / "runs-first.json"
RATIO, NU = 0.05, 0.3
#: (n_contact, grading) of the default mesh and of about 2× and 4× its dofs
MESHES = {"hertz-cylinder": ((40, 0.15), (55, 0.11), (80, 0.07)),
          "hertz-sphere": ((60, 0.15), (90, 0.1), (120, 0.07))}
SIZES = ("default", "2x", "4x")
MATCH = 0.02
REPEAT = 3


@contextmanager
def triangle_factor(factor: float):
    """Triangle asked for edges of ``factor`` times the size field while inside."""
    saved = triangulated.TRIANGLE_SIZE
    triangulated.TRIANGLE_SIZE = factor
    try:
        yield
    finally:
        triangulated.TRIANGLE_SIZE = saved


def disc(n_contact: int, grading: float, mesher: str) -> GradedDisc:
    return graded_quarter_disc(1.0, RATIO, n_contact, grading, mesher=mesher)


def matched_factor(n_contact: int, grading: float, nodes: int) -> float:
    """Triangle's size factor whose mesh has ``nodes`` nodes within :data:`MATCH`."""
    factor = triangulated.TRIANGLE_SIZE
    for _ in range(12):
        with triangle_factor(factor):
            got = disc(n_contact, grading, "triangle").mesh.p.shape[1]
        if abs(got / nodes - 1) <= MATCH:
            return factor
        factor *= (got / nodes) ** 0.5
    raise RuntimeError(f"Triangle's mesh did not reach {nodes} nodes within {MATCH:.0%}")


def shape(mesh) -> dict[str, float]:
    """Smallest angle (degrees) and radius ratio 2r/R of every triangle: their minimum and median."""
    corners = mesh.p[:, mesh.t]  # (2, 3, triangles)
    sides = np.array([np.linalg.norm(corners[:, (i + 1) % 3] - corners[:, (i + 2) % 3], axis=0)
                      for i in range(3)])  # side i faces corner i
    cosines = [(sides[(i + 1) % 3] ** 2 + sides[(i + 2) % 3] ** 2 - sides[i] ** 2)
               / (2 * sides[(i + 1) % 3] * sides[(i + 2) % 3]) for i in range(3)]
    smallest = np.degrees(np.arccos(np.clip(np.max(cosines, axis=0), -1.0, 1.0)))
    s = 0.5 * sides.sum(axis=0)
    area = np.sqrt(np.maximum(s * (s - sides[0]) * (s - sides[1]) * (s - sides[2]), 0.0))
    ratio = 2 * (area / s) / (sides.prod(axis=0) / (4 * area))
    return {"min_angle": float(smallest.min()), "median_min_angle": float(np.median(smallest)),
            "min_radius_ratio": float(ratio.min()), "median_radius_ratio": float(np.median(ratio))}


def timed_disc(n_contact: int, grading: float, mesher: str) -> tuple[GradedDisc, float]:
    """The disc and the best of :data:`REPEAT` times to mesh it."""
    times = []
    for _ in range(REPEAT):
        start = time.perf_counter()
        made = disc(n_contact, grading, mesher)
        times.append(time.perf_counter() - start)
    return made, min(times)


def run() -> list[dict]:
    rows = []
    for scene, meshes in MESHES.items():
        for size, (n_contact, grading) in zip(SIZES, meshes):
            nodes = disc(n_contact, grading, "bisection").mesh.p.shape[1]
            factor = matched_factor(n_contact, grading, nodes)
            for mesher in MESHERS:
                params = {"mesher": mesher, "n_contact": n_contact, "grading": grading,
                          "nu": NU, "a_over_R": RATIO}
                with triangle_factor(factor):
                    made, seconds = timed_disc(n_contact, grading, mesher)
                    result = signorini.solve(scene, params=params, tol=1e-10)
                hertz = result.hertz
                rows.append({"scene": scene, "size": size, **params,
                             "triangle_size": factor if mesher == "triangle" else None,
                             "status": result.status, "dofs": result.problem.n,
                             "mesh_seconds": seconds, **shape(made.model.mesh),
                             "a_err": hertz.a / hertz.a_ref - 1, "p0_err": hertz.p0 / hertz.p0_ref - 1})
                print(f"{scene} {params} {result.problem.n} dofs {seconds:.3f} s: "
                      f"a {rows[-1]['a_err']:+.2e} p0 {rows[-1]['p0_err']:+.2e}", file=sys.stderr)
    return rows


def _pct(x: float) -> str:
    return f"{100 * x:+.3f} %"


def table(rows: list[dict]) -> str:
    """One row per scene, mesh and mesher: dofs, meshing time, triangle shape, Hertz errors."""
    lines = ["| scene | mesh | mesher | dofs | meshing time | smallest angle: min, median | "
             "radius ratio: min, median | a error | p₀ error |",
             "|---|---|---|---:|---:|---|---|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['size']} ({r['n_contact']}, {r['grading']:g}) | {r['mesher']} "
                     f"| {r['dofs']:,} | {r['mesh_seconds']:.3f} s | {r['min_angle']:.1f}°, "
                     f"{r['median_min_angle']:.1f}° | {r['min_radius_ratio']:.2f}, "
                     f"{r['median_radius_ratio']:.2f} | {_pct(r['a_err'])} | {_pct(r['p0_err'])} |")
    return "\n".join(lines)


def summary(rows: list[dict]) -> str:
    """Per scene and mesher: meshing time on each mesh, and the largest error over the three."""
    lines = ["| scene | mesher | meshing time: default, 2×, 4× | largest \\|a error\\| | "
             "largest \\|p₀ error\\| |", "|---|---|---|---:|---:|"]
    for key in dict.fromkeys((r["scene"], r["mesher"]) for r in rows):
        group = [r for r in rows if (r["scene"], r["mesher"]) == key]
        times = ", ".join(f"{r['mesh_seconds']:.3f}" for r in group)
        lines.append(f"| {key[0]} | {key[1]} | {times} s | {100 * max(abs(r['a_err']) for r in group):.3f} % "
                     f"| {100 * max(abs(r['p0_err']) for r in group):.3f} % |")
    return "\n".join(lines)


def machine_load(path: Path = OUT) -> str:
    """One sentence: the lowest and highest one-minute load average kept with the run's rows."""
    run_ = json.loads(path.read_text())
    loads = [x for r in run_["rows"] for x in r["load_average"]]
    return (f"Run at a one-minute load average of {min(loads):.1f}–{max(loads):.1f} on the machine's "
            f"{run_['cores']} cores (taken before and after the run, kept with every row of the JSON).")


def load(path: Path = OUT) -> list[dict]:
    return json.loads(path.read_text())["rows"]


if __name__ == "__main__":
    load_before = os.getloadavg()[0]
    measured = run()
    stamp = datetime.now(timezone.utc).isoformat(timespec="seconds")
    rows = [{**r, "measured": stamp, "load_average": [load_before, os.getloadavg()[0]]} for r in measured]
    atomic_write_text(OUT, to_json({"command": "python tools/mesher_compare.py",
                                    "cores": os.cpu_count(), "rows": rows}))
    print(f"written: {OUT}", file=sys.stderr)
