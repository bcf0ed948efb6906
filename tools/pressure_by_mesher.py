"""The contact pressure's estimate against its true error on each mesher's meshes of the Hertz
discs (docs/estimate.md, "The pressure estimate on each mesher").

    .venv/bin/python tools/pressure_by_mesher.py   # about a minute; the ``meshers`` rows of
                                                   # docs/estimate/runs.json, and their table

Each mesh is solved exactly (tools/estimate.py's ``solve``) and against the same mesh two uniform
refinements finer, whose nodal pressure along the arc is the reference (``pressure_error``).
"""

from __future__ import annotations

import json
import sys

from estimate import EFFECTIVITY_HEADER, OUT, SCENES, effectivity_cells, pressure_error, solve
from signorini.files import atomic_write_text, to_json

MESHERS = ("triangle", "bisection", "relaxed")
#: the pressure estimate against the true error on each mesher's meshes (ν = 0.3): the coarse
#: base and a mesh of about the default's dofs, the error against the same mesh two refinements
#: finer
MESHER_BASES = {"hertz-cylinder": ((16, 0.2), (24, 0.11)), "hertz-sphere": ((16, 0.2), (36, 0.15))}


def run() -> list[dict]:
    rows = []
    for scene in SCENES:
        for mesher in MESHERS:
            for n_contact, grading in MESHER_BASES[scene]:
                coarse, _ = solve(scene, n_contact, grading, 0, mesher=mesher)
                fine, _ = solve(scene, n_contact, grading, 2, mesher=mesher)
                error = pressure_error(coarse, fine)
                rows.append({"scene": scene, "mesher": mesher, "n_contact": n_contact, "grading": grading,
                             "dofs": coarse.problem.n, "pressure_estimate": coarse.estimate.pressure.relative,
                             "pressure_error": error,
                             "effectivity": coarse.estimate.pressure.relative / error})
                print(rows[-1], file=sys.stderr)
    return rows


def table(rows: list[dict]) -> str:
    lines = ["| scene | mesher | mesh (n_contact, grading) | dofs " + EFFECTIVITY_HEADER,
             "|---|---|---|---:|---:|---:|---:|"]
    lines += [f"| {r['scene']} | {r['mesher']} | {r['n_contact']}, {r['grading']:g} | {r['dofs']:,} "
              + effectivity_cells(r) for r in rows]
    return "\n".join(lines)


if __name__ == "__main__":
    record = json.loads(OUT.read_text())
    record["meshers"] = run()
    record.setdefault("commands", {})["meshers"] = "python tools/pressure_by_mesher.py"
    atomic_write_text(OUT, to_json(record))
    print(table(record["meshers"]))
