"""The cross-check's record as tables: methods, pairs and, per candidate, each method's answer.

:func:`render` and :func:`render_markdown` read the record
:meth:`signorini.CrossCheck.to_dict` writes; :func:`render_candidates` its
``candidates`` (gap, λ and classification of every candidate by every method).
"""

from __future__ import annotations

from typing import Any

from signorini.reprs import markdown_table, number, plain_table

REFERENCE_COLUMNS = (("p0_rel", "p0 err"), ("a_rel", "a err"), ("pressure_l2_rel", "L2 err"),
                     ("pressure_max_rel", "p max err"))


def _said(run: dict[str, Any]) -> str:
    if run["claimed_status"] != run["status"]:
        return f"{run['claimed_status']} → {run['status']}"
    return run["status"]


def _count(value: Any) -> str:
    return "–" if value is None or value < 0 else str(value)


def _polished(run: dict[str, Any]) -> str:
    if run.get("polished_status") is None:
        return "–"
    return f"{number(run.get('polished_lam_ref'))} ({run['polished_status']})"


def _form(run: dict[str, Any]) -> str:
    polish = {None: "", True: ", polished", False: ", raw (polish did not help)"}[run["polished"]]
    return (run["form"] or "–") + polish


def _tables(record: dict[str, Any]) -> tuple[str, list[str], list[list[str]], list[str],
                                              list[list[str]]]:
    """The title and the two tables (methods, pairs) as header and rows of strings."""
    title = (f"cross-check of {record['scene'] or 'a problem'}: {record['dofs']:,} dofs, "
             f"{record['contact_candidates']:,} contact candidates, tol {record['tol']:.0e}")
    present = [(key, label) for key, label in REFERENCE_COLUMNS
               if any(key in run["reference"] for run in record["methods"])]
    ref = record.get("reference_method") or "reference"
    head = ["method", "said → certificate", "form", "worst KKT", f"λ vs {ref}", "active",
            "apart", "iterations", "time s"]
    polish = record.get("polish", False)
    head += [f"polished λ vs {ref}"] * polish + [label for _, label in present]
    rows = []
    for run in record["methods"]:
        row = [run["method"] + " (allowed)" * bool(run.get("allowed")), _said(run), _form(run),
               f"{number(run['kkt_worst'])} {run['kkt_worst_name']}".strip(),
               number(run.get("lam_ref")), _count(run.get("active")), _count(run.get("apart_ref")),
               str(run["iterations"]), number(run["time_s"], ".2f")]
        if polish:
            row.append(_polished(run))
        row += [number(run["reference"].get(key), ".2e") for key, _ in present]
        rows.append(row)
    pair_head = ["pair", "λ rel", "u rel", "nodes apart", "weak", "limit", "verdict"]
    pair_rows = [[f"{p['first']} ~ {p['second']}", number(p["lam_rel"]), number(p["u_rel"]),
                  str(p["apart"]), str(p["weak"]), number(p["limit"]), p["verdict"]]
                 for p in record["pairs"]]
    return title, head, rows, pair_head, pair_rows


def _verdict_line(record: dict[str, Any]) -> str:
    allowed = [r["method"] for r in record["methods"] if r.get("allowed")]
    let = f" (allowed through: {', '.join(allowed)})" if allowed else ""
    if record["failures"]:
        return (f"FAILED: {'; '.join(record['failures'])}{let}. A method fails when it does not "
                f"converge at tol; a pair when both said converged and they differ beyond "
                f"{record['agree_factor']:.0e} × tol or classify nodes apart")
    judged = sum(p["judged"] for p in record["pairs"])
    return (f"passed: every method converged and every judged pair agrees ({judged} of "
            f"{len(record['pairs'])} pairs said converged on both sides){let}")


def render(record: dict[str, Any]) -> str:
    """The cross-check record as plain-text tables (see :meth:`CrossCheck.to_dict`)."""
    title, head, rows, pair_head, pair_rows = _tables(record)
    return "\n".join([title, "", *plain_table(head, rows), "", *plain_table(pair_head, pair_rows), "",
                      _verdict_line(record)])


def render_markdown(record: dict[str, Any]) -> str:
    """The cross-check record as Markdown."""
    title, head, rows, pair_head, pair_rows = _tables(record)
    params = ", ".join(f"{k}={v}" for k, v in record["params"].items()) or "defaults"
    notes = (f"Parameters: {params}. Each method's own answer is judged (polish "
             f"{'shown as an extra column' if record.get('polish') else 'off'}); λ vs "
             f"{record.get('reference_method') or 'the reference'} is λ's relative distance to "
             f"that answer, apart the nodes classified apart from it. "
             f"A pair is judged when both methods said `converged` "
             f"(their own claim); it disagrees when a node is active in one answer and "
             f"inactive in the other (weakly active nodes apart: force and gap both within "
             f"max(1e-6, tol)), or λ or u differ by more than {record['agree_factor']:.0e} × tol.")
    return "\n".join([f"# {title}", "", notes, "", *markdown_table(head, "l" * len(head), rows), "", *markdown_table(pair_head, "l" * len(pair_head), pair_rows),
                      "", _verdict_line(record), ""])


def render_candidates(record: dict[str, Any]) -> str:
    """Per candidate: its point, and each method's gap, λ and classification (``-v``)."""
    names = [run["method"] for run in record["methods"] if run["method"] in
             (record["candidates"][0]["lam"] if record["candidates"] else {})]
    head = ["candidate", "point"] + [f"{what} {name}" for name in names
                                     for what in ("gap", "λ", "class")]
    rows = [[str(c["index"]), "(" + ", ".join(f"{x:.3g}" for x in c["point"]) + ")"
             if c["point"] is not None else "–"]
            + [x for name in names for x in (number(c["gap"][name], ".2e"),
                                              number(c["lam"][name], ".2e"), c["class"][name])]
            for c in record["candidates"]]
    return "\n".join(["per candidate (gap > 0 apart, < 0 penetrating; λ the contact force):",
                      *plain_table(head, rows)])


__all__ = ["REFERENCE_COLUMNS", "render", "render_candidates", "render_markdown"]
