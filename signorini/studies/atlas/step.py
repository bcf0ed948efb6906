"""Axis 1: Uzawa's step ρ on either side of the bound 2/λ_max(W)."""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.figure import Figure

from signorini.studies.atlas import figures
from signorini.studies.atlas.axis import TINY_HERTZ, Axis, Rows, cell, pivot, scene_spec
from signorini.studies.atlas.findings import claim, one, pick, span, times
from signorini.studies.task import Task

STEP_FRACTIONS = (0.05, 0.1, 0.25, 0.5, 0.75, 0.9, 0.95, 0.99, 1.01, 1.05, 1.1, 1.15, 1.2, 1.25,
                  1.5, 2.0, 2.5)
STEP_SCENES = {"hertz-cylinder": {"n_contact": 16, "grading": 0.4}, "block": {"nx": 8, "ny": 8}}
QUICK_STEP_SCENES = {"hertz-cylinder": TINY_HERTZ, "block": {"nx": 4, "ny": 4}}
STEP_CAPS = {"uzawa": 60_000, "uzawa-nesterov": 20_000}


def tasks(quick: bool, methods: list[str]) -> list[Task]:
    fractions = (0.5, 0.95, 1.25) if quick else STEP_FRACTIONS
    out = []
    for scene, params in (QUICK_STEP_SCENES if quick else STEP_SCENES).items():
        for method, cap in STEP_CAPS.items():
            if method in methods:
                out += [Task("uzawa-step", scene, fraction, scene_spec(scene, params=params), method,
                             options={"step_fraction": fraction}, max_iter=cap, measure=("bound",))
                        for fraction in fractions]
    return out


def counts(row: dict[str, Any]) -> bool:
    """Only steps inside the method's bound count (1× for Uzawa, 0.5× for its Nesterov variant)."""
    return row["value"] <= (0.5 if row["method"] == "uzawa-nesterov" else 1.0)


def _fraction_text(value: float) -> str:
    return f"{value:g}×"


def cycles(row: dict[str, Any]) -> bool:
    """Whether a divergence the package named is a two-step cycle (λ returns every other step)
    rather than growth."""
    return "cycle" in str(row["message"])


def _beyond_text(beyond: Rows) -> str:
    """The statuses past the last right step, a divergence told as a two-step cycle or growth."""
    kinds: dict[str, list[float]] = {}
    for r in beyond:
        kind = r["status"]
        if r["status"] == "diverged":
            kind = "diverged: two-step cycle" if cycles(r) else "diverged: growth"
        kinds.setdefault(kind, []).append(r["value"])
    return "; beyond: " + "; ".join(f"{kind} at {', '.join(_fraction_text(v) for v in values)}"
                                    for kind, values in kinds.items())


def findings(rows: Rows) -> list[str]:
    out = []
    for case in dict.fromkeys(r["case"] for r in rows):
        for method in dict.fromkeys(r["method"] for r in rows):
            mine = sorted((r for r in rows if r["case"] == case and r["method"] == method),
                          key=lambda r: r["value"])
            if not mine:
                continue
            right = [r["value"] for r in mine if r["outcome"] == "right"]
            failing = [r for r in mine if r["outcome"] != "right"]
            text = f"**{case}, {method}** ({mine[0].get('dofs', 0):.0f} dofs): "
            if right:
                text += (f"right answer for ρ from {_fraction_text(min(right))} to "
                         f"{_fraction_text(max(right))} the bound 2/λ_max(W)")
                iters = {r["value"]: r["iterations"] for r in mine if r["outcome"] == "right"}
                shown = [v for v in (0.05, 0.5, 0.95) if v in iters]
                if shown:
                    text += " (" + ", ".join(f"{iters[v]:,.0f} iterations at {_fraction_text(v)}"
                                             for v in shown) + ")"
            beyond = [r for r in failing if r["value"] > (max(right) if right else 0)]
            if beyond:
                text += _beyond_text(beyond)
            inside = [r for r in failing if right and r["value"] < max(right)]
            if inside:
                text += "; not right inside that range at " + ", ".join(
                    f"{_fraction_text(r['value'])} ({r['status']})" for r in inside)
            bound = mine[0].get("bound_at_solution")
            if method == "uzawa" and bound is not None and np.isfinite(bound):
                text += (f". On the exact active set A the bound is 2/λ_max(W_AA) = "
                         f"{bound:.3f} × 2/λ_max(W)")
                if right and max(right) > 1.0:
                    text += (" — steps past 2/λ_max(W) can still converge, but the iteration "
                             "starts from λ = 0, far from A, so the slack is smaller")
            out.append(text + ".")
    return out


def table(rows: Rows) -> list[str]:
    columns = [dict(r, _column=f"{r['case']}, {r['method']}") for r in rows]
    return pivot(columns, "value", "_column", lambda r: cell(r, f"{r.get('iterations', 0):,.0f}"),
                 corner="ρ / (2/λ_max)")


