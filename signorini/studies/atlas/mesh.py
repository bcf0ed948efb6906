"""Axis 2: mesh refinement of Hertz's cylinder, every method at each level."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from signorini.studies.atlas import figures
from signorini.studies.atlas.axis import TINY_HERTZ, Axis, Rows, cell, every_method, num, pivot, scene_spec
from signorini.studies.atlas.findings import claim, methods_of, name, one, pick, power, right
from signorini.studies.task import Task

MESH_BASE = TINY_HERTZ
MESH_LEVELS = (0, 1, 2, 3)
#: methods whose iteration counts the findings follow from level to level
FOLLOWED = ("pdas", "uzawa", "uzawa-nesterov", "condensed")


def tasks(quick: bool, methods: list[str]) -> list[Task]:
    out = []
    for level in (MESH_LEVELS[:2] if quick else MESH_LEVELS):
        out += every_method("mesh", f"refine {level}", level,
                            scene_spec("hertz-cylinder", params={**MESH_BASE, "refine": level}, cold=True),
                            methods)
    return out


def per_halving(iterations: list[float]) -> str:
    """``×g per halving of h``: the mean growth of ``iterations`` from one level to the next."""
    growth = (iterations[-1] / iterations[0]) ** (1.0 / (len(iterations) - 1))
    return f"×{growth:.2f} per halving of h"


def _growth_text(method: str, mine: Rows) -> str:
    """Iterations and times from level to level, and how fast the iterations grow."""
    its = [r.get("iterations", float("nan")) for r in mine]
    text = (f"**{method}**: iterations " + " → ".join(num(i, 0) for i in its)
            + ", time " + " → ".join(f"{r.get('time_s', float('nan')):.2f}" for r in mine) + " s")
    if len(its) >= 2 and all(np.isfinite(its)) and min(its) > 0:
        text += f" ({per_halving(its)}"
        if method == "pdas":
            step = (its[-1] - its[0]) / (len(its) - 1)
            text += (f": about {step:.1f} more steps per halving — nearly, not exactly, "
                     "mesh-independent")
        text += ")"
    return text + "."


def findings(rows: Rows) -> list[str]:
    levels = sorted({r["value"] for r in rows})
    dofs = {lv: next(r["dofs"] for r in rows if r["value"] == lv) for lv in levels}
    out = ["levels: " + ", ".join(f"refine {lv} = {dofs[lv]:,.0f} dofs" for lv in levels) + "."]
    for method in dict.fromkeys(r["method"] for r in rows):
        if method in FOLLOWED:
            out.append(_growth_text(method, sorted((r for r in rows if r["method"] == method),
                                                   key=lambda r: r["value"])))
    for level in levels:
        mine = [r for r in rows if r["value"] == level]
        right = [r for r in mine if r["outcome"] == "right"]
        fastest = min(right, key=lambda r: r["time_s"]) if right else None
        not_right = [f"{r['method']} ({cell(r)})" for r in mine if r["outcome"] != "right"
                     and r["status"] != "refused"]
        text = f"refine {level}: {len(right)} of {len(mine)} methods right"
        if fastest:
            text += f", fastest {fastest['method']} ({fastest['time_s']:.2f} s)"
        if not_right:
            text += "; not right: " + ", ".join(not_right)
        out.append(text + ".")
    return out


def table(rows: Rows) -> list[str]:
    dofs = {r["value"]: r.get("dofs") for r in rows}
    return pivot(rows, "method", "value",
                 lambda r: cell(r, f"{r.get('iterations', 0):,.0f} it, {r.get('time_s', 0):.2g} s"),
                 corner="method", col_label=lambda v: f"refine {v} ({dofs[v]:,.0f} dofs)")


def figure(rows: Rows) -> Figure:
    figure = Figure(figsize=(11, 4.4), layout="constrained")
    left, right = figure.subplots(1, 2)
    answered = [r for r in rows if r["status"] not in ("refused", "input-error")]
    counted = [r for r in answered if (r.get("iterations") or 0) > 0]  # some backends say 0
    figures.atlas_series(counted, "dofs", "iterations", ax=left,
                         ylabel="iterations (as the method counts them)")
    figures.atlas_series(answered, "dofs", "time_s", ax=right, ylabel="time (build + solve) [s]")
    figure.suptitle("Axis 2: mesh refinement of Hertz's cylinder (filled: right answer)", fontsize=9)
    return figure


def headline(rows: Rows) -> str:
    """The axis's finding in a paragraph, as docs/results.md states it."""
    levels = sorted({r["value"] for r in rows})

    def series(method: str, key: str) -> list[Any]:
        return [one(rows, method=method, value=v)[key] for v in levels]

    dofs = series("pdas", "dofs")
    pdas, uzawa, nesterov = (series(m, "iterations") for m in ("pdas", "uzawa", "uzawa-nesterov"))
    nested = series("nested", "iterations")
    claim(all(n <= p for n, p in zip(nested, pdas)), "`nested` takes no more steps than PDAS")
    qp = [m for m in methods_of(rows) if m.startswith("qp-") or m == "cvxpy"]
    sparse = [m for m in qp if not pick(rows, method=m, status="refused")]
    every = [m for m in sparse if len(right(pick(rows, method=m))) == len(levels)]
    some = {m: len(right(pick(rows, method=m))) for m in sparse if m not in every}
    partly = [f"{name(m)} at {k}" for m, k in sorted(some.items(), key=lambda i: -i[1]) if k]
    claim(len(every) >= 1, "a sparse QP backend is right at every level")
    at_all = ", ".join(name(m) for m in every)
    return (f"**Mesh** (axis 2, {dofs[0]:,} → {dofs[-1]:,} dofs, h halving): PDAS takes "
            + " → ".join(str(i) for i in pdas) + " steps from a cold start and `nested` "
            + " → ".join(str(i) for i in nested) + " (the zone from Hertz's width for the load, "
            "one factorisation at every level); Uzawa "
            f"{uzawa[0]:,} → {uzawa[-1]:,} iterations ({per_halving(uzawa)}), "
            f"`uzawa-nesterov` {nesterov[0]:,} → {nesterov[-1]:,}. Of the sparse QP backends "
            f"{at_all} {'is' if len(every) == 1 else 'are'} right at all {len(levels)} levels at "
            f"tol {power(rows[0]['tol'])}"
            + (" (" + ", ".join(partly) + "; the others at none)." if partly else "."))


AXIS = Axis(
    2, "mesh", "Mesh refinement",
    "How do iterations and time grow as h halves, and does PDAS stay mesh-independent?",
    setup=f"Hertz's cylinder {MESH_BASE}, `refine` 0–3 (h halves each level), every method from "
          "a cold start (not from the load targeting's answer) at tol 1e-8.",
    advice="on fine meshes use `pdas` (or `condensed` while the candidates are few): their "
           "iterations barely grow, while Uzawa's double with every halving of h. Of the QP "
           "backends only those shown right here reach tol 1e-8 honestly; check the status.",
    legend="Cells: status, iterations, time.",
    tasks=tasks, findings=findings, table=table, figure=figure, headline=headline)


__all__ = ["tasks", "per_halving", "findings", "table", "figure", "headline"]
