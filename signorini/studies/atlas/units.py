"""Axis 4: units and scaling, with and without the package's non-dimensionalisation."""

from __future__ import annotations

from matplotlib.figure import Figure

from signorini.studies.atlas import figures
from signorini.studies.atlas.axis import TINY_HERTZ, Axis, Rows, cell, every_method, num, pivot, scene_spec
from signorini.studies.atlas.findings import claim, methods_of, name, one, pick, right
from signorini.studies.task import Task

UNIT_SYSTEMS = (("E=1, R=1", 1.0, 1.0), ("E=1, R=0.01", 1.0, 0.01),
                ("MPa, mm: E=2.1e5, R=10", 2.1e5, 10.0), ("Pa, m: E=2.1e11, R=0.01", 2.1e11, 0.01),
                ("Pa, mm: E=2.1e11, R=10", 2.1e11, 10.0), ("E=2.1e11, R=1", 2.1e11, 1.0))
UNITS_MESH = {"n_contact": 16, "grading": 0.4}


def tasks(quick: bool, methods: list[str]) -> list[Task]:
    systems = UNIT_SYSTEMS[2:4] if quick else UNIT_SYSTEMS
    mesh = TINY_HERTZ if quick else UNITS_MESH
    out = []
    for label, E, R in systems:
        scaled = scene_spec("hertz-cylinder", params={**mesh, "E": E, "R": R})
        for nondimensionalise in (True, False):
            problem = scene_spec("hertz-cylinder", params={**mesh, "E": E, "R": R},
                                 nondimensionalise=nondimensionalise)
            case = f"{label}, {'scaled' if nondimensionalise else 'raw'}"
            out += every_method("units", case, label, problem, methods,
                                reference={"kind": "pdas", "problem": scaled})
    return out


def assembled(rows: Rows, scaling: str) -> Rows:
    """The runs on problems assembled ``"scaled"`` (non-dimensionalised) or ``"raw"``."""
    return [r for r in rows if r["case"].endswith(f", {scaling}")]


def findings(rows: Rows) -> list[str]:
    out = []
    for scaling in ("scaled", "raw"):
        mine = assembled(rows, scaling)
        systems = list(dict.fromkeys(r["value"] for r in mine))
        counts = [f"{s}: {sum(r['outcome'] == 'right' for r in mine if r['value'] == s)}/"
                  f"{sum(r['value'] == s for r in mine)}" for s in systems]
        out.append(f"**{scaling}** — methods right per unit system: " + "; ".join(counts) + ".")
    for method in dict.fromkeys(r["method"] for r in rows):
        scaled, raw = (pick(assembled(rows, s), method=method) for s in ("scaled", "raw"))
        s_ok, r_ok = len(right(scaled)), len(right(raw))
        if s_ok != r_ok or s_ok < len(scaled):
            bad = [f"{r['value']} ({cell(r)}, λ off {num(r.get('lam_rel'))})"
                   for r in raw if r["outcome"] != "right"]
            text = f"**{method}**: right in {s_ok}/{len(scaled)} systems scaled, {r_ok}/{len(raw)} raw"
            if bad:
                text += "; raw units fail at " + "; ".join(bad)
            out.append(text + ".")
    return out


def table(rows: Rows) -> list[str]:
    return pivot(rows, "method", "case", lambda r: cell(r, num(r.get("lam_rel"), 0)), corner="method")


def figure(rows: Rows) -> Figure:
    figure = Figure(figsize=(11, 5.0), layout="constrained")
    left, right = figure.subplots(1, 2, sharey=True)
    for ax, scaling in ((left, "scaled"), (right, "raw")):
        figures.atlas_outcomes(assembled(rows, scaling), column="value", ax=ax,
                               title=f"{'non-dimensionalised' if scaling == 'scaled' else 'raw units'}")
    figure.suptitle("Axis 4: units (green: right; orange: false 'solved' caught; grey: no claim; "
                    "red: the package's status was wrong)", fontsize=9)
    return figure


def headline(rows: Rows) -> str:
    """The axis's finding in a paragraph, as docs/results.md states it."""
    systems = list(dict.fromkeys(r["value"] for r in rows))
    scaled, raw = assembled(rows, "scaled"), assembled(rows, "raw")
    methods = methods_of(rows)
    for m in methods:
        claim(len({one(scaled, method=m, value=s)["outcome"] for s in systems}) == 1,
              f"{m} behaves the same in every scaled unit system")
    right_scaled = len(right(pick(scaled, value=systems[0])))
    changed = {m: (len(right(pick(scaled, method=m))), len(right(pick(raw, method=m))))
               for m in methods}
    changed = {m: c for m, c in changed.items() if c[0] != c[1]}
    claim(all(s > r for s, r in changed.values()), "raw units never help a method")
    infeasible = [r for r in pick(raw, method="qp-quadprog") if r["status"] == "infeasible"]
    if infeasible:
        claim(all("E=2.1e11" in r["value"] for r in infeasible)
              and len(infeasible) == sum("E=2.1e11" in s for s in systems),
              "quadprog calls exactly the raw problems with E = 2.1e11 infeasible")
    moves = [f"{name(m)} is right in {r} of {len(systems)} (scaled: {s})"
             for m, (s, r) in changed.items() if m != "qp-quadprog" or not infeasible]
    quadprog = (f", and quadprog calls the {len(infeasible)} feasible problems with E = 2.1e11 "
                "`infeasible`" if infeasible else "")
    return (f"**Units** (axis 4): with the default non-dimensionalisation every method behaves the "
            f"same in all {len(systems)} unit systems (E = 1 … 2.1e11, lengths in m or mm; "
            f"{right_scaled} of {len(methods)} methods right in each); in raw units "
            + (", ".join(moves) if moves else "no method changes") + quadprog + ".")


AXIS = Axis(
    4, "units", "Units and scaling",
    "What do raw units (E up to 2.1e11, lengths in m or mm) do to each method, with and "
    "without the package's non-dimensionalisation?",
    setup=f"Hertz's cylinder {UNITS_MESH}, a/R = 0.05, in six unit systems; each assembled "
          "non-dimensionalised (the default) and raw (`nondimensionalise=False`, "
          "`--raw-units`); every method at tol 1e-8; the exact answer is PDAS on the scaled "
          "problem, converted.",
    advice="keep the default non-dimensionalisation. Raw units (`--raw-units`, "
           "`nondimensionalise=False`) leave the exact methods unharmed but put the QP "
           "backends' absolute tolerances at the mercy of E and the length unit.",
    legend="Cells: status, λ error.",
    tasks=tasks, findings=findings, table=table, figure=figure, headline=headline)


__all__ = ["tasks", "assembled", "findings", "table", "figure", "headline"]
