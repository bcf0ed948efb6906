"""Axis 6: a body held only by contact (force control, a singular K) and its regularisation."""

from __future__ import annotations

from typing import Any

from matplotlib.figure import Figure

from signorini.studies.atlas import figures
from signorini.studies.atlas.axis import Axis, Rows, cell, every_method, num, pivot
from signorini.studies.atlas.findings import claim, methods_of, names, one, pick, power, right
from signorini.studies.task import Task

FORCE_BLOCK = {"nx": 8, "ny": 8}
REGULARISATION = 1e-8
EPSILONS = (1e-14, 1e-12, 1e-10, 1e-8, 1e-6, 1e-4, 1e-2)
#: the methods of the sweep over ε
SWEPT = ("pdas", "qp-clarabel")
#: the two problems every method runs: K singular, and K regularised by REGULARISATION
SINGULAR, REGULARISED = "singular K", f"regularised ε={REGULARISATION:g}"


def _force_spec(params: dict[str, Any], epsilon: float = 0.0) -> dict[str, Any]:
    return {"kind": "force-controlled", "params": params, "pressure": 0.01,
            "regularisation": epsilon}


def _swept(row: dict[str, Any]) -> bool:
    """A run of the sweep over ε (not of the singular or the default-regularised problem)."""
    return str(row["case"]).startswith("ε=")


def counts(row: dict[str, Any]) -> bool:
    """The sweep over ε does not count for the verdict."""
    return not _swept(row)


def tasks(quick: bool, methods: list[str]) -> list[Task]:
    params = {"nx": 4, "ny": 4} if quick else FORCE_BLOCK
    exact = {"kind": "force-controlled-exact"}
    out = every_method("force-control", SINGULAR, 0.0, _force_spec(params), methods,
                       reference=exact, measure=("diagnosis", "patch"))
    out += every_method("force-control", REGULARISED, REGULARISATION,
                        _force_spec(params, REGULARISATION), methods, measure=("patch",))
    for epsilon in ((1e-8, 1e-2) if quick else EPSILONS):
        for method in SWEPT:
            if method in methods:
                out.append(Task("force-control", f"ε={epsilon:g}", epsilon,
                                _force_spec(params, epsilon), method, measure=("patch",)))
    return out


def _case_text(case: str, mine: Rows) -> str:
    """Who is right on one problem, who raised, and what the diagnosis says."""
    right = [r["method"] for r in mine if r["outcome"] == "right"]
    raised = [r for r in mine if r["status"] == "raised"]
    other = [f"{r['method']} ({cell(r)})" for r in mine
             if r["outcome"] != "right" and r["status"] != "raised"]
    text = f"**{case}** ({mine[0].get('dofs', 0):,.0f} dofs): right: {', '.join(right) or 'none'}"
    if raised:
        text += (f"; the package raised instead of giving a status for "
                 f"{', '.join(r['method'] for r in raised)} (own answers: " + ", ".join(
                     f"{r['method']} {r['claimed_status']}, λ off {num(r.get('lam_rel'))}"
                     for r in raised) + ")")
    if other:
        text += "; not right: " + ", ".join(other)
    diagnosis = next((r.get("diagnosis") for r in mine if r.get("diagnosis")), "")
    if diagnosis:
        text += f". Diagnosis: “{diagnosis}”"
    return text + "."


def findings(rows: Rows) -> list[str]:
    out = []
    for case in (SINGULAR, REGULARISED):
        mine = [r for r in rows if r["case"] == case]
        if mine:
            out.append(_case_text(case, mine))
    sweep = [r for r in rows if _swept(r)]
    for method in dict.fromkeys(r["method"] for r in sweep):
        mine = sorted((r for r in sweep if r["method"] == method), key=lambda r: r["value"])
        out.append(f"**{method}, regularised**: λ off the exact patch solution by " + ", ".join(
            f"{num(r.get('patch_lam_rel'))} at ε={r['value']:g}" for r in mine) + ".")
    return out


def table(rows: Rows) -> list[str]:
    return pivot([r for r in rows if counts(r)], "method", "case",
                 lambda r: cell(r, f"{num(r.get('patch_lam_rel'), 0)}"), corner="method")


