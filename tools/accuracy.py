"""Where the Hertz scenes' difference to Hertz comes from: loading, mesh grading, ν, finite body.

    .venv/bin/python tools/accuracy.py        # ~4 min here; writes docs/accuracy/runs.json

Every run is a task of the studies' runner (signorini.studies.runner): pdas at tol 1e-10 on
the scene as signorini.solve builds it (its load matched with the answer), measured against
the scene's reference; p₀ and a are Hertz's profile fitted to the nodal pressures
(signorini.references.profile.hertz_fit).
docs/accuracy.md quotes the tables that ``tables`` renders from the JSON
(tools/readme.py writes them there; tests/test_readme_numbers.py holds them).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from signorini.files import atomic_write_text, to_json
from signorini.studies.runner import run_tasks
from signorini.studies.task import Task

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "accuracy" / "runs.json"
NUS = (0.0, 0.3, 0.45)
#: (loading, mesher, n_contact, grading): the former default first, the current default marked
CYLINDER_MESHES = (("displacement", "bisection", 120, 0.15), ("traction", "bisection", 120, 0.15),
                   ("traction", "bisection", 40, 0.1), ("traction", "bisection", 60, 0.05),
                   ("traction", "relaxed", 16, 0.15), ("traction", "relaxed", 40, 0.15),
                   ("traction", "relaxed", 48, 0.12))
SPHERE_MESHES = (("displacement", "bisection", 100, 0.15), ("traction", "bisection", 100, 0.15),
                 ("traction", "relaxed", 40, 0.15), ("traction", "relaxed", 60, 0.15),
                 ("traction", "relaxed", 100, 0.15))
DEFAULTS = {"hertz-cylinder": (40, 0.15), "hertz-sphere": (60, 0.15)}
RATIOS = (0.05, 0.025, 0.0125)
#: plain P1 against the volumetric strain averaged at the nodes, on the default mesh and a finer one
VOLUMETRIC_NUS = (0.3, 0.4, 0.45, 0.49, 0.499)
VOLUMETRIC_MESHES = {"hertz-cylinder": (40, 80), "hertz-sphere": (60, 120)}
#: seconds a case may take in the runner's worker
TIME_LIMIT = 300.0


def cases() -> list[dict]:
    out = []
    for table, scene, meshes in (("cylinder", "hertz-cylinder", CYLINDER_MESHES),
                                 ("sphere", "hertz-sphere", SPHERE_MESHES)):
        for loading, mesher, n_contact, grading in meshes:
            for nu in NUS:
                out.append({"table": table, "scene": scene, "loading": loading, "mesher": mesher,
                            "n_contact": n_contact, "grading": grading, "nu": nu, "a_over_R": 0.05,
                            "volumetric": "element"})
    for scene, (n_contact, grading) in DEFAULTS.items():
        for nu in NUS:
            for ratio in RATIOS:
                out.append({"table": "finite-body", "scene": scene, "loading": "traction",
                            "mesher": "relaxed", "n_contact": n_contact, "grading": grading,
                            "nu": nu, "a_over_R": ratio, "volumetric": "auto"})
    for scene, meshes in VOLUMETRIC_MESHES.items():
        for n_contact in meshes:
            for volumetric in ("element", "nodal"):
                for nu in VOLUMETRIC_NUS:
                    out.append({"table": "volumetric", "scene": scene, "loading": "traction",
                                "mesher": "relaxed", "n_contact": n_contact, "grading": 0.15,
                                "nu": nu, "a_over_R": 0.05, "volumetric": volumetric})
    return out


#: the case's keys that are the scene's parameters, and those a case may add to them
PARAMS = ("loading", "mesher", "n_contact", "grading", "nu", "a_over_R", "volumetric")
OPTIONAL_PARAMS = ("refine", "E", "R")


def task(case: dict) -> Task:
    """The runner's task of a case: pdas at 1e-10 on the scene as signorini.solve builds it."""
    return Task(axis=case["table"], case=case["scene"], value=case["nu"],
                problem={"kind": "scene", "scene": case["scene"], "matched": False,
                         "params": {k: case[k] for k in PARAMS + OPTIONAL_PARAMS if k in case}},
                method="pdas", tol=1e-10, reference={"kind": "none"},
                measure=("reference", "matrix"))


