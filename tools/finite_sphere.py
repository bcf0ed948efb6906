"""The finite sphere against Hertz's half-space: the axisymmetric sphere's difference from Hertz
under uniform refinement, at contact radii a/R from 0.05 down, for ν = 0, 0.3 and 0.45.

    .venv/bin/python tools/finite_sphere.py        # ~20 min here; writes docs/accuracy/finite-sphere.json
    .venv/bin/python tools/finite_sphere.py --doc  # docs/accuracy.md's tables from the JSON

A discretisation error falls under refinement and, at a fixed number of elements across a,
does not depend on a/R; the difference between a finite sphere and a half-space stays under
refinement and falls with a/R. Each series refines the scene's default mesh uniformly (refine
0, 1, 2: each halves every element); the finest level stands for the model's own answer, and the
change from the level before for how far it still is from it. A second table holds meshes of
at most 10,000 dofs at a/R = 0.05 and at a light load, a/R = 0.0025, for ν = 0, 0.3 and 0.45
(the last in two sets of units).
Every run is tools/accuracy.py's task (pdas at tol 1e-10, the studies' runner), so p₀ and a are
Hertz's profile fitted to the nodal pressures (signorini.references.profile.hertz_fit).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import accuracy  # noqa: E402  (tools/accuracy.py: the task and row of one accuracy run)

from signorini.scenes.registry import SCENES  # noqa: E402
from signorini.studies.runner import run_tasks  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "accuracy" / "finite-sphere.json"
SCENE = "hertz-sphere"
#: the series: ν, contact radii, one graded mesh refined uniformly; the rate is fitted where the
#: difference stands clear of the discretisation's (at ν = 0.45 it is within 0.04 % at every a/R)
SERIES_NUS = (0.0, 0.3, 0.45)
RATE_NUS = (0.0, 0.3)
RATIOS = (0.05, 0.025, 0.0125, 0.00625, 0.0025)
LEVELS = (0, 1, 2)
#: the meshes of at most 10k dofs: (a/R, n_contact, grading, units), Triangle's (None: the
#: scene's default); units are the scene's own or a steel sphere's of radius 10 mm
MESH_NUS = (0.0, 0.3, 0.45)
UNITS = {"E = R = 1": {}, "steel, R = 10 mm": {"E": 2.1e11, "R": 0.01}}
MESHES = ((0.05, None, None, "E = R = 1"), (0.0025, None, None, "E = R = 1"),
          (0.0025, 40, 0.12, "E = R = 1"), (0.0025, 40, 0.12, "steel, R = 10 mm"))
#: the model's difference from Hertz the scene's default a/R is chosen to stay under
MODEL_ERROR = 1e-4


def scene_default(name: str):
    return next(p.default for p in SCENES[SCENE].params if p.name == name)


def cases() -> list[dict]:
    base = {"scene": SCENE, "loading": "traction", "volumetric": "auto", "mesher": "triangle"}
    default = {key: scene_default(key) for key in ("n_contact", "grading")}
    out = [{**base, "table": "series", **default, "nu": nu, "a_over_R": ratio, "refine": level}
           for nu in SERIES_NUS for ratio in RATIOS for level in LEVELS]
    for ratio, n_contact, grading, units in MESHES:
        mesh = default if n_contact is None else {"n_contact": n_contact, "grading": grading}
        out += [{**base, "table": "meshes", **mesh, "nu": nu, "a_over_R": ratio, "refine": 0,
                 "units": units, **UNITS[units]} for nu in MESH_NUS]
    return out


def run() -> dict:
    from readme import provenance  # tools/readme.py: where a study's run was made

    chosen = cases()
    rows = run_tasks([accuracy.task(c) for c in chosen], time_limit=accuracy.TIME_LIMIT,
                     progress=lambda i, n, t, r: print(f"{i}/{n} {t.problem['params']}: {r['status']}",
                                                       file=sys.stderr))
    return {**provenance("finite_sphere.py"),
            "rows": [accuracy.row_of(case, row) for case, row in zip(chosen, rows)]}


def load() -> list[dict]:
    return json.loads(OUT.read_text())["rows"]


def limits(rows: list[dict]) -> list[dict]:
    """Per ν and a/R: the finest level's errors of a and p₀, the change from the level before."""
    out = []
    series = [r for r in rows if r["table"] == "series"]
    for nu in dict.fromkeys(r["nu"] for r in series):
        for ratio in dict.fromkeys(r["a_over_R"] for r in series):
            by_level = sorted((r for r in series if r["nu"] == nu and r["a_over_R"] == ratio),
                              key=lambda r: r["refine"])
            finest, before = by_level[-1], by_level[-2]
            out.append({"nu": nu, "a_over_R": ratio, "dofs": finest["dofs"],
                        **{key: finest[key] for key in ("a_err", "p0_err")},
                        **{f"{key}_change": finest[key] - before[key] for key in ("a_err", "p0_err")}})
    return out


