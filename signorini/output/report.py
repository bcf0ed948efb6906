"""Reports: the validation suite as Markdown, JSON and figures; one solve as a summary."""

from __future__ import annotations

import datetime
import os
import platform
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np

from signorini.files import atomic_write_text, save_figure, to_json, writable_directory
from signorini.kkt import certificate
from signorini.output import plots
from signorini.pressure import contact_profile, load_resultant
from signorini.problem import ContactProblem, ContactSolution
from signorini.references import reference_of
from signorini.studies.suite import LIMITS, REFERENCE_LABEL, SuiteResult

PACKAGES = ("signorini", "numpy", "scipy", "scikit-fem", "qpsolvers", "osqp", "clarabel", "cvxpy",
            "proxsuite", "piqp", "scs", "ecos", "highspy", "daqp", "quadprog", "qpalm", "cvxopt")


def provenance() -> dict[str, Any]:
    """Versions, machine and date of a run."""
    versions = {}
    for name in PACKAGES:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            pass
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {"date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "python": platform.python_version(), "platform": platform.platform(),
            "cpu": cpu, "cores": os.cpu_count(), "versions": versions}


def _scalar_rows(value: Any) -> bool:
    """A list of flat records (e.g. per-rank timings): kept in the JSON."""
    return isinstance(value, list) and all(
        isinstance(row, dict) and all(isinstance(x, (int, float, str, bool)) for x in row.values())
        for row in value)


def solve_record(problem: ContactProblem, solution: ContactSolution) -> dict[str, Any]:
    """The JSON contract of ``signorini solve --json``."""
    cert = certificate(problem, solution)
    finite = bool(np.all(np.isfinite(solution.lam)) and np.all(np.isfinite(solution.u)))
    record: dict[str, Any] = {
        "scene": problem.scene, "params": problem.params, "method": solution.method,
        "status": solution.status, "claimed_status": solution.own_status,
        "message": solution.message,
        "iterations": int(solution.iterations), "dofs": problem.n,
        "contact_candidates": problem.m,
        "time": {"assemble_s": problem.assemble_time, "build_s": solution.build_time,
                 "solve_s": solution.solve_time},
        "kkt": cert.as_dict(),
    }
    if finite:
        profile = contact_profile(problem, solution)
        record["total_force"] = profile.total_force
        record["applied_load"] = profile.applied_load
        record["contact"] = profile.as_dict()
        reference = reference_of(problem)
        if reference is not None:
            if reference.resultant:  # curved or cornered obstacles: the vertical load
                record["load_resultant"] = load_resultant(problem, solution.lam)
            record[reference.key] = reference.compare(problem, solution).as_dict()
    else:
        record["total_force"] = None
        record["contact"] = None
    record["extras"] = {k: v for k, v in solution.extras.items()
                        if isinstance(v, (int, float, str, bool)) or _scalar_rows(v)}
    return record


def solve_summary(record: dict[str, Any]) -> str:
    """A few human lines about one solve."""
    lines = [f"{record['scene']} with {record['method']}: {record['status']} "
             f"after {record['iterations']} iterations ({record['message']})",
             f"  {record['dofs']} dofs, {record['contact_candidates']} contact candidates; "
             f"assemble {record['time']['assemble_s']:.2f} s, build {record['time']['build_s']:.2f} s, "
             f"solve {record['time']['solve_s']:.2f} s"]
    kkt = record["kkt"]
    lines.append("  KKT (relative): " + ", ".join(f"{k} {v:.1e}" for k, v in kkt.items()))
    if record.get("contact"):
        active = sum(record["contact"]["active"])
        lines.append(f"  total force {record['total_force']:.6g} (applied {record['applied_load']:.6g}), "
                     f"{active} nodes in contact")
    if record.get("hertz"):
        h = record["hertz"]
        lines.append(f"  Hertz: a = {h['a']:.6g} (ref {h['a_ref']:.6g}, {100 * h['a_rel']:.2f} %), "
                     f"p0 = {h['p0']:.6g} (ref {h['p0_ref']:.6g}, {100 * h['p0_rel']:.2f} %), "
                     f"pressure L2 {100 * h['pressure_l2_rel']:.2f} %")
    if record.get("punch"):
        q = record["punch"]
        lines.append(f"  punch: load {q['load']:.6g}; pressure vs P/(π√(a² − x²)) on |x| ≤ "
                     f"{q['inner']:g}a: max {100 * q['pressure_max_rel']:.2f} %, "
                     f"L2 {100 * q['pressure_l2_rel']:.2f} %; edge node p = {q['edge_pressure']:.4g} "
                     f"(element {q['edge_h']:.3g} next to the edge)")
    for rank in record["extras"].get("per_rank", []):
        if "local_rows" in rank:
            lines.append(f"  rank {rank['rank']}: {rank['local_rows']} rows, set-up "
                         f"{rank['setup_s']:.2f} s, solve {rank['solve_s']:.2f} s, "
                         f"peak memory {rank['peak_memory_mb']:.0f} MB")
    return "\n".join(lines)


def _fmt(value: Any, digits: int = 1) -> str:
    if value is None or (isinstance(value, float) and not np.isfinite(value)):
        return "–"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.{digits}e}"
    return str(value)


