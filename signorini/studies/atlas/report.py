"""The atlas's report: ``stability.md``, and the runs (CSV, JSON) and a figure per axis beside it."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from signorini.files import atomic_write_text, save_figure, to_json, writable_directory
from signorini.output.report import provenance, provenance_lines
from signorini.reprs import csv_text, markdown_table
from signorini.solvers.options import DEFAULT_TOL
from signorini.studies.atlas.axis import Axis, capped, nodes_text, num
from signorini.studies.atlas.summary import (AtlasResult, method_rows, method_summary, share, verdicts,
                                             wrapper_record)
from signorini.studies.runner import AGREE_CAP, AGREE_FACTOR, NEAR_FACTOR

#: the columns of ``runs.csv``
COLUMNS = ("axis", "case", "value", "scene", "dofs", "candidates", "method", "tol", "options",
           "expect", "status", "claimed_status", "wrapper", "iterations", "time_s", "kkt_worst",
           "kkt_name", "cert_ok", "lam_rel", "u_rel", "misclassified", "weak",
           "misclassified_strict", "weak_penetrating", "exact_ok", "near_exact", "claim_correct",
           "wrapper_right", "conservative", "outcome", "a_rel", "p0_rel", "pressure_l2_rel",
           "ref_a_rel", "ref_p0_rel", "ref_pressure_l2_rel", "rho_over_bound", "lambda_max",
           "bound_at_solution", "patch_lam_rel", "diagnosis", "message", "problem")


def reproduction(row: dict[str, Any], axis: Axis | None = None) -> str:
    """A Python line that repeats the run of ``row`` (of ``axis``) with the package's wrapper."""
    options = json.loads(row["options"]) if row.get("options") else {}
    arguments = f"tol={row['tol']!r}" if row.get("tol") is not None else "tol=None"
    max_iter = (axis.max_iter(row["method"], row.get("tol")) if axis is not None
                else capped(row["method"], row.get("tol")))
    if max_iter:
        arguments += f", max_iter={max_iter}"
    arguments += "".join(f", {k}={v!r}" for k, v in options.items())
    return ("from signorini.studies.problems import build_spec; "
            "from signorini.solvers.registry import solve; "
            f"solve(build_spec({row['problem']}), {row['method']!r}, {arguments})")


