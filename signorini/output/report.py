"""Reports: the validation suite as Markdown, JSON and figures; one solve as a summary."""

from __future__ import annotations

import contextlib
import datetime
import os
import platform
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np

from signorini.files import atomic_write_text, save_figure, to_json, writable_directory
from signorini.api import SCHEMA_VERSION
from signorini.certification.kkt import certificate
from signorini.output import plots
from signorini.references.profile import contact_profile
from signorini.references.catalogue import reference_of
from signorini.reprs import markdown_table, number

PACKAGES = ("signorini", "numpy", "scipy", "scikit-fem", "qpsolvers", "osqp", "clarabel", "cvxpy",
            "proxsuite", "piqp", "scs", "ecos", "highspy", "daqp", "quadprog", "qpalm", "cvxopt")


def provenance() -> dict[str, Any]:
    """Versions, machine and date of a run."""
    versions = {}
    for name in PACKAGES:
        with contextlib.suppress(metadata.PackageNotFoundError):
            versions[name] = metadata.version(name)
    cpu = platform.processor() or platform.machine()
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    return {"date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "python": platform.python_version(), "platform": platform.platform(),
            "cpu": cpu, "cores": os.cpu_count(), "versions": versions}


def _fmt(value: Any, digits: int = 1) -> str:
    if isinstance(value, bool):
        return "yes" if value else "no"
    return number(value, f".{digits}e") if value is None or isinstance(value, float) else str(value)


def provenance_lines(info: dict[str, Any]) -> list[str]:
    """A report's lines on the machine and the versions (:func:`provenance`), then a blank one."""
    return [f"Machine: {info['cpu']}, {info['cores']} cores, Python {info['python']}, {info['date']}  ",
            "Versions: " + ", ".join(f"{k} {v}" for k, v in info["versions"].items()), ""]


def status_claimed(run: dict[str, Any], claimed_word: str = "") -> str:
    """The status, and the method's own claim in brackets where it differs."""
    claimed = run.get("claimed_status")
    if claimed in (None, "", run["status"]):
        return run["status"]
    return f"{run['status']} ({claimed_word}{claimed})"


def runs_table(runs: list[dict[str, Any]]) -> list[str]:
    """Markdown table of the runs of one case."""
    head = ["method @ tol", "status (claimed)", "iterations", "time [s]", "worst KKT", "λ vs pdas",
            "misclassified", "p0 err", "a err"]
    rows = []
    for row in runs:
        vs = row.get("vs_reference", {})
        ref = row.get("reference", {})
        p0 = ref.get("p0_rel", ref.get("pressure_max_rel"))
        rows.append([row["label"], status_claimed(row), row.get("iterations", "–"),
                     f"{row.get('time_s', 0):.2f}", _fmt(row.get("kkt_worst")),
                     _fmt(vs.get("lam_rel")), vs.get("misclassified", "–"), _fmt(p0, 2),
                     _fmt(ref.get("a_rel"), 2)])
    return markdown_table(head, "llrrrrrrr", rows)


#: the files :func:`write_suite_report` writes into its folder
REPORT_FILES = ("report.md", "report.json", "*.png")


def write_suite_report(suite: Any, out: str | Path, command: str) -> dict[str, Path]:
    """Write report.md, report.json and the figures of a suite run to ``out``."""
    directory = writable_directory(out)
    info = provenance()
    figures: dict[str, Path] = {}

    def keep(key: str, ax) -> None:
        figures[key] = directory / f"{key}.png"
        save_figure(ax.figure, figures[key])

    for result in suite.results:
        problem, ref = result.problem, result.reference
        name = result.case.name
        reference = reference_of(problem)
        if reference is not None and reference.figure and np.all(np.isfinite(ref.lam)):
            profile = contact_profile(problem, ref)
            hertz = reference.compare(problem, ref)
            others = [(label, contact_profile(problem, s).pressure)
                      for label, s in result.solutions.items()
                      if label != suite.reference_label and s.status != "failed" and np.all(np.isfinite(s.lam))]
            ax = plots.pressure_profile(profile.x, profile.pressure, a_ref=hertz.a_ref,
                                        p0_ref=hertz.p0_ref, label="pdas", others=others)
            ax.set_title(f"{name}: contact pressure, every method against Hertz", fontsize=9)
            keep(f"{name}-pressure", ax)
        keep(f"{name}-kkt-time", plots.kkt_against_time(result.runs,
                                                        title=f"{name}: accuracy against time"))
    md = ["# signorini validation report", "",
          f"Command: `{command}`  ", f"Result: **{'PASS' if suite.passed else 'FAIL'}** "
          f"({sum(c.passed for c in suite.checks)}/{len(suite.checks)} checks) in {suite.elapsed_s:.1f} s  ",
          *provenance_lines(info),
          "Statuses are the package's: `converged` only when the method claimed success *and* the",
          "independent KKT certificate agrees; `inaccurate (converged)` means the method claimed",
          "success and the certificate did not back it. λ vs pdas is the relative ∞-norm distance",
          "from the exact primal-dual active-set answer; misclassified counts contact nodes whose",
          "active/inactive label differs from it.", "",
          "## Checks", ""]
    md += markdown_table(["case", "check", "value", "limit", "pass"], "llrrl",
                         ([c.case, c.name, _check_value(c), _fmt(c.limit, 0),
                           "✅" if c.passed else "❌ " + c.detail] for c in suite.checks))
    for result in suite.results:
        p = result.problem
        md += ["", f"## {result.case.name}", "",
               f"Scene `{result.case.scene}` with "
               + ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                           for k, v in p.model.params.items() if v is not None)
               + f": {p.n} dofs, {p.m} contact candidates.", ""]
        md += runs_table(result.runs)
        notes = [r for r in result.runs if r["status"] in ("skipped", "failed")]
        if notes:
            md += [""] + [f"- {r['label']} {r['status']}: {r['message']}" for r in notes]
        for key in (f"{result.case.name}-pressure", f"{result.case.name}-kkt-time"):
            if key in figures:
                md += ["", f"![{key}]({figures[key].name})"]
    md += ["", "## Limits", ""] + [f"- `{k}`: {v:g}" for k, v in suite.limits.items()]
    atomic_write_text(directory / "report.md", "\n".join(md) + "\n")
    payload = {"schema_version": SCHEMA_VERSION, "command": command, "passed": suite.passed,
               "elapsed_s": suite.elapsed_s,
               "provenance": info,
               "checks": [vars(c) for c in suite.checks], "runs": suite.runs, "limits": suite.limits}
    atomic_write_text(directory / "report.json", to_json(payload))
    return {"report.md": directory / "report.md", "report.json": directory / "report.json", **figures}


