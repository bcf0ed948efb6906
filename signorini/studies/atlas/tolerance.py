"""Axis 3: the tolerance asked of each QP backend, and whether its own 'solved' is honest."""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.figure import Figure

from signorini.studies.atlas import figures
from signorini.studies.atlas.axis import (TINY_HERTZ, Axis, Rows, capped, cell, nodes_text, num, pivot,
                                          plural, scene_spec, wrong_nodes)
from signorini.studies.atlas.findings import claim, methods_of, names, one, pct, pick, power, right
from signorini.studies.task import Task

TOLERANCES = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
TOLERANCE_SCENE = {"n_contact": 24, "grading": 0.35}
#: backends without a tolerance to set: run once, at their own settings
NO_TOLERANCE = ("qp-quadprog",)


def tasks(quick: bool, methods: list[str]) -> list[Task]:
    problem = scene_spec("hertz-cylinder", params=TINY_HERTZ if quick else TOLERANCE_SCENE)
    tolerances = (1e-3, 1e-8, None) if quick else TOLERANCES + (None,)
    out = []
    for method in methods:
        if not (method.startswith("qp-") or method == "cvxpy"):
            continue
        for tol in ((None,) if method in NO_TOLERANCE else tolerances):
            out.append(Task("tolerance", "default" if tol is None else f"{tol:.0e}",
                            "default" if tol is None else tol, problem, method, tol=tol,
                            max_iter=capped(method, tol)))
    return out


def _right_text(numeric: Rows) -> str:
    """The loosest tolerance with a right answer, and the tighter ones without."""
    right = [r for r in numeric if r["outcome"] == "right"]
    if not right:
        return "right at no tolerance" if numeric else "no tolerance to set"
    text = f"right from tol = {right[0]['value']:.0e}"
    later = [r for r in numeric if r["value"] < right[0]["value"] and r["outcome"] != "right"]
    if later:
        text += " (not at " + ", ".join(f"{r['value']:.0e}: {cell(r)}" for r in later) + ")"
    return text


def _false_claims_text(mine: Rows, false_claims: Rows) -> str:
    """How many of the method's claims were false, and the worst of them against Hertz."""
    worst = max(false_claims, key=lambda r: (wrong_nodes(r), r.get("lam_rel") or 0))
    text = (f"; its own success was false in {len(false_claims)} of "
            f"{sum(r.get('claimed_status') == 'converged' for r in mine)} claims (worst at "
            f"tol {worst['case']}: {plural(wrong_nodes(worst), 'node')} misclassified, "
            f"λ off by {num(worst.get('lam_rel'))}")
    if np.isfinite(worst.get("a_rel", np.nan)):
        text += (f", a off Hertz by {100 * worst['a_rel']:.1f} % and p₀ by "
                 f"{100 * worst['p0_rel']:.1f} % where the exact answer gives "
                 f"{100 * worst['ref_a_rel']:.1f} % and {100 * worst['ref_p0_rel']:.1f} %")
    return text + ")"


def _default_text(default: dict[str, Any]) -> str:
    """The backend at its own settings."""
    text = (f"; at its own defaults: {cell(default)}, λ off by "
            f"{num(default.get('lam_rel'))}, {plural(wrong_nodes(default), 'node')} "
            "misclassified")
    if np.isfinite(default.get("a_rel", np.nan)) and wrong_nodes(default) > 0:
        text += (f" (Hertz a off by {100 * default['a_rel']:.1f} %, p₀ by "
                 f"{100 * default['p0_rel']:.1f} %)")
    return text


def findings(rows: Rows) -> list[str]:
    out = []
    for method in dict.fromkeys(r["method"] for r in rows):
        mine = [r for r in rows if r["method"] == method]
        numeric = sorted((r for r in mine if r["value"] != "default"), key=lambda r: -r["value"])
        false_claims = [r for r in mine if not r["claim_correct"]]
        text = f"**{method}**: " + _right_text(numeric)
        if false_claims:
            text += _false_claims_text(mine, false_claims)
        default = next((r for r in mine if r["value"] == "default"), None)
        if default is not None:
            text += _default_text(default)
        out.append(text + ".")
    return out