def runs_table(runs: list[dict[str, Any]]) -> list[str]:
    """Markdown table of the runs of one case."""
    lines = ["| method @ tol | status (claimed) | iterations | time [s] | worst KKT | "
             "λ vs pdas | misclassified | p0 err | a err |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for row in runs:
        vs = row.get("vs_reference", {})
        ref = row.get("reference", {})
        claimed = row.get("claimed_status", row["status"])
        status = row["status"] if claimed == row["status"] else f"{row['status']} ({claimed})"
        p0 = ref.get("p0_rel", ref.get("pressure_max_rel"))
        lines.append(
            f"| {row['label']} | {status} | {row.get('iterations', '–')} | {row.get('time_s', 0):.2f} | "
            f"{_fmt(row.get('kkt_worst'))} | {_fmt(vs.get('lam_rel'))} | {vs.get('misclassified', '–')} | "
            f"{_fmt(p0, 2)} | {_fmt(ref.get('a_rel'), 2)} |")
    return lines


def write_suite_report(suite: SuiteResult, out: str | Path, command: str) -> dict[str, Path]:
    """Write report.md, report.json and the figures of a suite run to ``out``."""
    directory = writable_directory(out)
    info = provenance()
    figures: dict[str, Path] = {}
    for result in suite.results:
        problem, ref = result.problem, result.reference
        name = result.case.name
        reference = reference_of(problem)
        if reference is not None and reference.figure and np.all(np.isfinite(ref.lam)):
            profile = contact_profile(problem, ref)
            hertz = reference.compare(problem, ref)
            others = [(label, contact_profile(problem, s).pressure)
                      for label, s in result.solutions.items()
                      if label != REFERENCE_LABEL and s.status != "failed" and np.all(np.isfinite(s.lam))]
            ax = plots.pressure_profile(profile.x, profile.pressure, a_ref=hertz.a_ref,
                                        p0_ref=hertz.p0_ref, label="pdas", others=others)
            ax.set_title(f"{name}: contact pressure, every method against Hertz", fontsize=9)
            path = directory / f"{name}-pressure.png"
            save_figure(ax.figure, path)
            figures[f"{name}-pressure"] = path
        ax = plots.kkt_against_time(result.runs, title=f"{name}: accuracy against time")
        path = directory / f"{name}-kkt-time.png"
        save_figure(ax.figure, path)
        figures[f"{name}-kkt-time"] = path
    md = ["# signorini validation report", "",
          f"Command: `{command}`  ", f"Result: **{'PASS' if suite.passed else 'FAIL'}** "
          f"({sum(c.passed for c in suite.checks)}/{len(suite.checks)} checks) in {suite.elapsed_s:.1f} s  ",
          f"Machine: {info['cpu']}, {info['cores']} cores, Python {info['python']}, {info['date']}  ",
          "Versions: " + ", ".join(f"{k} {v}" for k, v in info["versions"].items()), "",
          "Statuses are the package's: `converged` only when the method claimed success *and* the",
          "independent KKT certificate agrees; `inaccurate (converged)` means the method claimed",
          "success and the certificate did not back it. λ vs pdas is the relative ∞-norm distance",
          "from the exact primal-dual active-set answer; misclassified counts contact nodes whose",
          "active/inactive label differs from it.", "",
          "## Checks", "", "| case | check | value | limit | pass |", "|---|---|---:|---:|---|"]
    for c in suite.checks:
        value = _fmt(c.value, 2) if not isinstance(c.value, bool) else _fmt(c.value)
        md.append(f"| {c.case} | {c.name} | {value} | {_fmt(c.limit, 0)} | "
                  f"{'✅' if c.passed else '❌ ' + c.detail} |")
    for result in suite.results:
        p = result.problem
        md += ["", f"## {result.case.name}", "",
               f"Scene `{result.case.scene}` with "
               + ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                           for k, v in p.params.items() if v is not None)
               + f": {p.n} dofs, {p.m} contact candidates.", ""]
        md += runs_table(result.runs)
        notes = [r for r in result.runs if r["status"] in ("skipped", "failed")]
        if notes:
            md += [""] + [f"- {r['label']} {r['status']}: {r['message']}" for r in notes]
        for key in (f"{result.case.name}-pressure", f"{result.case.name}-kkt-time"):
            if key in figures:
                md += ["", f"![{key}]({figures[key].name})"]
    md += ["", "## Limits", ""] + [f"- `{k}`: {v:g}" for k, v in LIMITS.items()]
    atomic_write_text(directory / "report.md", "\n".join(md) + "\n")
    payload = {"command": command, "passed": suite.passed, "elapsed_s": suite.elapsed_s,
               "provenance": info,
               "checks": [vars(c) for c in suite.checks], "runs": suite.runs, "limits": LIMITS}
    atomic_write_text(directory / "report.json", to_json(payload))
    return {"report.md": directory / "report.md", "report.json": directory / "report.json", **figures}


def checks_summary(suite: SuiteResult) -> str:
    """The checks as a plain-text table for the terminal."""
    width = max(len(c.name) for c in suite.checks)
    lines = [f"{'case':<18} {'check':<{width}}  {'value':>9}  {'limit':>7}  result"]
    for c in suite.checks:
        value = _fmt(c.value, 2) if not isinstance(c.value, bool) else _fmt(c.value)
        lines.append(f"{c.case:<18} {c.name:<{width}}  {value:>9}  {_fmt(c.limit, 0):>7}  "
                     f"{'pass' if c.passed else 'FAIL ' + c.detail}")
    lines.append(f"{sum(c.passed for c in suite.checks)} of {len(suite.checks)} checks passed "
                 f"in {suite.elapsed_s:.1f} s")
    return "\n".join(lines)
