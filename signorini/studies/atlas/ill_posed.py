"""Axis 8: infeasible and ill-posed input — a clear error or status for each."""

from __future__ import annotations

from typing import Any

from matplotlib.figure import Figure

from signorini.studies.atlas import figures
from signorini.studies.atlas.axis import Axis, Rows, cell, every_method, pivot, scene_spec
from signorini.studies.atlas.findings import claim, pick
from signorini.studies.atlas.summary import method_rows
from signorini.studies.problems import ILL_POSED_CASES
from signorini.studies.task import BUILD_ONLY, Task

ILL_POSED_EXPECT = {"penetrated": "refuse", "no-candidates": "refuse", "zero-weight": "refuse",
                    "duplicate": "solve", "never-touches": "solve"}
ILL_POSED_BLOCK = {"nx": 4, "ny": 4}


def tasks(quick: bool, methods: list[str]) -> list[Task]:
    params = ILL_POSED_BLOCK
    out = []
    for case, expect in ILL_POSED_EXPECT.items():
        spec = {"kind": "ill-posed", "case": case, "params": params}
        flag = "solve" if case == "never-touches" else "refuse"  # the build row: flagged or clean
        out.append(Task("ill-posed", case, case, spec, BUILD_ONLY, expect=flag,
                        measure=("diagnosis",)))
        if case == "duplicate":  # λ is not unique: compare u with that of the block listed once
            reference = {"kind": "pdas", "problem": scene_spec("block", params=params),
                         "displacement_only": True}
            out += every_method("ill-posed", case, case, spec, methods, expect=expect,
                                answer="displacement", reference=reference)
        elif case in ("penetrated", "never-touches"):
            out += every_method("ill-posed", case, case, spec, methods, expect=expect)
    return out


def _build_text(build: dict[str, Any]) -> str:
    """What building the problem did: refused it, or built it and diagnosed what."""
    if build["status"] == "input-error":
        return f"refused when the problem is built: “{build['message']}”"
    return ("built; the diagnosis says “" + build["diagnosis"] + "”"
            if build.get("diagnosis") else "built; nothing to diagnose")


def findings(rows: Rows) -> list[str]:
    out = []
    for case in dict.fromkeys(r["case"] for r in rows):
        build = next((r for r in rows if r["case"] == case and r["method"] == BUILD_ONLY), None)
        mine = method_rows(r for r in rows if r["case"] == case)
        text = f"**{case}** — {ILL_POSED_CASES.get(case, case)}: "
        if build is not None:
            text += _build_text(build)
        if mine:
            counts: dict[str, list[str]] = {}
            for r in mine:
                counts.setdefault(cell(r), []).append(r["method"])
            text += ". Methods: " + "; ".join(f"{k}: {', '.join(v)}" for k, v in counts.items())
            unclear = [r for r in mine if r["status"] == "failed"]
            if unclear:
                text += (". Failure messages: " + "; ".join(
                    f"{r['method']} “{str(r['message'])[:90]}”" for r in unclear[:3]))
        out.append(text + ".")
    return out


def table(rows: Rows) -> list[str]:
    return pivot(method_rows(rows), "method", "case", lambda r: cell(r), corner="method")


def figure(rows: Rows) -> Figure:
    ax = figures.atlas_outcomes(method_rows(rows), column="case",
                                title="Axis 8: infeasible and ill-posed input (green: the right "
                                      "status or answer)")
    ax.figure.set_size_inches(7, 5)
    return ax.figure


def headline(rows: Rows) -> str:
    """The axis's finding in a paragraph, as docs/results.md states it."""
    penetrated = method_rows(pick(rows, case="penetrated"))
    statuses = {s: len(pick(penetrated, status=s)) for s in ("infeasible", "failed")}
    claim(sum(statuses.values()) == len(penetrated), "every method says infeasible or failed")
    unclear = "float division by zero"
    claim(any(unclear in str(r["message"]) for r in penetrated), f"a message says '{unclear}'")
    return ("**Ill-posed input** (axis 8): an empty contact set and a zero-weight candidate are "
            "refused when the problem is built; `signorini.certification.diagnosis.diagnose(problem)` names an "
            "obstacle the Dirichlet data already penetrate (infeasible), a candidate listed twice "
            "(λ not unique) and a singular K. On the penetrated obstacle "
            f"{statuses['infeasible']} methods say `infeasible` and {statuses['failed']} "
            f"`failed`, some with unclear messages (\"{unclear}\").")


AXIS = Axis(
    8, "ill-posed", "Infeasible and ill-posed input",
    "Does every infeasible or ill-posed input end in a clear error or status?",
    setup="The block (4 × 4) made infeasible or ill-posed five ways "
          "(`signorini.studies.problems.ill_posed_problem`); each problem is built and diagnosed "
          "(`signorini.certification.diagnosis.diagnose`), then solved by every method where it builds.",
    advice="run `signorini.certification.diagnosis.diagnose(problem)` on a problem you built yourself: it "
           "names infeasible candidates, duplicated candidates and a singular K in words. "
           "The package refuses an empty contact set and zero-weight candidates outright.",
    legend="Cells: status.",
    tasks=tasks, findings=findings, table=table, figure=figure, headline=headline)


__all__ = ["tasks", "findings", "table", "figure", "headline"]