def table(rows: Rows) -> list[str]:
    return pivot(rows, "method", "case", lambda r: cell(r, f"{num(r.get('lam_rel'), 0)}/{nodes_text(r)}"),
                 corner="backend \\ tol")


def figure(rows: Rows) -> Figure:
    numeric = [r for r in rows if r["value"] != "default"]
    figure = Figure(figsize=(11, 4.4), layout="constrained")
    left, right = figure.subplots(1, 2)
    figures.atlas_series(numeric, "value", "lam_rel", ax=left, xlabel="tolerance asked for",
                         ylabel="‖λ − λ*‖∞ / ‖λ*‖∞")
    left.plot([1e-10, 1e-2], [1e-10, 1e-2], "k:", lw=0.8)
    left.invert_xaxis()
    figures.atlas_series(numeric, "value", "misclassified", ax=right, xlabel="tolerance asked for",
                         ylabel="misclassified contact nodes", logy=False)
    right.invert_xaxis()
    figure.suptitle("Axis 3: tolerance (filled: right answer; red ring: the backend's own "
                    "'solved' was false)", fontsize=9)
    return figure


def headline(rows: Rows) -> str:
    """The axis's finding in a paragraph, as docs/results.md states it."""
    osqp = one(rows, method="qp-osqp", tol=None)
    prox = one(rows, method="qp-proxqp", tol=None)
    claim(osqp["claimed_status"] == prox["claimed_status"] == "converged" and osqp["misclassified"] == 0
          and prox["misclassified"] > 0, "OSQP and ProxQP claim success at their defaults")
    tolerances = sorted({r["tol"] for r in rows if r["tol"] is not None})
    never = [m for m in methods_of(rows) if m != "qp-quadprog"
             and not right(pick(rows, method=m, tol=lambda t: t is not None))]
    daqp_false = [r for r in pick(rows, method="qp-daqp") if r["claimed_status"] == "converged"
                  and not r["claim_correct"]]
    claim(len(daqp_false) == 1, "DAQP makes one false claim")
    return (f"**Tolerance** (axis 3, a {osqp['dofs']:,}-dof cylinder): at its defaults OSQP says "
            f"\"solved\" with λ {pct(osqp['lam_rel'])} off and no node misclassified, ProxQP with "
            f"λ off by {prox['lam_rel']:.1f} times its size, {prox['misclassified']} nodes misclassified "
            f"and Hertz's a and p₀ {pct(prox['a_rel'])} and {pct(prox['p0_rel'])} off (the exact "
            f"answer: {pct(prox['ref_a_rel'], 2)} and {pct(prox['ref_p0_rel'], 2)}); "
            f"{names(never)} are right at no tolerance from {power(tolerances[-1])} to "
            f"{power(tolerances[0])}; DAQP's one false claim is at {power(daqp_false[0]['tol'])} "
            "(below).")


AXIS = Axis(
    3, "tolerance", "Solver tolerance",
    "At which tolerance does each QP backend find the right contact, and where is its own "
    "'solved' dishonest?",
    setup=f"Hertz's cylinder {TOLERANCE_SCENE}; every QP backend and cvxpy at tol 1e-2 … "
          "1e-10 and at its own defaults (quadprog has no tolerance: defaults only).",
    advice="ask for the accuracy you need (`--tol`) and trust `converged` only; a "
           "backend's own 'solved' at its defaults or at a loose tolerance is no evidence "
           "of the right contact zone. For exact contact use `pdas`, `condensed`, daqp or "
           "quadprog (the last two on small problems).",
    legend="Cells: status, λ error / misclassified nodes (`+kp`: k more nodes with zero "
           "force that penetrate, which `kkt.classify` labels weakly active).",
    tasks=tasks, findings=findings, table=table, figure=figure, headline=headline)


__all__ = ["tasks", "findings", "table", "figure", "headline"]
