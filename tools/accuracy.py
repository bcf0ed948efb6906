"""Where the Hertz scenes' difference to Hertz comes from: loading, mesh grading, ν, finite body.

    .venv/bin/python tools/accuracy.py        # ~4 min here; writes docs/accuracy/runs.json

Every run solves with pdas at tol 1e-10 through the public API; p₀ and a are
Hertz's profile fitted to the nodal pressures (signorini.pressure.hertz_fit).
docs/accuracy.md quotes the tables that ``tables`` renders from the JSON
(tools/readme.py writes them there; tests/test_readme_numbers.py holds them).
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import signorini
from signorini.files import atomic_write_text, to_json

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


def run() -> list[dict]:
    rows = []
    for i, case in enumerate(cases(), 1):
        params = {k: case[k] for k in ("loading", "mesher", "n_contact", "grading", "nu", "a_over_R",
                                       "volumetric")}
        start = time.perf_counter()
        result = signorini.solve(case["scene"], params=params, tol=1e-10)
        hertz = result.hertz
        rows.append({**case, "status": result.status, "dofs": result.problem.n,
                     "nonzeros": int(result.problem.K.nnz),
                     "a_err": hertz.a / hertz.a_ref - 1, "p0_err": hertz.p0 / hertz.p0_ref - 1,
                     "p0_nodal_err": hertz.p0_nodal / hertz.p0_ref - 1,
                     "l2": hertz.pressure_l2_rel, "seconds": time.perf_counter() - start})
        print(f"{i}/{len(cases())} {case['scene']} {params}: {rows[-1]['a_err']:+.2e}",
              file=sys.stderr)
    return rows


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
