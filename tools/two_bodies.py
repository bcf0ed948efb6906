"""Two elastic bodies: the contact patch test and Hertz between two cylinders, per discretisation.

    .venv/bin/python tools/two_bodies.py      # about five minutes; writes docs/two-bodies/runs.json
    .venv/bin/python tools/two_bodies.py --figure   # docs/two-bodies/cylinders-deformed.png
    .venv/bin/python tools/two_bodies.py --cost     # docs/two-bodies/cost.json (a minute)

Every run is a task of the studies' runner (signorini.studies.runner): pdas (at tol 1e-10 on
the blocks, 1e-8 on the cylinders: ``CYLINDERS_TOL``) on the scene as signorini.solve builds
it, measured against the scene's reference.

- ``patch``: two-block-patch with two materials (E1 = 1, ν1 = 0.3 below; E2 = 3, ν2 = 0.2,
  H2 = 0.7 above), for each contact discretisation and mesh ratio: the largest relative
  error of the nodal pressures λ/w against the uniform δ / (H1/E1* + H2/E2*).
- ``cylinders``: hertz-two-cylinders on its default mesh, for equal cylinders, for two
  materials and radii (also in SI units), and for a stiff large lower cylinder (E2 = 10⁶,
  R2 = 10³) beside hertz-cylinder at the same load P.
- ``dissimilar``: equal radii and ν, E1/E2 = 1, 3 and 1/3, with the rows' normal vertical
  (the default) or each master segment's, on the default mesh and a finer one.

``--cost`` times two bodies against one of about as many dofs: hertz-two-cylinders at its
defaults and hertz-cylinder at refine=1, each solved in process by ``signorini.solve`` with
pdas and with auto, the two scenes in turn, :data:`COST_REPEAT` times; the fastest of each is
kept with the work counted (factorisations, back-solves) and the machine's load average.

docs/two-bodies.md quotes the tables that ``tables`` and ``cost_table`` render from the JSON
(tools/readme.py writes them).
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

import numpy as np

from signorini.references.analytic import contact_modulus, hertz_cylinder_load
from signorini.files import atomic_write_text, to_json
from signorini.studies.runner import run_tasks
from signorini.studies.task import Task

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "two-bodies" / "runs.json"
COST = OUT.parent / "cost.json"
#: two bodies and one body of about as many dofs, and how often each is solved for its time
COST_SCENES = (("hertz-two-cylinders", {}), ("hertz-cylinder", {"refine": 1}))
COST_REPEAT = 5
DISCRETISATIONS = ("mortar", "mortar-standard", "nts")
MESH_RATIOS = (1.0, 1.7, 1 / 1.7, 3.3, 1 / 3.3)
PATCH = {"E2": 3.0, "nu2": 0.2, "H2": 0.7}
#: hertz-cylinder's default load (a/R = 0.05, E = 1, ν = 0.3), given to both scenes as P
RIGID_P = hertz_cylinder_load(0.05, 1.0, contact_modulus(1.0, 0.3))
PAIRS = {"equal": {}, "different": {"E2": 3.0, "nu2": 0.2, "R2": 2.0},
         "steel on aluminium, SI": {"E1": 2.1e11, "E2": 7e10, "nu2": 0.33, "R1": 0.01, "R2": 0.02},
         "stiff and large": {"E2": 1e6, "R2": 1e3, "P": RIGID_P}}
#: E1/E2 (equal radii and ν) on the default mesh and on one twice as fine across the contact
STIFFNESS_RATIOS = (1.0, 3.0, 1 / 3)
MESHES = ((48, 0.12), (80, 0.075))
NORMALS = ("vertical", "master")
TIME_LIMIT = 300.0
#: the certificate's tolerance for the cylinders: the stiff pair's K spans a stiffness contrast of
#: 10⁶ on elements from 10⁻³ to 250, and its stationarity residual stays near 3e-9 (round-off)
CYLINDERS_TOL = 1e-8


def cases() -> list[dict]:
    out = [{"table": "patch", "scene": "two-block-patch", "discretisation": d, "label": f"{r:.3g}",
            "tol": 1e-10, "params": {**PATCH, "mesh_ratio": r, "discretisation": d}}
           for d in DISCRETISATIONS for r in MESH_RATIOS]
    out += [{"table": "cylinders", "scene": "hertz-two-cylinders", "discretisation": d,
             "label": name, "tol": CYLINDERS_TOL, "params": {**params, "discretisation": d}}
            for name, params in PAIRS.items() for d in ("mortar", "nts")]
    out.append({"table": "cylinders", "scene": "hertz-cylinder", "discretisation": "rigid flat",
                "label": "stiff and large", "tol": CYLINDERS_TOL, "params": {"P": RIGID_P}})
    out += [{"table": "dissimilar", "scene": "hertz-two-cylinders", "discretisation": "mortar",
             "label": f"{ratio:.3g}", "normal": normal, "tol": CYLINDERS_TOL,
             "params": {"E1": ratio, "normal": normal, "n_contact": n_contact, "grading": grading}}
            for normal in NORMALS for ratio in STIFFNESS_RATIOS for n_contact, grading in MESHES]
    return out


def task(case: dict) -> Task:
    """The runner's task of a case: pdas at the case's tol on the scene as signorini.solve builds it."""
    return Task(axis=case["table"], case=case["scene"], value=case["label"],
                problem={"kind": "scene", "scene": case["scene"], "matched": False,
                         "params": case["params"]},
                method="pdas", tol=case["tol"], reference={"kind": "none"}, measure=("reference",))


def row_of(case: dict, row: dict) -> dict:
    """The study's row from the runner's: the scene's comparison with its reference."""
    return {**case, "status": row["status"], "dofs": row["dofs"],
            "candidates": row["candidates"], "reference": row.get("reference") or {},
            "seconds": row["time_s"]}