def row_of(case: dict, row: dict) -> dict:
    """The study's row from the runner's: Hertz's a and p₀ fitted, the nodal p₀, the pressure L2."""
    h = row.get("reference") or {}
    nan = float("nan")
    return {**case, "status": row["status"], "dofs": row["dofs"], "nonzeros": row["nonzeros"],
            "a_err": h.get("a", nan) / h.get("a_ref", nan) - 1,
            "p0_err": h.get("p0", nan) / h.get("p0_ref", nan) - 1,
            "p0_nodal_err": h.get("p0_nodal", nan) / h.get("p0_ref", nan) - 1,
            "a_edge_err": h.get("a_edge", nan) / h.get("a_ref", nan) - 1,
            "force_balance": h.get("force_balance", nan), "a_ref": h.get("a_ref", nan),
            "l2": h.get("pressure_l2_rel", nan), "seconds": row["time_s"]}


def run(chosen: list[dict] | None = None) -> list[dict]:
    chosen = cases() if chosen is None else chosen
    rows = run_tasks([task(c) for c in chosen], time_limit=TIME_LIMIT, progress=lambda i, n, t, r:
                     print(f"{i}/{n} {t.case} {t.problem['params']}: {r['status']}", file=sys.stderr))
    return [row_of(case, row) for case, row in zip(chosen, rows)]


def _pct(x: float) -> str:
    return f"{100 * x:+.3f} %"


def tables(rows: list[dict]) -> dict[str, str]:
    """Markdown tables by name: error of a and p₀ for ν = 0, 0.3, 0.45 per model."""
    out = {}
    for table, scene_rows in (("cylinder", [r for r in rows if r["table"] == "cylinder"]),
                              ("sphere", [r for r in rows if r["table"] == "sphere"])):
        lines = ["| loading | mesher | n_contact | grading | dofs | " + " | ".join(
                     f"a, p₀ at ν = {nu:g}" for nu in NUS) + " |",
                 "|---|---|---:|---:|---:|" + "---|" * len(NUS)]
        keys = dict.fromkeys((r["loading"], r["mesher"], r["n_contact"], r["grading"])
                             for r in scene_rows)
        for key in keys:
            group = [r for r in scene_rows
                     if (r["loading"], r["mesher"], r["n_contact"], r["grading"]) == key]
            cells = [f"{_pct(r['a_err'])}, {_pct(r['p0_err'])}" for r in group]
            default = " (default)" if (key[0], key[1]) == ("traction", "relaxed") and \
                DEFAULTS[group[0]["scene"]] == (key[2], key[3]) else ""
            lines.append(f"| {key[0]} | {key[1]}{default} | {key[2]} | {key[3]:g} | "
                         f"{group[0]['dofs']:,} | " + " | ".join(cells) + " |")
        out[table] = "\n".join(lines)
    finite = [r for r in rows if r["table"] == "finite-body"]
    lines = ["| scene | ν | " + " | ".join(f"a, p₀ at a/R = {x:g}" for x in RATIOS) + " |",
             "|---|---:|" + "---|" * len(RATIOS)]
    for scene in ("hertz-cylinder", "hertz-sphere"):
        for nu in NUS:
            group = [r for r in finite if r["scene"] == scene and r["nu"] == nu]
            lines.append(f"| {scene} | {nu:g} | " + " | ".join(
                f"{_pct(r['a_err'])}, {_pct(r['p0_err'])}" for r in group) + " |")
    out["finite-body"] = "\n".join(lines)
    volumetric = [r for r in rows if r["table"] == "volumetric"]
    lines = ["| scene | n_contact | dofs | volumetric | nonzeros of K | " + " | ".join(
                 f"a, p₀ at ν = {nu:g}" for nu in VOLUMETRIC_NUS) + " |",
             "|---|---:|---:|---|---:|" + "---|" * len(VOLUMETRIC_NUS)]
    for key in dict.fromkeys((r["scene"], r["n_contact"], r["volumetric"]) for r in volumetric):
        group = [r for r in volumetric if (r["scene"], r["n_contact"], r["volumetric"]) == key]
        cells = [f"{_pct(r['a_err'])}, {_pct(r['p0_err'])}"
                 + ("" if r["status"] == "converged" else f" ({r['status']})") for r in group]
        lines.append(f"| {key[0]} | {key[1]} | {group[0]['dofs']:,} | {key[2]} | "
                     f"{group[0]['nonzeros']:,} | " + " | ".join(cells) + " |")
    out["volumetric"] = "\n".join(lines)
    return out


def load() -> list[dict]:
    return json.loads(OUT.read_text())["rows"]


if __name__ == "__main__":
    rows = run()
    atomic_write_text(OUT, to_json({"command": "python tools/accuracy.py", "rows": rows}))
    print(f"written: {OUT}", file=sys.stderr)
