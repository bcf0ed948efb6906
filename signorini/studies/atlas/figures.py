"""The stability atlas's figures. Every function takes ``ax=None`` and returns the Axes."""

from __future__ import annotations

import numpy as np

from signorini.output.plots import axes, framed, series_style

#: colours of the atlas's outcomes
OUTCOME_COLOURS = {"right": "#4daf4a", "conservative": "#a6d96a", "caught": "#fdae61",
                   "failed": "#d9d9d9", "wrong": "#d7191c"}


def atlas_step_sweep(rows: list[dict], *, ax=None):
    """Uzawa: iterations against ``ρ / (2/λ_max(W))``, one line per scene and method.

    ``●`` converged, ``✕`` diverged in a two-step cycle, ``▲`` diverged by
    growth, ``■`` stopped at the iteration limit. The textbook bound
    ``ρ = 2/λ_max(W)`` is the solid vertical line; dotted lines mark
    ``2/λ_max(W_AA)`` on the exact active set A of each scene (the bound the
    iteration sees once the active set has settled).
    """
    ax = axes(ax)
    groups = sorted({(r["case"], r["method"]) for r in rows})
    for i, (case, method) in enumerate(groups):
        mine = sorted((r for r in rows if (r["case"], r["method"]) == (case, method)),
                      key=lambda r: r["value"])
        colour = series_style(i)[0]  # the marker tells the status
        ax.plot([r["value"] for r in mine], [max(r["iterations"], 1) for r in mine], "-",
                color=colour, lw=1, alpha=0.6, label=f"{case}, {method}")
        for r in mine:
            message = str(r.get("message", ""))
            marker = {"converged": "o", "max_iter": "s"}.get(r["status"], "^")
            if r["status"] == "diverged" and "cycle" in message:
                marker = "x"
            ax.plot(r["value"], max(r["iterations"], 1), marker, color=colour, ms=5,
                    mfc=colour if r["outcome"] == "right" else "none")
        bounds = [r.get("bound_at_solution") for r in mine]
        bounds = [b for b in bounds if b is not None and np.isfinite(b)]
        if bounds and method == "uzawa" and abs(bounds[0] - 1.0) > 1e-3:
            ax.axvline(bounds[0], color=colour, ls=":", lw=1,
                       label=f"2/λ_max(W_AA) = {bounds[0]:.2f} × bound ({case})")
    ax.axvline(1.0, color="k", lw=1.2, label="ρ = 2/λ_max(W)")
    ax.axvline(0.5, color="0.5", lw=0.8, ls="--", label="ρ = 1/λ_max(W) (FISTA's bound)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    return framed(ax, "step ρ / (2/λ_max(W))", "iterations (to 1e-8, or until stopped)", "both",
                  fontsize=6)


def atlas_series(rows: list[dict], x: str, y: str, *, ax=None, xlabel: str = "",
                 ylabel: str = "", logx: bool = True, logy: bool = True, group: str = "method",
                 floor: float = 1e-16):
    """One line per ``group``: ``y`` against ``x`` over the atlas's runs.

    Filled markers: the package says converged and the answer is right; open
    markers: any other outcome; a red ring: the method claimed success and
    was wrong.
    """
    ax = axes(ax)
    names = list(dict.fromkeys(r[group] for r in rows))
    for i, name in enumerate(names):
        mine = [r for r in rows if r[group] == name and isinstance(r.get(x), (int, float))
                and isinstance(r.get(y), (int, float)) and np.isfinite(r[x]) and np.isfinite(r[y])]
        if not mine:
            continue
        mine.sort(key=lambda r: r[x])
        colour, marker = series_style(i)
        values = [max(r[y], floor) if logy else r[y] for r in mine]
        ax.plot([r[x] for r in mine], values, "-", color=colour, lw=1, alpha=0.7, label=name)
        for r, value in zip(mine, values):
            ax.plot(r[x], value, marker, color=colour, ms=4,
                    mfc=colour if r["outcome"] == "right" else "none")
            if not r.get("claim_correct", True):
                ax.plot(r[x], value, "o", ms=9, mfc="none", mec="red", mew=0.8)
    if logx:
        ax.set_xscale("log")
    if logy:
        ax.set_yscale("log")
    return framed(ax, xlabel or x, ylabel or y, "both", fontsize=5, ncol=2)


def atlas_outcomes(rows: list[dict], *, column: str = "case", ax=None, title: str = ""):
    """Methods × ``column``: each cell coloured by the run's outcome and labelled with its status.

    Outcomes: right (converged, agrees with the exact answer), conservative (a
    right answer the certificate turned down), caught (a false claim of
    success the package downgraded), failed (no claim), wrong (the package's
    status was wrong, or it raised).
    """
    ax = axes(ax)
    methods = list(dict.fromkeys(r["method"] for r in rows))
    columns = list(dict.fromkeys(r[column] for r in rows))
    short = {"converged": "conv", "inaccurate": "inacc", "max_iter": "max it", "diverged": "div",
             "infeasible": "infeas", "failed": "fail", "refused": "n/a", "raised": "RAISED",
             "timeout": "time", "crashed": "crash", "input-error": "error"}
    for r in rows:
        i, j = methods.index(r["method"]), columns.index(r[column])
        colour = OUTCOME_COLOURS.get(r.get("outcome", "failed"), "#ffffff")
        ax.add_patch(_rectangle(j, i, colour))
        ax.text(j + 0.5, i + 0.5, short.get(r["status"], str(r["status"])[:6]), ha="center",
                va="center", fontsize=5)
    ax.set_xlim(0, len(columns))
    ax.set_ylim(len(methods), 0)
    ax.set_xticks(np.arange(len(columns)) + 0.5)
    ax.set_xticklabels([str(c) for c in columns], rotation=30, ha="right", fontsize=6)
    ax.set_yticks(np.arange(len(methods)) + 0.5)
    ax.set_yticklabels(methods, fontsize=6)
    ax.tick_params(length=0)
    if title:
        ax.set_title(title, fontsize=8)
    return ax


def _rectangle(x: float, y: float, colour: str):
    from matplotlib.patches import Rectangle  # matplotlib: only when a figure is drawn

    return Rectangle((x, y), 1.0, 1.0, facecolor=colour, edgecolor="white", lw=0.8)


def atlas_weak_nodes(rows: list[dict], *, ax=None):
    """Misclassified contact nodes per run: weakly active nodes left out, and counted strictly.

    The comparison of :func:`signorini.certification.comparison.compare` leaves out nodes that touch
    with zero force; counting them as well (weak tolerance 0) shows what a
    comparison without the weak label would have flagged.
    """
    ax = axes(ax)
    labels = [f"{r['method']} ({r['case']})" for r in rows]
    positions = np.arange(len(rows))
    weak = [r.get("weak", np.nan) for r in rows]
    strict = [r.get("misclassified_strict", np.nan) for r in rows]
    kept = [r.get("misclassified", np.nan) for r in rows]
    ax.bar(positions - 0.27, weak, 0.27, color="#bdbdbd", label="weakly active nodes")
    ax.bar(positions, strict, 0.27, color="#fdae61", label="misclassified, counted strictly (weak tol 0)")
    ax.bar(positions + 0.27, kept, 0.27, color="#4daf4a",
           label="misclassified, weakly active nodes left out (the package's comparison)")
    ax.set_xticks(positions)
    ax.set_xticklabels(labels, rotation=60, ha="right", fontsize=5)
    ax.set_ylabel("misclassified contact nodes")
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize=6)
    return ax


__all__ = ["atlas_step_sweep", "atlas_series", "atlas_outcomes", "atlas_weak_nodes"]
