"""Axis 7: degenerate contact — nodes that touch with zero force."""

from __future__ import annotations

from matplotlib.figure import Figure

from signorini.studies.atlas import figures
from signorini.studies.atlas.axis import Axis, Rows, cell, every_method, num, pivot, plural, scene_spec
from signorini.studies.atlas.findings import claim, pick
from signorini.studies.task import Task

TOUCHING = (0.25, 0.5)


def tasks(quick: bool, methods: list[str]) -> list[Task]:
    params = {"nx": 4, "ny": 4} if quick else {"nx": 8, "ny": 8}
    out = []
    for touching in TOUCHING[:1] if quick else TOUCHING:
        out += every_method("degenerate", f"touching={touching:g}", touching,
                            scene_spec("block", params={**params, "touching": touching}), methods)
    return out


def _most_strict(rows: Rows) -> float:
    return max((r.get("misclassified_strict") or 0 for r in rows), default=0)


def _flagged_strictly(converged: Rows) -> Rows:
    """The runs a comparison without the weak label (weak tolerance 0) would flag."""
    return [r for r in converged if (r.get("misclassified_strict") or 0) > 0]


def findings(rows: Rows) -> list[str]:
    out = []
    for case in dict.fromkeys(r["case"] for r in rows):
        mine = [r for r in rows if r["case"] == case]
        pdas = next((r for r in mine if r["method"] == "pdas"), mine[0])
        converged = [r for r in mine if r["status"] == "converged"]
        wolves = [r for r in converged if (r.get("misclassified") or 0) > 0]
        strict = _flagged_strictly(converged)
        out.append(
            f"**{case}** ({pdas.get('candidates', 0):.0f} candidates, {num(pdas.get('weak'), 0)} "
            f"weakly active in the exact answer): {len(converged)} methods converged; with weakly "
            f"active nodes left out, {len(wolves)} of them show a misclassified node; counting "
            f"strictly (weak tolerance 0), {len(strict)} would (up to "
            f"{plural(_most_strict(mine), 'node')} each).")
    return out


def table(rows: Rows) -> list[str]:
    return pivot(rows, "method", "case",
                 lambda r: cell(r, f"{num(r.get('misclassified'), 0)} / "
                                   f"{num(r.get('misclassified_strict'), 0)} / {num(r.get('weak'), 0)}"),
                 corner="method")


def figure(rows: Rows) -> Figure:
    ax = figures.atlas_weak_nodes(rows)
    ax.figure.set_size_inches(11, 4.4)
    ax.set_title("Axis 7: degenerate contact — misclassified nodes with and without the weak label",
                 fontsize=9)
    return ax.figure


def headline(rows: Rows) -> str:
    """The axis's finding in a paragraph, as docs/results.md states it."""
    case = max({r["case"] for r in rows}, key=lambda c: max(r["weak"] for r in pick(rows, case=c)))
    converged = pick(rows, case=case, status="converged")
    claim(all(r["misclassified"] == 0 for r in pick(rows, status="converged")),
          "no converged method shows a misclassified node")
    strict = _flagged_strictly(converged)
    claim(_most_strict(strict) <= 1,
          "a strict count flags at most one node")
    flagged = (f"a comparison without the weak label would flag one for {len(strict)} of the "
               f"{len(converged)} converged methods" if strict else
               f"even a comparison without the weak label flags none of the {len(converged)} "
               "converged methods")
    return ("**Degenerate contact** (axis 7, `signorini solve block --set "
            f"{case}`): nodes that touch with zero force are labelled weakly "
            f"active and left out; no converged method shows a misclassified node, and {flagged}.")


AXIS = Axis(
    7, "degenerate", "Degenerate contact",
    "Nodes that touch with zero force: does the comparison classify them and stay quiet?",
    setup="The block (8 × 8) with `touching` = 0.25 and 0.5: the outer part of the bottom "
          "meets an obstacle shaped exactly to where it goes unsupported, so those nodes "
          "touch with zero force. Every method at tol 1e-8.",
    advice="nothing: nodes that touch with zero force are labelled weakly active and left "
           "out of active-set comparisons, so an inexact method is not blamed for them. "
           "Look at their count (`weak`) when two answers seem to disagree.",
    legend="Cells: status, misclassified nodes (weak left out) / counted strictly / "
           "weakly active nodes.",
    tasks=tasks, findings=findings, table=table, figure=figure, headline=headline)


__all__ = ["tasks", "findings", "table", "figure", "headline"]