def run(chosen: list[dict] | None = None) -> list[dict]:
    chosen = cases() if chosen is None else chosen
    rows = run_tasks([task(c) for c in chosen], time_limit=TIME_LIMIT, progress=lambda i, n, t, r:
                     print(f"{i}/{n} {t.case} {t.problem['params']}: {r['status']}", file=sys.stderr))
    return [row_of(case, row) for case, row in zip(chosen, rows)]


def tables(rows: list[dict]) -> dict[str, str]:
    """Markdown tables by name: the patch test's pressure error; the cylinders against Hertz."""
    patch = [r for r in rows if r["table"] == "patch"]
    lines = ["| mesh ratio | dofs | " + " | ".join(DISCRETISATIONS) + " |",
             "|---:|---:|" + "---:|" * len(DISCRETISATIONS)]
    for label in dict.fromkeys(r["label"] for r in patch):
        group = {r["discretisation"]: r for r in patch if r["label"] == label}
        lines.append(f"| {label} | {group['mortar']['dofs']:,} | " + " | ".join(
            f"{group[d]['reference']['pressure_max_rel']:.1e}" for d in DISCRETISATIONS) + " |")
    out = {"patch": "\n".join(lines)}
    lines = ["| cylinders | scene | discretisation | dofs | status | a / a_Hertz − 1 | "
             "p₀ / p₀,Hertz − 1 | a against hertz-cylinder | p₀ against hertz-cylinder |",
             "|---|---|---|---:|---|---:|---:|---:|---:|"]
    cylinders = [r for r in rows if r["table"] == "cylinders"]
    rigid = next(r["reference"] for r in cylinders if r["scene"] == "hertz-cylinder")
    for r in cylinders:
        h = r["reference"]
        against = (f"{_pct(h['a'] / rigid['a'] - 1)} | {_pct(h['p0'] / rigid['p0'] - 1)}"
                   if r["label"] == "stiff and large" else "| ").strip()
        lines.append(f"| {r['label']} | {r['scene']} | {r['discretisation']} | {r['dofs']:,} | "
                     f"{r['status']} | {_pct(h['a'] / h['a_ref'] - 1)} | "
                     f"{_pct(h['p0'] / h['p0_ref'] - 1)} | {against} |")
    out["cylinders"] = "\n".join(lines)
    lines = ["| normal | E1 / E2 | " + " | ".join(f"n_contact = {n}: dofs, a, p₀" for n, _ in MESHES)
             + " |", "|---|---:|" + "---|" * len(MESHES)]
    dissimilar = [r for r in rows if r["table"] == "dissimilar"]
    for key in dict.fromkeys((r["normal"], r["label"]) for r in dissimilar):
        cells = [f"{r['dofs']:,}: {_pct(r['reference']['a'] / r['reference']['a_ref'] - 1)}, "
                 f"{_pct(r['reference']['p0'] / r['reference']['p0_ref'] - 1)}"
                 for r in dissimilar if (r["normal"], r["label"]) == key]
        lines.append(f"| {key[0]} | {key[1]} | " + " | ".join(cells) + " |")
    out["dissimilar"] = "\n".join(lines)
    return out