def figure(rows: Rows) -> Figure:
    ax = figures.atlas_step_sweep(rows)
    ax.set_title("Axis 1: Uzawa's step (filled: right answer)", fontsize=9)
    return ax.figure


def headline(rows: Rows) -> str:
    """The axis's finding in a paragraph, as docs/results.md states it."""
    cyl, block = (pick(rows, case=c) for c in ("hertz-cylinder", "block"))
    uz_cyl, uz_block = pick(cyl, method="uzawa"), pick(block, method="uzawa")
    diverged = pick(rows, method="uzawa", status="diverged")
    claim(all(cycles(r) for r in diverged), "Uzawa diverges only in a two-step cycle")
    first_cycle = {case: min(r["value"] for r in pick(diverged, case=case))
                   for case in ("hertz-cylinder", "block")}
    for mine in (uz_cyl, uz_block):  # right from just past the first wrong step up to the cycle
        claim(all(r["outcome"] == "right" for r in mine
                  if r["value"] < first_cycle[mine[0]["case"]] and r["status"] != "max_iter"),
              "Uzawa is right at every step below its cycle that reaches the iteration cap")
    capped = sorted(r["value"] for r in uz_cyl + uz_block if r["status"] == "max_iter")
    claim(capped == [min(r["value"] for r in uz_cyl)] and not pick(uz_block, status="max_iter"),
          "Uzawa stops at its cap only at the cylinder's smallest step")
    cap = one(uz_cyl, value=capped[0])["iterations"]
    bound = uz_cyl[0]["bound_at_solution"]
    claim(first_cycle["hertz-cylinder"] < bound, "the cylinder cycles before its W_AA bound")
    iterations = {v: one(uz_cyl, value=v)["iterations"] for v in (0.1, 0.95)}
    nesterov = pick(rows, method="uzawa-nesterov")
    stalled = {case: [r["value"] for r in pick(nesterov, case=case, status="max_iter")]
               for case in ("hertz-cylinder", "block")}
    grown = pick(nesterov, status="diverged")
    early = [r for r in nesterov if r["value"] <= 0.5]
    uncertified = [r for r in early if r["status"] == "inaccurate"]
    claim(not any(cycles(r) for r in grown) and min(r["value"] for r in grown) > 1
          and all(r["outcome"] in ("right", "caught", "conservative") for r in early)
          and all(v < 1 for vs in stalled.values() for v in vs),
          "uzawa-nesterov is never wrong to 0.5×, stalls below 1× and grows past it")
    return (f"**Uzawa's step** (axis 1): plain Uzawa is right for ρ up to the bound 2/λ_max(W) on "
            f"a {uz_cyl[0]['dofs']:,}-dof cylinder ({iterations[0.1]:,} iterations at 0.1×, "
            f"{iterations[0.95]:,} at 0.95×) and the {uz_block[0]['dofs']:,}-dof block, except at "
            f"{times(capped[0])} on the cylinder, where it stops at its {cap:,}-iteration cap. "
            "Beyond the bound the package says `diverged` and names a **two-step cycle** (λ "
            "returns every other step; growth is never seen): from "
            f"{times(first_cycle['block'])} on the block, from "
            f"{times(first_cycle['hertz-cylinder'])} on the cylinder, whose active block W_AA "
            f"allows {bound:.2f}×. `uzawa-nesterov` needs ρ ≤ 1/λ_max: up to 0.5× it meets the "
            "KKT residuals, but its stopping rule stops short of the forces: the certificate's "
            f"forward error leaves {len(uncertified)} of its {len(early)} runs there "
            "`inaccurate` (docs/certificate.md); at "
            f"{span(stalled['hertz-cylinder'])} of 2/λ_max ({span(stalled['block'])} on the "
            "block) it stops at `max_iter`, past 1× it diverges by growth.")


AXIS = Axis(
    1, "uzawa-step", "Uzawa's step ρ",
    "Uzawa converges iff 0 < ρ < 2/λ_max(W): what happens on either side of the bound, and "
    "does the package name a divergence or a two-step cycle?",
    setup=f"Hertz's cylinder {STEP_SCENES['hertz-cylinder']} and the block "
          f"{STEP_SCENES['block']}; `uzawa` and `uzawa-nesterov` with "
          "`step_fraction` = ρ/(2/λ_max(W)) from 0.05 to 2.5, tol 1e-8, at most "
          f"{STEP_CAPS['uzawa']:,} (uzawa) and {STEP_CAPS['uzawa-nesterov']:,} "
          "(uzawa-nesterov) iterations.",
    advice="keep `step_fraction` below 1 (the default 0.9); `uzawa-nesterov` needs at most "
           "0.5 (its default). Past the bound the package says `diverged` and names the "
           "two-step cycle or the growth; lower `rho` or `step_fraction`.",
    legend="Cells: status and iterations.",
    tasks=tasks, findings=findings, table=table, figure=figure, headline=headline, counts=counts,
    caps=STEP_CAPS)


__all__ = ["tasks", "counts", "cycles", "findings", "table", "figure", "headline"]