def _csv_value(value: Any) -> Any:
    """A cell of ``runs.csv``: a missing number left empty."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return ""
    return value


def write_report(result: AtlasResult, out: str | os.PathLike, command: str) -> dict[str, Path]:
    """Write ``out/stability.md``; the runs (CSV, JSON) and a figure per axis in ``out/stability/``.

    Every file is written whole or not at all (a temporary file, then a rename).
    """
    directory = writable_directory(out)
    data = writable_directory(Path(out) / "stability")
    info = provenance()
    rows = result.rows
    paths = {"csv": data / "runs.csv", "json": data / "runs.json", "report": directory / "stability.md"}
    right, runs, _faults = wrapper_record(rows)
    summary = method_summary(rows)
    atomic_write_text(paths["csv"], csv_text(({k: _csv_value(r.get(k)) for k in COLUMNS} for r in rows),
                                             COLUMNS))
    atomic_write_text(paths["json"], to_json({
        "command": command, "provenance": info, "elapsed_s": result.elapsed_s,
        "axis_seconds": result.axis_seconds, "quick": result.quick,
        "axes": [a.name for a in result.axes], "wrapper": {"right": right, "runs": runs},
        "methods": summary,
        "verdicts": {f"{m} | {a}": v for (m, a), v in verdicts(rows, result.axes).items()},
        "rows": rows}) + "\n")
    for axis in result.axes:
        mine = axis.rows(rows)
        if mine:
            save_figure(axis.figure(mine), data / axis.figure_name)
            paths[axis.name] = data / axis.figure_name
    atomic_write_text(paths["report"], report_markdown(result, command, info))
    return paths


def _header(result: AtlasResult, command: str, info: dict[str, Any], runs: int) -> list[str]:
    """Title, provenance and how to read the report."""
    minutes = result.elapsed_s / 60.0
    return [
        "# signorini stability atlas", "",
        f"Command: `{command}`  ",
        f"Run time: {result.elapsed_s:.0f} s ({minutes:.1f} min) for {runs} runs"
        + (" (quick: tiny meshes, few methods)" if result.quick else "") + "; per axis: "
        + ", ".join(f"{name} {sec:.0f} s" for name, sec in result.axis_seconds.items()) + "  ",
        *provenance_lines(info),
        ("Every run is a method at a tolerance on one problem, in its own worker process with a "
         "time limit. Data: [`stability/runs.csv`](stability/runs.csv) and "
         "[`stability/runs.json`](stability/runs.json) (one row per run, with the problem's "
         "spec to repeat it)."), "",
        "## How to read it", "",
        ("- **own status** (`claimed_status`): what the method said before the package judged "
         "it; **status**: what `signorini.solvers.registry.solve` returned."),
        ("- **certificate**: the worst relative KKT residual of `signorini.certification.kkt.certificate`; it "
         f"passes when ≤ τ (the tolerance asked for; {DEFAULT_TOL:g} without one)."),
        ("- **exact answer**: PDAS at 1e-9 on the non-dimensionalised problem (or the patch "
         "solution where K is singular). An answer **agrees** when no contact node is "
         "misclassified (`comparison.compare`, weakly active nodes left out — but a node with zero "
         "force that penetrates the obstacle counts) and ‖λ − λ*‖∞ ≤ "
         f"min({AGREE_FACTOR:g} τ, {AGREE_CAP:g}) · max(‖λ*‖∞, 1e-5 ‖f‖∞) (the validation "
         "suite's ratio, capped so that a loose τ cannot excuse a wrong contact force)."),
        ("- a method's claim of success is **correct** when its answer passes the certificate "
         "and agrees; the **correct rate** is the share of its claims that were correct."),
        ("- the package's status is **right** when it says `converged` only for answers that "
         "agree, grants `converged` whenever the claim was correct, and returns a status "
         "instead of raising."),
        ("- outcomes: **right** (converged, agrees), **caught** (a false claim the package "
         "downgraded to `inaccurate`), **conservative** (a claim the certificate turned down "
         f"although λ is within {NEAR_FACTOR:g} τ of the exact answer), **failed** (no claim), "
         "**wrong** (the package's status was wrong: `converged` for an answer that does not "
         "agree, `infeasible` for a problem that has a solution, or an exception instead of a "
         "status)."),
        ("- in tables: `*` a false claim caught, `°` conservative, `!` the package's status was "
         "wrong; `n/a` a dense backend refusing a problem above 3000 dofs."), ""]


def _per_method(rows: list[dict[str, Any]]) -> list[str]:
    md = ["## Per method", "",
          ("| method | runs | own claims of success | correct claims | correct rate | right answers "
           "| package's status right | statuses |"),
          "|---|---:|---:|---:|---:|---:|---:|---|"]
    for s in method_summary(rows):
        rate = "–" if not np.isfinite(s["correct_rate"]) else f"{100 * s['correct_rate']:.0f} %"
        statuses = ", ".join(f"{k} {v}" for k, v in sorted(s["statuses"].items()))
        md.append(f"| {s['method']} | {s['runs']} | {s['claims']} | {s['claims_correct']} | {rate} "
                  f"| {s['right']} | {s['wrapper_right']}/{s['runs']} | {statuses} |")
    return md


def _package_status(result: AtlasResult) -> list[str]:
    """The package's record, each run where its status was wrong, and the conservative runs."""
    rows = result.rows
    right, runs, faults = wrapper_record(rows)
    by_name = {a.name: a for a in result.axes}
    md = ["", "## The package's status", "",
          f"**Right in {share(right, runs)}.**", ""]
    if faults:
        md += ["Where it was not (each line repeats the run):", ""]
        for r in faults:
            detail = r.get("wrapper", "") if r["status"] == "raised" else r.get("message", "")
            md.append(f"- axis {r['axis']}, {r['case']}, `{r['method']}`: status `{r['status']}`, "
                      f"own `{r.get('claimed_status')}`; {str(detail)[:160]}; "
                      f"λ off {num(r.get('lam_rel'))}, {nodes_text(r)} misclassified.  \n"
                      f"  `{reproduction(r, by_name.get(r['axis']))}`")
        md.append("")
    conservative = [r for r in method_rows(rows) if r.get("conservative")]
    if conservative:
        md += [f"{len(conservative)} runs were **conservative**: the method's answer agreed with the "
               f"exact one to within {NEAR_FACTOR:g} τ but missed τ on the certificate, so the "
               "package said `inaccurate` "
               "(methods: " + ", ".join(sorted({r["method"] for r in conservative})) + ").", ""]
    return md