def _pct(x: float) -> str:
    return f"{100 * x:+.3f} %"


def figure(path: Path = OUT.parent / "cylinders-deformed.png") -> Path:
    """Both deformed cylinders (E2 = 3 E1, R2 = 2 R1, on the default mesh) near the contact, at
    true scale, and their contact pressure."""
    import signorini
    from signorini.files import save_figure
    from signorini.output.export import candidate_nodes, nodal_displacement
    from signorini.output.plots import deformed_bodies
    from signorini.references.pressure import contact_profile

    result = signorini.solve("hertz-two-cylinders", "pdas", params=PAIRS["different"])
    problem, solution = result.problem, result.solution
    body = np.repeat([1, 2], [material[0] for material in problem.model.materials])
    ax = deformed_bodies(problem.model.mesh.p * problem.scales.length, problem.model.mesh.t,
                         nodal_displacement(problem, solution), body, candidate_nodes(problem),
                         contact_profile(problem, solution).pressure, magnify=1.0)
    a = result.comparison.a
    ax.set_xlim(0.0, 2.5 * a)
    ax.set_ylim(-1.2 * a, 1.2 * a)
    ax.set_title(f"hertz-two-cylinders, E2 = 3 E1, R2 = 2 R1 ({problem.n:,} dofs):\n"
                 f"deformed at true scale near the contact, a = {a:.4f}", fontsize=8)
    save_figure(ax.figure, path)
    return path


def load() -> list[dict]:
    return json.loads(OUT.read_text())["rows"]


def cost() -> dict:
    """In-process time and work of two bodies against one body of about as many dofs."""
    import signorini
    from signorini.numerics.factor import counting

    rows, before = [], os.getloadavg()[0]
    for method in ("pdas", "auto"):
        best: dict[str, dict] = {}
        for _ in range(COST_REPEAT):
            for scene, params in COST_SCENES:
                with counting() as work:
                    start = time.perf_counter()
                    result = signorini.solve(scene, method, params=params)
                    seconds = time.perf_counter() - start
                if scene not in best or seconds < best[scene]["seconds"]:
                    best[scene] = {"scene": scene, "method": method, "dofs": result.problem.n,
                                   "status": result.status, "seconds": seconds,
                                   "factorisations": work.factorisations,
                                   "back_solves": work.back_solves}
        rows += best.values()
    return {"command": "python tools/two_bodies.py --cost", "cores": os.cpu_count(),
            "load_average": [before, os.getloadavg()[0]], "rows": rows}


def cost_table(record: dict) -> str:
    """Two bodies against one, per method: dofs, time in process, work, and the ratios."""
    lines = [f"Fastest of {COST_REPEAT} in-process solves each, the scenes in turn, on the "
             f"machine's {record['cores']} cores at a load average of "
             f"{record['load_average'][0]:.1f} before and {record['load_average'][1]:.1f} after "
             f"(`{record['command']}`).", "",
             "| method | scene | dofs | status | time | factorisations | back-solves | "
             "time, two bodies / one |", "|---|---|---:|---|---:|---:|---:|---:|"]
    for method in dict.fromkeys(r["method"] for r in record["rows"]):
        two, one = (next(r for r in record["rows"] if r["method"] == method and r["scene"] == s)
                    for s, _ in COST_SCENES)
        for r in (one, two):
            ratio = f"{two['seconds'] / one['seconds']:.2f}" if r is two else ""
            lines.append(f"| {method} | {r['scene']} | {r['dofs']:,} | {r['status']} | "
                         f"{r['seconds']:.3f} s | {r['factorisations']} | {r['back_solves']} | "
                         f"{ratio} |")
    return "\n".join(lines)


if __name__ == "__main__":
    if "--figure" in sys.argv:
        sys.exit(print(f"written: {figure()}", file=sys.stderr))
    if "--cost" in sys.argv:
        atomic_write_text(COST, to_json(cost()))
        sys.exit(print(cost_table(json.loads(COST.read_text()))))
    if "--tables" not in sys.argv:
        rows = run()
        atomic_write_text(OUT, to_json({"command": "python tools/two_bodies.py", "rows": rows}))
        print(f"written: {OUT}", file=sys.stderr)
    for name, table in tables(load()).items():
        print(f"{name}:\n\n{table}\n")
