"""A convergence study's report: its figures, its markdown table and its files."""

from __future__ import annotations

from typing import Any

import numpy as np

from signorini.files import atomic_write_text, save_figure, to_json, writable_directory
from signorini.output.plots import axes, framed
from signorini.reprs import markdown_table, number
from signorini.studies.convergence import ESTIMATES, LABELS, ConvergenceStudy, GradingComparison

__all__ = ["plot_convergence", "plot_grading", "study_table", "write_study"]


def plot_convergence(study: ConvergenceStudy, ax=None, metrics: tuple[str, ...] | None = None):
    """Errors against h on log–log axes, one line per metric and exact method, rates in the legend."""
    ax = axes(ax)
    markers = "osd^v"
    for i, metric in enumerate(metrics or study.metrics):
        for j, method in enumerate(study.methods[:1] if metric in ESTIMATES else study.methods):
            h, _, err = study.series(method, metric)
            if h.size == 0:
                continue
            rate = study.rates.get(method, {}).get(metric, float("nan"))
            style = ":" if metric in ESTIMATES else "-" if j == 0 else "--"
            ax.loglog(h, np.abs(err), style, color=f"C{i}", marker=markers[i % len(markers)],
                      ms=5 if j == 0 else 9, mfc="none" if j else None,
                      label=f"{LABELS.get(metric, metric)} ({method}): rate {rate:.2f}")
    framed(ax, "h (spacing of the contact candidates)",
           "relative error" if "edge_over_centre" not in (metrics or study.metrics)
           else "relative error; edge pressure / (P/πa)", "both")
    ax.set_title(f"{study.scene}: convergence under uniform refinement", fontsize=9)
    return ax


def plot_grading(comparison: GradingComparison, ax=None):
    """The error of the graded and the uniform series against dofs, with the target line."""
    ax = axes(ax)
    for name, study, marker in (("graded", comparison.graded, "o"),
                                ("uniform", comparison.uniform, "s")):
        _, dofs, err = study.series("pdas", comparison.metric)
        ax.loglog(dofs, err, "-", marker=marker, label=name)
    ax.axhline(comparison.target, color="k", lw=0.8, ls=":",
               label=f"{100 * comparison.target:g} % target")
    for dofs, how, color in ((comparison.graded_dofs, comparison.graded_how, "C0"),
                             (comparison.uniform_dofs, comparison.uniform_how, "C1")):
        if np.isfinite(dofs):
            ax.plot([dofs], [comparison.target], "x", color=color, ms=10,
                    label=f"{dofs:,.0f} dofs ({how})")
    framed(ax, "dofs", LABELS.get(comparison.metric, comparison.metric), "both")
    ax.set_title(f"{comparison.scene}: graded against uniform meshes "
                 f"(grading saves {comparison.saving:,.0f}× the dofs)", fontsize=9)
    return ax


def study_table(study: ConvergenceStudy) -> list[str]:
    """Markdown table of a study: one row per level and method."""
    metrics = list(study.metrics)
    labels = [LABELS.get(m, m) for m in metrics]
    right = "r" * len(metrics)
    lines = markdown_table(
        ["level", "method", "status", "dofs", "candidates", "h", *labels, "λ vs first", "solve [s]"],
        f"rllrrr{right}rr",
        ([r.level, r.method, r.status, r.dofs, r.candidates, f"{r.h:.3g}",
          *(f"{r.errors[m]:.3e}" if m in r.errors else "–" for m in metrics),
          number(r.lam_rel_vs_first), f"{r.solve_s:.2f}"] for r in study.rows))
    lines += ["", "Fitted rates (slope of log error against log h"
              + (f", levels ≥ {study.fit_from}" if study.fit_from else "") + "):", ""]
    return lines + markdown_table(["method", *labels], f"l{right}",
                                  ([method, *(f"{rates.get(m, float('nan')):.2f}" for m in metrics)]
                                   for method, rates in study.rates.items()))


def write_study(study: ConvergenceStudy, out, command: str,
                comparison: GradingComparison | None = None) -> dict[str, Any]:
    """Write ``convergence-<scene>.md``, ``.json`` and ``.png`` (and the grading figure) to ``out``."""
    directory = writable_directory(out)
    stem = f"convergence-{study.scene}"
    paths = {"figure": directory / f"{stem}.png", "markdown": directory / f"{stem}.md",
             "json": directory / f"{stem}.json"}
    save_figure(plot_convergence(study).figure, paths["figure"])
    md = [f"# Convergence: {study.scene}", "", f"Command: `{command}`  ",
          "Parameters: " + ", ".join(f"{k}={v}" for k, v in study.params.items()), "",
          f"Largest λ difference between exact methods: {study.max_disagreement():.1e}", ""]
    md += study_table(study)
    md += ["", f"![convergence]({stem}.png)"]
    payload: dict[str, Any] = {"command": command, "study": study.as_dict()}
    if comparison is not None:
        paths["grading"] = directory / f"grading-{study.scene}.png"
        save_figure(plot_grading(comparison).figure, paths["grading"])
        md += ["", "## Graded against uniform meshes", "",
               f"{LABELS.get(comparison.metric, comparison.metric)} of {100 * comparison.target:g} %: "
               f"graded {comparison.graded_dofs:,.0f} dofs ({comparison.graded_how}), uniform "
               f"{comparison.uniform_dofs:,.0f} dofs ({comparison.uniform_how}; uniform error ∝ "
               f"dofs^{comparison.uniform_rate_per_dof:.2f}): grading saves "
               f"{comparison.saving:,.0f}× the dofs.", ""]
        md += study_table(comparison.uniform)
        md += ["", f"![grading](grading-{study.scene}.png)"]
        payload["grading"] = {k: v for k, v in comparison.as_dict().items()
                              if k not in ("graded", "uniform")}
        payload["uniform"] = comparison.uniform.as_dict()
    atomic_write_text(paths["markdown"], "\n".join(md) + "\n")
    atomic_write_text(paths["json"], to_json(payload))
    return paths