def figure(rows: Rows) -> Figure:
    figure = Figure(figsize=(11, 4.8), layout="constrained")
    left, right = figure.subplots(1, 2, width_ratios=(1.0, 0.8))
    figures.atlas_series([r for r in rows if _swept(r)], "value", "patch_lam_rel", ax=left,
                         xlabel="regularisation ε",
                         ylabel="‖λ − λ_exact‖∞ / ‖λ_exact‖∞ (vs the unregularised patch solution)")
    figures.atlas_outcomes([r for r in rows if counts(r)], column="case", ax=right,
                           title="status per method")
    figure.suptitle("Axis 6: a block held only by contact (force control, singular K)", fontsize=9)
    return figure


def headline(rows: Rows) -> str:
    """The axis's finding in a paragraph, as docs/results.md states it."""
    singular, eps = pick(rows, case=SINGULAR), pick(rows, case=REGULARISED)
    claim(len({r["value"] for r in eps}) == 1, "one regularisation is run with every method")
    fine = right(singular)
    worst = max(r["patch_lam_rel"] for r in fine)
    qp = [m for m in methods_of(singular) if m.startswith("qp-")]
    lost = [m for m in qp if m not in {r["method"] for r in fine}]
    claim({r["method"] for r in fine} == (set(qp) - set(lost)) | {"cvxpy"}
          | {m for m in methods_of(singular) if m.startswith("petsc-")},
          "the QP backends but a few, cvxpy and the PETSc methods are right on the singular K")
    claim({r["method"] for r in singular if r["outcome"] != "right"} - set(lost)
          == {"pdas", "pdas-amg", "auto", "nested", "condensed", "uzawa", "uzawa-nesterov"},
          "PDAS (and pdas-amg, auto's picks), nested, the condensed dual and both Uzawas fail on "
          "the singular K")
    moved = one(eps, method="pdas")["patch_lam_rel"]
    not_helped = [r for r in eps if r["outcome"] != "right"]
    claim(all(r["status"] == "max_iter" for r in not_helped if r["method"].startswith("uzawa")),
          "both Uzawas stop at max_iter on the regularised problem")
    return (f"**Force control** (axis 6): K is singular; {len(fine)} of {len(singular)} methods are "
            "right on it (every QP backend but " + names(lost) + ", cvxpy and the PETSc methods; "
            f"λ within {power(worst)} of the exact patch solution), while PDAS (also `pdas-amg`, and "
            "`auto`, which picks one of them), `nested`, the condensed dual and both Uzawas need K⁻¹ "
            "and fail. The handling: "
            f"`signorini.certification.diagnosis.regularise(problem, {power(eps[0]['value'])})` adds "
            f"{power(eps[0]['value'])} · mean(diag K) to the diagonal; then {len(right(eps))} of "
            f"{len(eps)} methods are right and λ moves by {power(moved, 1)} "
            f"({moved / eps[0]['value']:.0f} ε); Uzawa is not helped (both variants stop at "
            "`max_iter`: W gains an eigenvalue of order 1/ε). The scene: "
            "`signorini.scenes.block.force_controlled_problem(pressure=…)`.")


AXIS = Axis(
    6, "force-control", "A body held only by contact",
    "K is singular under force control: which methods still work, and what does a small "
    "regularisation cost?",
    setup=f"The block {FORCE_BLOCK} under a pressure q = 0.01 E on its top, only the "
          "symmetry plane prescribed (`signorini.scenes.block.force_controlled_problem`); "
          "the exact answer is the patch solution (p = q). Every method on the singular "
          f"problem and on `regularise(problem, {REGULARISATION:g})`; PDAS and Clarabel "
          "for ε from 1e-14 to 1e-2.",
    advice="prescribe a displacement where you can (every scene of the package does). "
           "For a body held only by contact, `signorini.certification.diagnosis.regularise(problem, "
           "1e-8)` adds ε·mean(diag K) to the diagonal: PDAS, the condensed dual and "
           "the QP backends then solve it with λ within about 100 ε of the exact answer on "
           "the 8 × 8 block; "
           "Uzawa does not (its W gains an eigenvalue of order 1/ε). Run "
           "`signorini.certification.diagnosis.diagnose(problem)` to see whether K is singular.",
    legend="Cells: status, λ error against the exact patch solution.",
    tasks=tasks, findings=findings, table=table, figure=figure, headline=headline, counts=counts)


__all__ = ["counts", "tasks", "findings", "table", "figure", "headline"]