def method_axis_table(rows: list[dict[str, Any]], axes: list[Axis]) -> list[str]:
    """The method × axis verdicts (:func:`verdicts`) as Markdown lines, one row per method.

    ``stability.md`` prints it under "Method × axis"; docs/results.md quotes it (tools/readme.py).
    """
    table = verdicts(rows, axes)
    methods = list(dict.fromkeys(r["method"] for r in method_rows(rows)))
    return markdown_table(["method", *(f"{a.number}. {a.name}" for a in axes)], "l" * (len(axes) + 1),
                          ([method, *(table.get((method, a.name), "–") for a in axes)]
                           for method in methods))


def _method_by_axis(rows: list[dict[str, Any]], axes: list[Axis]) -> list[str]:
    return ["## Method × axis", "",
            ("Right answers among the runs that count (inside the step bound on axis 1; not "
             "refused for size): works = all, degrades = some, fails = none."), ""
            ] + method_axis_table(rows, axes)


def _axis_section(result: AtlasResult, axis: Axis) -> list[str]:
    """One axis: its question, set-up, findings, advice, table and figure."""
    mine = axis.rows(result.rows)
    here_right, here_runs, _ = wrapper_record(mine)
    md = ["", f"## {axis.number}. {axis.title}", "", f"*{axis.question}*", "",
          (f"Set-up: {axis.setup} {here_runs} runs, "
           f"{result.axis_seconds.get(axis.name, float('nan')):.0f} s; the package's status "
           f"was right in {here_right} of them."), "", "Findings:", ""]
    md += [f"- {line}" for line in axis.findings(mine)]
    md += ["", f"What to do: {axis.advice}", "", axis.legend, ""] + axis.table(mine)
    md += ["", f"![axis {axis.number}](stability/{axis.figure_name})"]
    return md


LIMITATIONS = [
    ("- Times are single runs on a shared 2-core machine: compare them within one axis, "
     "not across reports."),
    ("- The meshes are kept small so that the atlas runs in minutes; the mesh axis stops at "
     "about 31k dofs. The benchmark (`signorini bench`) goes further."),
    ("- An answer is compared with one exact answer; at weakly active nodes any force "
     "between 0 and round-off is right, so those nodes are left out of the comparison."),
    "- Dense backends (daqp, quadprog, ECOS) refuse problems above 3000 dofs (`n/a`)."]


def report_markdown(result: AtlasResult, command: str, info: dict[str, Any]) -> str:
    """The atlas as Markdown: summary, the package's record, method × axis, then each axis."""
    rows = result.rows
    _, runs, _ = wrapper_record(rows)
    axes = [a for a in result.axes if any(r["axis"] == a.name for r in rows)]
    md = _header(result, command, info, runs) + _per_method(rows) + _package_status(result)
    md += _method_by_axis(rows, axes)
    for axis in axes:
        md += _axis_section(result, axis)
    md += ["", "## Known limitations", ""] + LIMITATIONS
    return "\n".join(md) + "\n"


__all__ = ["reproduction", "write_report", "method_axis_table", "report_markdown"]