def _check_value(check: Any) -> str:
    return _fmt(check.value) if isinstance(check.value, bool) else _fmt(check.value, 2)


def checks_summary(suite: Any) -> str:
    """The checks as a plain-text table for the terminal."""
    width = max(len(c.name) for c in suite.checks)
    lines = [f"{'case':<18} {'check':<{width}}  {'value':>9}  {'limit':>7}  result"]
    for c in suite.checks:
        lines.append(f"{c.case:<18} {c.name:<{width}}  {_check_value(c):>9}  {_fmt(c.limit, 0):>7}  "
                     f"{'pass' if c.passed else 'FAIL ' + c.detail}")
    lines.append(f"{sum(c.passed for c in suite.checks)} of {len(suite.checks)} checks passed "
                 f"in {suite.elapsed_s:.1f} s")
    return "\n".join(lines)


def readme_validation(report: dict[str, Any], case: str = "hertz-cylinder") -> str:
    """The validation paragraph and table of docs/results.md, from a suite's ``report.json``.

    ``tests/test_readme_numbers.py`` holds that page to this text, and
    ``tools/readme.py`` writes it there, so that a number the page prints is
    one the committed report holds.
    """
    runs = [r for r in report["runs"] if r["case"] == case and r["status"] != "skipped"]
    first = runs[0]
    exact = next(r for r in runs if r["method"] == "pdas" and r["tol"] is not None)
    ref = exact["reference"]
    checks = report["checks"]
    order = {"converged": 0, "inaccurate": 1}
    runs.sort(key=lambda r: (order.get(r["status"], 2), (r.get("vs_reference") or {}).get("lam_rel", 1.0),
                             r["label"]))
    lines = [
        f"**{sum(c['passed'] for c in checks)} of {len(checks)} checks passed in "
        f"{report['elapsed_s']:.0f} s** ({report['provenance']['cpu']}, "
        f"{report['provenance']['cores']} cores, {report['provenance']['date'][:10]}). "
        f"On `{case}` ({first['dofs']:,} dofs, {first['candidates']} candidates) the exact "
        f"answer (pdas) is within **{100 * ref['p0_rel']:.2f} %** of Hertz on p₀, "
        f"**{100 * ref['a_rel']:.2f} %** on a, **{100 * ref['pressure_l2_rel']:.2f} %** in the L2 "
        f"norm of the pressure, and the contact force balances the applied load to "
        f"{ref['force_balance']:.0e}.",
        "",
        "| method @ tol | status | iterations | time [s] | worst KKT | λ vs pdas | misclassified nodes |",
        "|---|---|---:|---:|---:|---:|---:|",
    ]
    for run in runs:
        vs = run.get("vs_reference") or {}
        tol = "defaults" if run["tol"] is None else f"{run['tol']:g}"
        finite = run["status"] != "failed"
        lines.append(
            f"| {run['method']} @ {tol} | {status_claimed(run, 'claimed ')} | {run['iterations']:,} | "
            f"{run['time_s']:.2f} | {_fmt(run['kkt_worst'] if finite else None, 0)} | "
            f"{_fmt(vs.get('lam_rel') if finite else None) if vs.get('lam_rel') != 0 else '0'} | "
            f"{vs.get('misclassified', '–') if finite else '–'} |")
    return "\n".join(lines)


__all__ = ["provenance", "provenance_lines", "status_claimed", "runs_table", "write_suite_report",
           "checks_summary", "readme_validation", "REPORT_FILES"]