def load_error(row: dict) -> float:
    """The measured contact force over the target load, minus one: ``(a_ref / (a/R · R))³ − 1``,
    a_ref being Hertz's contact radius for the measured force."""
    return (row["a_ref"] / (row["a_over_R"] * row.get("R", 1.0))) ** 3 - 1.0


def rate(found: list[dict], key: str) -> tuple[float, float]:
    """``(k, c)`` of ``|error| ≈ c (a/R)^k`` fitted in logarithms to the finest levels."""
    ratios = np.array([r["a_over_R"] for r in found])
    errors = np.abs([r[key] for r in found])
    k, log_c = np.polyfit(np.log(ratios), np.log(errors), 1)
    return float(k), float(np.exp(log_c))


def _pct(x: float) -> str:
    return f"{100 * x:+.3f} %"


def _cell(row: dict) -> str:
    """a and p₀'s errors, and the status when it is not ``converged``."""
    status = "" if row["status"] == "converged" else f" ({row['status']})"
    return f"{_pct(row['a_err'])}, {_pct(row['p0_err'])}{status}"


def tables(rows: list[dict]) -> dict[str, str]:
    """docs/accuracy.md's blocks: the series, the rate and the a/R of a 0.01 % model, the default."""
    series = [r for r in rows if r["table"] == "series"]
    levels = sorted({r["refine"] for r in series})
    lines = ["| ν | a/R | dofs | " + " | ".join(f"a, p₀ at refine {k}" for k in levels) + " |",
             "|---:|---:|---|" + "---|" * len(levels)]
    for nu in dict.fromkeys(r["nu"] for r in series):
        for ratio in dict.fromkeys(r["a_over_R"] for r in series):
            group = sorted((r for r in series if r["nu"] == nu and r["a_over_R"] == ratio),
                           key=lambda r: r["refine"])
            lines.append(f"| {nu:g} | {ratio:g} | " + " → ".join(f"{r['dofs']:,}" for r in group)
                         + " | " + " | ".join(_cell(r) for r in group) + " |")
    out = {"finite-sphere-series": "\n".join(lines)}
    found = limits(rows)
    lines = ["| ν | quantity | k in c·(a/R)^k | c | finest level at a/R = 0.05 | a/R for 0.01 % |",
             "|---:|---|---:|---:|---:|---:|"]
    for nu in RATE_NUS:
        at_nu = [r for r in found if r["nu"] == nu]
        for key, name in (("a_err", "a"), ("p0_err", "p₀")):
            k, c = rate(at_nu, key)
            largest = max(at_nu, key=lambda r: r["a_over_R"])
            lines.append(f"| {nu:g} | {name} | {k:.2f} | {100 * c:.2f} % | {_pct(largest[key])} | "
                         f"{(MODEL_ERROR / c) ** (1 / k):.2g} |")
    out["finite-sphere-rate"] = "\n".join(lines)
    meshes = [r for r in rows if r["table"] == "meshes"]
    lines = ["| a/R | units | mesh | dofs | " + " | ".join(f"a, p₀ at ν = {nu:g}" for nu in MESH_NUS)
             + " |", "|---:|---|---|---:|" + "---|" * len(MESH_NUS)]
    default = {key: scene_default(key) for key in ("n_contact", "grading")}
    for key in dict.fromkeys((r["a_over_R"], r["n_contact"], r["grading"], r["units"]) for r in meshes):
        group = [r for r in meshes if (r["a_over_R"], r["n_contact"], r["grading"], r["units"]) == key]
        mesh = f"n_contact={key[1]}, grading={key[2]:g}" + (
            " (default)" if (key[1], key[2]) == (default["n_contact"], default["grading"]) else "")
        lines.append(f"| {key[0]:g} | {key[3]} | {mesh} | {group[0]['dofs']:,} | "
                     + " | ".join(_cell(r) for r in group) + " |")
    out["finite-sphere-meshes"] = "\n".join(lines)
    balance = max(r["force_balance"] for r in rows)
    target = max(abs(load_error(r)) for r in rows)
    out["finite-sphere-force"] = (
        f"Every run carries its load: over the {len(rows)} runs the contact force P is within "
        f"{target:.1e} of the target load (Hertz's for the a/R asked) and within {balance:.1e} of "
        f"the load applied on the cut, and Hertz's a and p₀ are those of the measured P.")
    return out


def write_doc(record: dict) -> None:
    from readme import ACCURACY, fill_blocks

    fill_blocks(ACCURACY, tables(record["rows"]))


if __name__ == "__main__":
    from readme import study_main

    sys.exit(study_main("docs/accuracy.md", OUT, run, write_doc))
